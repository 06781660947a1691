"""Clamped, free and cantilever square plates (Kirchhoff FE) against Leissa's tables.

Leissa's values (sources and digits in tailbeam.plate.closed_forms.LEISSA_SQUARE) are Ritz
upper bounds: the converged FE frequencies must lie below them, by no more than the table's
own accuracy (2e-3 for clamped edges, whose beam functions satisfy every edge condition;
1.5 % with free edges, where beam functions violate the natural conditions and Leissa's
series converges slowly from above). Run at nu = 0.3 as the free-edge tables assume.
"""

import numpy as np
import pytest

from tailbeam.physics.bodies import Plate
from tailbeam.physics.materials import Material
from tailbeam.plate import compute_modes
from tailbeam.plate.closed_forms import LEISSA_SQUARE, leissa_frequencies

STEEL_NU03 = Material("steel_nu03", density=7850.0, youngs_modulus=2.06e11, poisson_ratio=0.3)
PLATE = Plate(material=STEEL_NU03)


@pytest.mark.parametrize("boundary", ["CCCC", "FFFF", "CFFF"])
def test_square_plate_against_leissa(boundary):
    table = LEISSA_SQUARE[boundary]
    ref = leissa_frequencies(PLATE, boundary)
    # 6 divisions: FE converged to < 2e-4 for these low modes (checked against 12 divisions)
    basis = compute_modes(
        PLATE, boundary, theory="kirchhoff", count=len(ref), divisions=6, use_cache=False
    )
    rel = basis.frequencies_hz / ref - 1.0
    assert np.all(rel < 2e-4), rel  # Ritz upper bound (+ FE's own small error)
    assert np.all(rel > -table.table_accuracy), rel


def test_free_plate_excludes_rigid_body_modes_and_has_no_static_compliance():
    basis = compute_modes(PLATE, "FFFF", theory="kirchhoff", count=3, divisions=4, use_cache=False)
    assert basis.info["rigid_body_modes_excluded"] == 3
    # the first elastic mode (lambda ~ 13.47), not a zero-frequency rigid mode
    assert basis.frequencies_hz[0] > 0.9 * leissa_frequencies(PLATE, "FFFF")[0]
    assert basis.static_compliance_at is None


def test_one_simply_supported_edge_leaves_one_rigid_mode():
    basis = compute_modes(PLATE, "SFFF", theory="mindlin", count=2, divisions=4, use_cache=False)
    assert basis.info["rigid_body_modes_excluded"] == 1
    assert basis.frequencies_hz[0] > 10.0
