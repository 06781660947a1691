"""Thinning the plate force histories of a run with friction (``active.plate.thinning``, used by
``active.plate.forces``): the kept history is within the tolerance of every dropped node (checked
by interpolating through the kept nodes, numpy's ``interp``), jumps and ends are kept; on the
modal plate the sensors' replay of the thinned loads agrees with that of every node written.
"""

import numpy as np
import pytest

from tailbeam.physics.bodies import STANDARD_GRAVITY, Ball, Plate
from tailbeam.physics.friction import FrictionModel, FrictionSettings
from tailbeam.physics.incline import InclinedPlate
from tailbeam.physics.materials import COAL
from tailbeam.plate.closed_forms import ssss_kirchhoff_basis
from tailbeam.solvers.plate_loads.response import LoadResponse
from tailbeam.solvers.stream.active import members
from tailbeam.solvers.stream.active.plate import forces
from tailbeam.solvers.stream.active.plate.thinning import keep_nodes
from tailbeam.solvers.stream.driver.loop import solve_stream
from tailbeam.solvers.stream.plate import StreamPlate
from tailbeam.streams.generator import Particle, default_label


def dropped_distance(t, f, keep) -> float:
    """Largest distance of a node from the piecewise-linear history through the kept ones."""
    return float(np.max(np.abs(np.interp(t, t[keep], f[keep]) - f)))


@pytest.mark.parametrize("tol", [1e-9, 1e-6, 1e-3])
def test_every_dropped_node_within_the_tolerance(tol):
    rng = np.random.default_rng(3)
    t = np.cumsum(rng.uniform(1e-8, 1e-7, 4000))  # (steps of a sticking impact)
    f = 1e3 * np.sin(5e3 * t) ** 2 + 1e-4 * rng.standard_normal(t.size)  # (the noise: kinks)
    keep = keep_nodes(t, f, tol * 1e3)
    assert keep[0] and keep[-1]
    assert dropped_distance(t, f, keep) <= tol * 1e3 * (1 + 1e-12)
    if tol >= 1e-6:  # above the noise (1e-7 of the peak) most nodes go
        assert keep.sum() < t.size / 4


def test_straight_lines_and_jumps():
    t = np.array([0.0, 1.0, 2.0, 3.0, 3.0, 4.0, 5.0])
    f = np.array([0.0, 1.0, 2.0, 3.0, 7.0, 7.0, 7.0])  # a ramp, a jump at t = 3, a flat
    assert keep_nodes(t, f, 0.0).tolist() == [True, False, False, True, True, False, True]
    curved = np.array([0.0, 1.0, 4.0, 9.0])
    assert keep_nodes(np.arange(4.0), curved, 0.0).all()  # tol 0 keeps a curve's nodes
    assert keep_nodes(np.array([0.0]), np.array([1.0]), 1.0).tolist() == [True]


def test_thinned_replay_on_the_modal_plate():
    """A spinning coal ball lands obliquely on the SSSS plate (modes to 1.3 kHz, friction's
    moment in the replay): the sensors' replay of the thinned force histories (THIN of each
    drained piece's peak, THIN_FRICTION for the friction rows) against the replay of every
    node written: the modal state within 10 THIN_FRICTION (relative to its largest value over
    the run; a load within tol of its history moves the modes by a few tol)."""
    basis = ssss_kirchhoff_basis(Plate(), 1300.0)
    incline = InclinedPlate(Plate(), 10.0, STANDARD_GRAVITY)
    balls = [
        Ball("A", COAL, 0.02, (-0.1, 0.05, 0.021), (1.5, 0.3, -1.2), (0.0, 40.0, 0.0)),
    ]
    particles = [Particle.from_ball(b, default_label(b)) for b in balls]
    model = FrictionModel(FrictionSettings(0.5, 0.4, 1e-3, 2e-3, rolling=0.1))
    times = np.linspace(0.0, 0.003, 61)
    replays, nodes = [], []
    for thin in ((forces.THIN, forces.THIN_FRICTION), (0.0, 0.0)):
        with pytest.MonkeyPatch.context() as mp:
            mp.setattr(members, "THIN", thin[0])
            mp.setattr(members, "THIN_FRICTION", thin[1])
            plate = StreamPlate(basis, np.full(basis.n_modes, 0.01), residual_flexibility=False)
            run = solve_stream(particles, incline, 0.003, damping=300.0, rtol=1e-10,
                               friction=model, progress=False, plate=plate)  # fmt: skip
        response = LoadResponse.from_records(basis, np.full(basis.n_modes, 0.01), run.loads,
                                             run.dead_loads, quasi_static=False)  # fmt: skip
        replays.append(response.modal_coordinates(times))
        nodes.append(response.loads.n_nodes)
    thinned, full = replays
    print(nodes, np.max(np.abs(thinned - full)) / np.max(np.abs(full)))
    assert nodes[0] < nodes[1] / 4
    assert np.max(np.abs(thinned - full)) <= 10 * forces.THIN_FRICTION * np.max(np.abs(full))
