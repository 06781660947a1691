"""Error of the fast solver against the reference as the tolerance is tightened.

An adaptive 8th-order method with proportional error control should show tolerance
proportionality: error ~ C rtol (slope 1 in log-log). Measured on this scene: slope 0.9,
C <= 4; the bounds (slope in [0.7, 1.3], C <= 20) catch a lost order (e.g. a kink stepped over
or the contact-start singularity degrading the method to order ~2.5, slope ~0.3) without
being tuned to the noise. The full ladder and timings are in benchmarks/bench_rigid.py.
"""

import numpy as np
import pytest

from tailbeam import CARBON_STEEL, COAL, Ball, Plate, ball_plate_law
from tailbeam.solvers.rigid import simulate_rigid
from tailbeam.solvers.rigid.reference import simulate_rigid_reference

RTOLS = [1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10]


def _error(fast, ref):
    """Max relative error over every impact's peak force and apex height."""
    err = 0.0
    for x, y in zip(fast.impacts, ref.impacts, strict=True):
        err = max(err, abs(x.peak_force / y.peak_force - 1.0))
        if np.isfinite(y.next_apex_height):
            err = max(err, abs(x.next_apex_height / y.next_apex_height - 1.0))
    return err


@pytest.mark.parametrize("speed", [1.0, 2.0])
def test_error_is_proportional_to_tolerance(speed):
    law = ball_plate_law(COAL, 0.03, CARBON_STEEL, damping=800.0, penetration=1e-4)
    ball = Ball("A", COAL, 0.03, (0.0, 0.0, 0.13), (0.0, 0.0, -speed))
    ref = simulate_rigid_reference([ball], Plate(), [law], 0.3)
    errors = np.array(
        [_error(simulate_rigid([ball], Plate(), [law], 0.3, rtol=r), ref) for r in RTOLS]
    )
    assert np.all(errors <= 20.0 * np.array(RTOLS))
    slope = np.polyfit(np.log10(RTOLS), np.log10(errors), 1)[0]
    assert 0.7 <= slope <= 1.3
    assert errors[-1] < 1e-3 * errors[0]
