"""Friction on the two-way MODAL plate in the fast stream solver, against independent truths.

- the compiled friction of a plate pair on the modal plate (slip against the plate's top
  surface, h/2 above the mid-surface, moving at -(h/2) grad phi . q'; the moment
  (h/2) F_t . grad phi into the modes) against the reference's numpy formulas, to round-off;
- ten balls (coal and sandstone, spinning, friction per material pair with rolling
  resistance) landing and colliding on the SSSS plate: every contact
  record (times, normal and tangential impulses, rebound, how it ended), the final states
  and the plate's modal state against the slow reference (scipy DOP853, every pair watched)
  with frozen shapes (the fast solver's contact model: shapes and their gradients kept per
  contact, tests/test_stream_reference_modal.py), both at rtol 1e-11, on a scene where the
  fast solver's shapes are those at the touch (see ``ten_balls``); the sensors' load
  replay (the contact forces and friction's couples, ``active.plate.forces``) reproduces the
  plate's modal state;
- energy: c = 0 and undamped modes, balls + rotation + modes + contacts + friction's
  dissipation conserved (a conservation law); leaving the moment out breaks it.
"""

from types import SimpleNamespace

import numpy as np
import pytest
from test_friction_fast import (
    COAL,
    SANDSTONE,
    final_differences,
    record_differences,
)

from tailbeam.physics.bodies import STANDARD_GRAVITY, Ball, Plate
from tailbeam.physics.friction import FrictionModel, FrictionSettings
from tailbeam.physics.incline import InclinedPlate
from tailbeam.physics.materials import CARBON_STEEL
from tailbeam.plate.closed_forms import ssss_kirchhoff_basis
from tailbeam.solvers.plate_loads.response import LoadResponse
from tailbeam.solvers.stream.active import friction_pairs
from tailbeam.solvers.stream.active.compiled import friction as compiled
from tailbeam.solvers.stream.driver.loop import solve_stream
from tailbeam.solvers.stream.plate import StreamPlate
from tailbeam.solvers.stream.reference.friction import FrictionTable, pair_friction
from tailbeam.solvers.stream.reference.plate import ReferencePlate
from tailbeam.solvers.stream.reference.solver import simulate_stream_reference
from tailbeam.streams.generator import Particle, default_label

FMAX = 1300.0  # Hz: 11 modes of the SSSS plate
ZETA = 0.01
RTOL = 1e-11
AGREE = 1e-6
DURATION = 0.009  # s: before any ball lands a second time


@pytest.fixture(scope="module")
def basis():
    return ssss_kirchhoff_basis(Plate(), FMAX)


def ten_balls():
    """Five pairs dropped straight down (no lateral speed before they land, so the shapes the
    fast solver takes before the touch are those at it): each lower ball, spinning, lands
    obliquely in friction's sense and rebounds into the ball falling above it (a ball-ball
    contact with friction in flight). Every plate contact is its ball's first landing."""
    spots = [(-0.2, -0.15), (0.12, -0.05), (0.0, 0.18), (-0.1, 0.05), (0.2, 0.2)]
    spins = [(0.0, 40.0, 0.0), (-50.0, 0.0, 10.0), (20.0, 20.0, 0.0), (0.0, -60.0, 5.0),
             (30.0, 0.0, 0.0)]  # fmt: skip
    mats = [(COAL, SANDSTONE), (SANDSTONE, COAL), (COAL, COAL), (SANDSTONE, SANDSTONE),
            (COAL, SANDSTONE)]  # fmt: skip
    radii = [(0.02, 0.015), (0.025, 0.02), (0.015, 0.02), (0.02, 0.02), (0.03, 0.015)]
    out = []
    for k, ((x, y), w, (ml, mu), (rl, ru)) in enumerate(zip(spots, spins, mats, radii,
                                                            strict=True)):  # fmt: skip
        zl = rl + 0.002 + 0.001 * k
        out.append(Ball(f"L{k}", ml, rl, (x, y, zl), (0.0, 0.0, -1.5), w))
        out.append(Ball(f"U{k}", mu, ru, (x + 0.003, y, zl + rl + ru + 0.01), (0.0, 0.0, -1.5)))
    return out


