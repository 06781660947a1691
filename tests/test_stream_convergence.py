"""A many-ball two-way run on the modal plate converges with the tolerance and the band at a
measured order. Truth: the same scene at a much tighter tolerance / a much wider band
(self-convergence); the orders are the measured ones of
``python benchmarks/study_stream_convergence.py`` (DOP853 with its error per unit step: ~1 in
rtol; the band without residual flexibility at the contacts: ~1.9).

Compared: each ball's first impact (duration, peak force, separation speed), where both runs
have the same one. Later impacts of a stacked pair chattering on the vibrating plate diverge
exponentially with the contact count (chaos, measured in the study), so they are not a measure
of the solver's error.
"""

import numpy as np
import pytest
from stream_scenes import first_impact_difference, ten_ball_scene

from tailbeam.physics.bodies import Plate
from tailbeam.physics.incline import InclinedPlate
from tailbeam.plate.closed_forms import ssss_kirchhoff_basis
from tailbeam.solvers.stream.driver.loop import solve_stream
from tailbeam.solvers.stream.plate import StreamPlate
from tailbeam.streams.generator import Particle


def _run(band_hz, rtol, residual=True):
    incline = InclinedPlate()
    balls = ten_ball_scene(incline)
    particles = [
        Particle(b.name, "", "coal", b.material, b.radius, b.mass, 0.0, tuple(b.position),
                 tuple(b.velocity))
        for b in balls
    ]  # fmt: skip
    basis = ssss_kirchhoff_basis(Plate(), band_hz)
    plate = StreamPlate(basis, np.full(basis.n_modes, 0.01), residual_flexibility=residual)
    run = solve_stream(particles, incline, 0.2, damping=300.0, rtol=rtol, progress=False,
                       plate=plate)  # fmt: skip
    return run.contacts


def _order(values, errors) -> float:
    return float(np.polyfit(np.log(values), np.log(errors), 1)[0])


@pytest.fixture(scope="module")
def tight():
    return _run(5000.0, 1e-13)


def test_first_impacts_converge_with_the_tolerance(tight):
    rtols = [1e-6, 1e-8, 1e-10]
    errors = []
    for rtol in rtols:
        _prefix, _total, compared, worst = first_impact_difference(_run(5000.0, rtol), tight)
        assert compared == 10  # every ball's first impact is the same impact
        errors.append(worst)
    assert errors[-1] < 1e-8
    assert 0.8 < _order(rtols, errors) < 1.2  # measured 0.99


@pytest.mark.parametrize("residual, order", [(True, 2.5), (False, 1.5)])
def test_first_impacts_converge_with_the_band(residual, order):
    """With the residual flexibility of the truncated modes at the contacts (the default)
    and without it (measured orders ORDERS_MEASURED)."""
    truth = _run(20000.0, 1e-12, residual)
    bands = [2500.0, 5000.0, 10000.0]
    errors = []
    for band in bands:
        got = _run(band, 1e-12, residual)
        _prefix, _total, compared, worst = first_impact_difference(got, truth)
        assert compared >= 8
        errors.append(worst)
    assert errors[0] > errors[1] > errors[2]
    assert -_order(bands, errors) > order