def pair_model():
    default = FrictionSettings(0.5, 0.4, 1e-2, 2e-2, rolling=0.05)
    steel = FrictionSettings(0.6, 0.5, 1e-2, 2e-2, 0.1)
    mixed = FrictionSettings(0.7, 0.6, 1e-2, 2e-2)
    return FrictionModel(
        default, ((("sandstone", CARBON_STEEL.name), steel), (("coal", "sandstone"), mixed))
    )


def run_both(basis, balls, incline, model, duration, *, damping, zeta, moment=True):
    """(fast run, its StreamPlate, frozen reference) of ``balls`` on the modal plate."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(friction_pairs, "_PLATE_MOMENT", moment)
        plate = StreamPlate(basis, np.full(basis.n_modes, zeta), residual_flexibility=False)
        particles = [Particle.from_ball(b, default_label(b)) for b in balls]
        fast = solve_stream(particles, incline, duration, damping=damping, rtol=RTOL,
                            friction=model, progress=False, rest_speed=0.0,
                            plate=plate)  # fmt: skip
    ref = simulate_stream_reference(balls, incline, duration, friction=model, rtol=RTOL,
                                    damping=damping, max_steps=10**5,
                                    plate=ReferencePlate(basis, zeta, "frozen"))  # fmt: skip
    plate.propagate(duration)
    return fast, plate, ref


def test_the_compiled_modal_plate_pair_is_the_references(basis):
    """Force, torque, power and the modes' forces of a plate pair on the vibrating plate at
    random states (slips below v_s, between v_s and v_d, and above) against the reference's
    formulas: slip against its surface velocity (``Kinematics.surface_velocity``'s
    -(h/2) grad phi . q'), modal force (h/2) F_t . grad phi."""
    rng = np.random.default_rng(11)
    ref_plate = ReferencePlate(basis, 0.0)
    half = 0.5 * basis.plate.thickness
    m = basis.n_modes
    for _ in range(30):
        r = 0.03
        xi = np.array([*rng.uniform(-0.25, 0.25, 2), 0.0299])
        scale = 10.0 ** rng.uniform(-3, 0)
        vi, wi = rng.normal(size=3) * scale, rng.normal(size=3) * scale / r
        qd = rng.normal(size=m) * scale * 1e-2
        _, grad = ref_plate.shapes_and_gradients(xi[:2])
        surface = np.zeros(3)
        surface[:2] = -half * np.einsum("mk,m->k", grad[0], qd)
        fn = rng.uniform(0.1, 100.0)
        row = [0.5, 0.3, 0.05, 0.2, 0.1, 1.0, r]
        table = FrictionTable(*[np.array([c]) for c in row])
        kin = SimpleNamespace(normal=np.array([[0.0, 0.0, 1.0]]))
        ref = pair_friction(table, kin, np.array([fn]), xi[None], vi[None], wi[None],
                            (xi * [1, 1, 0])[None], surface[None], np.zeros((1, 3)))  # fmt: skip
        fric = np.array([[*row, half, half, *grad[0][:, 0], *grad[0][:, 1]]])
        y = np.concatenate([xi, vi, np.zeros(m), qd, wi])
        got = compiled.pair_friction(y, 1, 6 + 2 * m, 0, -1, 0, 0.0, 0.0, 1.0, fn, fric)
        size = 0.5 * fn
        np.testing.assert_allclose(got[0:3], ref.force[0], rtol=0, atol=1e-13 * size)
        np.testing.assert_allclose(got[3:6], ref.torque_i[0], rtol=0, atol=1e-13 * size * r)
        assert got[9] == pytest.approx(ref.power[0], rel=1e-12, abs=1e-14 * size * scale)
        out = np.zeros_like(y)
        compiled.add_plate_moment(1, 0, got[0], got[1], fric, out)
        modal = half * np.einsum("k,mk->m", ref.force[0, :2], grad[0])
        np.testing.assert_allclose(out[6 + m : 6 + 2 * m], modal, rtol=0,
                                   atol=1e-13 * size * half * np.max(np.abs(grad)))  # fmt: skip


@pytest.fixture(scope="module")
def ten(basis):
    incline = InclinedPlate(Plate(), 0.0, STANDARD_GRAVITY)
    return run_both(basis, ten_balls(), incline, pair_model(), DURATION, damping=300.0,
                    zeta=ZETA)  # fmt: skip


def test_ten_balls_on_the_modal_plate_as_the_reference(ten, basis):
    """Every contact record and the final states within 1e-6 (relative as in
    tests/test_friction_fast.py; measured 1e-10, the tangential impulses 8e-8), friction's
    dissipated energy and the plate's modal state at the end within 1e-6 (measured 8e-9,
    2e-9), and the sensors' load replay (contact forces and friction's couples) gives the
    same modal state within 1e-6 (measured 1.9e-8, the histories thinned)."""
    fast, plate, ref = ten
    balls = ten_balls()
    landings = [r.ball for r in fast.contacts if r.partner == "plate"]
    assert len(landings) == len(set(landings)) == 5  # first landings only (docstring)
    assert sum(r.partner != "plate" for r in fast.contacts) == 10  # 5 ball-ball contacts
    diffs = {**final_differences(fast, ref, balls, 1.5, DURATION),
             **record_differences(fast, ref, 1.5, DURATION)}  # fmt: skip
    q, qd = ref.plate_states[-1]
    diffs["q"] = np.max(np.abs(plate.q - q)) / np.max(np.abs(q))
    diffs["qd"] = np.max(np.abs(plate.qd - qd)) / np.max(np.abs(qd))
    diffs["friction"] = abs(fast.stats["energy_friction"] / ref.dissipated[-1] - 1.0)
    response = LoadResponse.from_records(basis, np.full(basis.n_modes, ZETA), fast.loads,
                                         fast.dead_loads, quasi_static=False)  # fmt: skip
    replay = response.modal_coordinates(np.linspace(0.0, DURATION, 301))[:, -1]
    diffs["replay"] = np.max(np.abs(replay - q)) / np.max(np.abs(q))
    print({k: f"{v:.1e}" for k, v in diffs.items()})
    assert max(diffs.values()) <= AGREE, diffs


@pytest.mark.parametrize("moment", [True, False])
def test_energy_with_friction_on_the_modal_plate(basis, moment):
    """c = 0, undamped modes, a spinning ball landing obliquely: released = final (ball,
    rotation, contacts) + plate + friction's dissipation, to 1e-9 of the energy released
    (measured 3e-13), with the plate holding > 1e-4 of it and friction > 1 %. Without the
    moment on the plate the ledger misses the work the friction force does on the plate's
    surface (measured 8e-5 of it): the moment is not negligible there."""
    incline = InclinedPlate(Plate(), 0.0, STANDARD_GRAVITY)
    ball = Ball("a", COAL, 0.03, (-0.1, 0.05, 0.0301), (2.0, 0.5, -1.0), (0.0, 0.0, 20.0))
    model = FrictionModel(FrictionSettings(0.3, 0.3, 1e-2, 2e-2))
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(friction_pairs, "_PLATE_MOMENT", moment)
        plate = StreamPlate(basis, np.zeros(basis.n_modes), residual_flexibility=False)
        fast = solve_stream([Particle.from_ball(ball, default_label(ball))], incline, 3e-3,
                            damping=0.0, rtol=RTOL, friction=model, progress=False,
                            rest_speed=0.0, plate=plate)  # fmt: skip
    st = fast.stats
    imbalance = (st["energy_released"] - st["energy_left"] - st["energy_final"]
                 - st["rest_energy_removed"] - st["energy_plate_final"]
                 - st["energy_friction"]) / st["energy_released"]  # fmt: skip
    print(f"moment {moment}: imbalance {imbalance:.2e}")
    assert st["energy_plate_final"] > 1e-4 * st["energy_released"]
    assert st["energy_friction"] > 1e-2 * st["energy_released"]
    if moment:
        assert abs(imbalance) < 1e-9
    else:
        assert abs(imbalance) > 1e-6
