"""The fast stream solver (tailbeam.solvers.stream.driver.loop) against independent truths.

- the slow reference (tailbeam.solvers.stream.reference.solver: scipy DOP853 over all balls, every
  pair watched) on scenes with ball-ball contacts, a 3-ball cluster, a stacked pair, the
  kinks of the damped law and balls leaving over the edges: every Impact field within
  1e-6 (the issue's rigid-plate bound; measured <= 3.5e-8);
- the energy ledger with 100+ balls: conserved (c = 0) and never gained (c > 0);
- closed forms: a ball resting on the frictionless incline slides off at
  x0 + v t + g sin(theta) t^2 / 2 = a/2; a ball at rest on a horizontal plate stays there;
- no contact found late (the audit of the certified predictions) in a dense stream;
- the modal plate driven by the stream's plate loads = the one-way coupled solver.
"""

import math
from dataclasses import replace

import numpy as np
import pytest
from stream_scenes import leave_scene, static_penetration_on, ten_ball_scene

from tailbeam import COAL, SANDSTONE
from tailbeam.physics.incline import InclinedPlate
from tailbeam.solvers.stream.driver.loop import solve_stream
from tailbeam.solvers.stream.reference.solver import simulate_stream_reference
from tailbeam.streams.generator import Particle, generate_particles

FIELDS = ("t_start", "t_end", "v_in", "v_out", "approach_in", "approach_out", "peak_force",
          "t_peak", "max_penetration", "x", "y")  # fmt: skip
TIME_SCALE = 1e-3  # s: contact times compared on the scale of a contact (~0.1-1 ms)


def _particles(balls, release=None):
    release = release or [0.0] * len(balls)
    return [
        Particle(b.name, "", "coal", b.material, b.radius, b.mass, t, tuple(b.position),
                 tuple(b.velocity))
        for b, t in zip(balls, release, strict=True)
    ]  # fmt: skip


def _worst_difference(ref, fast) -> float:
    """Largest relative difference over every field of every contact (times on the contact
    scale, speeds and positions on 1 m/s and 1 m); the records must pair up one to one."""

    def key(r):
        return (r.ball, r.partner, round(r.t_start, 7))

    a, b = sorted(ref, key=key), sorted(fast, key=key)
    assert [(r.ball, r.partner, r.end) for r in a] == [(r.ball, r.partner, r.end) for r in b]
    worst = 0.0
    for ra, rb in zip(a, b, strict=True):
        for f in FIELDS:
            va, vb = getattr(ra, f), getattr(rb, f)
            if math.isnan(va) and math.isnan(vb):
                continue
            scale = TIME_SCALE if f.startswith("t_") else abs(va) if f in (
                "peak_force", "max_penetration") else 1.0  # fmt: skip
            worst = max(worst, abs(va - vb) / scale)
    return worst


def _ten(c, d):
    incline = InclinedPlate(inclination=15.0)
    return ten_ball_scene(incline), incline, dict(damping=c, penetration=d)


@pytest.mark.parametrize(
    ("scene", "duration"),
    [(lambda: _ten(0.0, 1e-4), 0.25), (lambda: _ten(2000.0, 2e-5), 0.1),
     (lambda: (leave_scene(InclinedPlate(inclination=30.0)), InclinedPlate(inclination=30.0),
               {}), 0.6)],
    ids=["ten_balls_elastic", "ten_balls_damped_clamp", "leaving_balls"],
)  # fmt: skip
def test_matches_the_reference(scene, duration):
    balls, incline, law = scene()
    ref = simulate_stream_reference(balls, incline, duration, **law)
    fast = solve_stream(_particles(balls), incline, duration, rtol=1e-12, rest_speed=0.0,
                        progress=False, **law)  # fmt: skip
    assert len(fast.contacts) == len(ref.contacts) >= 4
    assert _worst_difference(ref.contacts, fast.contacts) < 1e-6
    assert [(e.ball, e.edge) for e in fast.leaves] == [(e.ball, e.edge) for e in ref.leaves]
    for e_ref, e_fast in zip(ref.leaves, fast.leaves, strict=True):
        assert e_fast.time == pytest.approx(e_ref.time, abs=1e-9)
    assert fast.stats["late_starts"] == 0


def _stream(rate=400.0, stop=0.3, seed=5, inclination=0.0, **extra):
    incline = InclinedPlate(inclination=inclination)
    settings = dict(name="s", rate=rate, start=0.0, stop=stop, gangue_fraction=0.3,
                    radius=[0.01, 0.03], area=[[-0.15, 0.15], [-0.15, 0.15]],
                    height=[0.02, 0.2], velocity=[0.0, 0.0, -1.0], velocity_spread=0.5,
                    seed=seed, **extra)  # fmt: skip
    return generate_particles([settings], incline), incline


def test_generated_stream_matches_the_reference():
    """A generated stream (releases over time, ball-ball contacts in flight, leaves)."""
    particles, incline = _stream(rate=40.0, stop=0.2, seed=3, inclination=20.0)
    balls = [p.ball() for p in particles]
    ref = simulate_stream_reference(balls, incline, 0.6, damping=500.0,
                                    release_times=[p.t_release for p in particles])  # fmt: skip
    fast = solve_stream(particles, incline, 0.6, damping=500.0, rtol=1e-12, rest_speed=0.0,
                        progress=False)  # fmt: skip
    assert len(fast.leaves) == len(ref.leaves) >= 5
    assert _worst_difference(ref.contacts, fast.contacts) < 1e-6


def _imbalance(run) -> float:
    st = run.stats
    return st["energy_released"] - st["energy_left"] - st["energy_final"] - st[
        "rest_energy_removed"]  # fmt: skip


@pytest.mark.parametrize("inclination", [0.0, 20.0])
def test_energy_is_conserved_without_damping(inclination):
    """143 balls, c = 0: energy released = energy carried off the edges + energy at the end
    + the normal energy dropped by the rest rules, to 1e-9 (measured ~8e-12)."""
    particles, incline = _stream(inclination=inclination)
    run = solve_stream(particles, incline, 0.5, rtol=1e-12, progress=False)
    assert len(particles) >= 100 and len(run.contacts) > 500 and len(run.leaves) > 50
    assert abs(_imbalance(run)) < 1e-9 * run.stats["energy_released"]
    assert run.stats["late_starts"] == 0


def test_ball_leaving_in_a_contact_takes_the_contact_energy_with_it():
    """b overtakes a in flight and a's centre passes the x+ edge 0.05 mm after their contact
    starts: the contact ends with a, so its whole elastic energy leaves (half of it, a's
    share only, left the ledger short by the other half: 1.3 % of the released energy)."""
    incline = InclinedPlate()
    r, gap, va, vb = 0.02, 0.002, 1.0, 3.0
    t_touch = gap / (vb - va)
    xa = incline.half_sizes[0] - va * t_touch - 5e-5
    a = Particle("a", "", "coal", COAL, r, COAL.density * 4 / 3 * math.pi * r**3, 0.0,
                 (xa, 0.0, 0.3), (va, 0.0, 0.0))  # fmt: skip
    b = replace(a, name="b", position=(xa - 2 * r - gap, 0.0, 0.3), velocity=(vb, 0.0, 0.0))
    run = solve_stream([a, b], incline, 0.05, rtol=1e-12, progress=False)
    assert [(c.ball, c.partner, c.end) for c in run.contacts] == [("a", "b", "left"),
                                                                  ("b", "a", "left")]  # fmt: skip
    assert [e.ball for e in run.leaves][:1] == ["a"]
    assert abs(_imbalance(run)) < 1e-9 * run.stats["energy_released"]


def test_energy_never_increases_with_damping():
    particles, incline = _stream(inclination=10.0)
    run = solve_stream(particles, incline, 0.5, damping=300.0, rtol=1e-12, progress=False)
    dissipated = _imbalance(run)
    assert dissipated > 0.0  # the damping took energy ...
    assert dissipated > -1e-9 * run.stats["energy_released"]  # ... and none was created


def test_resting_ball_slides_off_the_incline_at_the_closed_form_time():
    """A ball at its static penetration on a frictionless 30-degree plate comes to rest
    (SETTLE at once), slides in closed form and leaves over the downhill edge."""
    incline = InclinedPlate(inclination=30.0)
    r = 0.02
    z = r - static_penetration_on(SANDSTONE, r, incline)
    x0, y0, vx, vy = -0.1, 0.05, 0.2, 0.1
    p = Particle("b", "", "gangue", SANDSTONE, r, SANDSTONE.density * 4 / 3 * math.pi * r**3,
                 0.0, (x0, y0, z), (vx, vy, 0.0))  # fmt: skip
    run = solve_stream([p], incline, 2.0, progress=False)
    a = incline.gravity * math.sin(math.radians(30.0))
    t_leave = (-vx + math.sqrt(vx * vx + 2 * a * (0.3 - x0))) / a
    assert [(e.ball, e.edge) for e in run.leaves] == [("b", "x+")]
    assert run.leaves[0].time == pytest.approx(t_leave, abs=1e-12)
    assert [c.end for c in run.contacts] == ["rest"]


def test_ball_at_rest_on_a_horizontal_plate_stays():
    incline = InclinedPlate()
    r = 0.03
    z = r - static_penetration_on(COAL, r, incline)
    p = Particle("b", "", "coal", COAL, r, COAL.density * 4 / 3 * math.pi * r**3, 0.0,
                 (0.0, 0.0, z), (0.0, 0.0, 0.0))  # fmt: skip
    run = solve_stream([p], incline, 5.0, progress=False)
    assert not run.leaves and len(run.contacts) == 1 and run.contacts[0].end == "rest"
    assert run.stats["kernel_steps"] < 100  # resting costs nothing over 5 s
    assert abs(_imbalance(run)) < 1e-12


def test_dense_stream_finds_every_contact_on_time():
    """The audit: no ball ever enters the active set already overlapping something (a
    contact the predictions missed), in a dense, colliding stream on the 30-degree plate."""
    particles, incline = _stream(rate=800.0, stop=0.2, seed=11, inclination=30.0)
    run = solve_stream(particles, incline, 0.5, damping=300.0, progress=False)
    balls = sum(1 for c in run.contacts if c.partner != "plate")
    assert balls > 100 and run.stats["late_starts"] == 0


def test_modal_plate_under_stream_loads_matches_the_one_way_solver():
    """Two balls (no ball-ball contact) on the closed-form SSSS plate: the stream solver's
    plate loads through tailbeam.solvers.plate_loads.response = tailbeam.solvers.coupled's one-way
    solver (the rigid solver + dense replay), at a sensor point over 20 ms."""
    from tailbeam import Ball, ball_plate_law
    from tailbeam.physics.bodies import Plate
    from tailbeam.physics.materials import CARBON_STEEL
    from tailbeam.plate.closed_forms import ssss_kirchhoff_basis
    from tailbeam.solvers.coupled.oneway import simulate_one_way
    from tailbeam.solvers.plate_loads.loads import PlateLoads
    from tailbeam.solvers.plate_loads.response import plate_response

    basis = ssss_kirchhoff_basis(Plate(), 5000.0)
    balls = [Ball("a", COAL, 0.02, (0.05, 0.02, 0.03), (0.0, 0.0, -2.0)),
             Ball("b", SANDSTONE, 0.015, (-0.1, 0.1, 0.05), (0.0, 0.0, -3.0))]  # fmt: skip
    laws = [ball_plate_law(b.material, b.radius, CARBON_STEEL, damping=300.0) for b in balls]
    one_way = simulate_one_way(balls, basis, laws, 0.02)
    run = solve_stream(_particles(balls), InclinedPlate(), 0.02, damping=300.0, progress=False)
    loads = PlateLoads()
    for x, y, t, f in run.loads:
        loads.add_contact(x, y, t, f)
    times = np.arange(2048) * (0.02 / 2048)
    point = np.array([[0.12, -0.08]])
    want = one_way.plate.sample(times, point, quasi_static=False)["a"][0]
    got = plate_response(basis, one_way.plate.zeta, loads, point, times, quasi_static=False)["a"][0]
    assert np.linalg.norm(got - want) < 1e-4 * np.linalg.norm(want)


# --- the modal plate, two-way ---------------------------------------------------------------


def _ssss(fmax=5000.0):
    from tailbeam.physics.bodies import Plate
    from tailbeam.plate.closed_forms import ssss_kirchhoff_basis

    return ssss_kirchhoff_basis(Plate(), fmax)


@pytest.mark.parametrize("damping", [0.0, 800.0])
def test_two_way_single_ball_matches_the_coupled_solver(damping):
    """One sandstone ball at 2 m/s on the closed-form SSSS plate (52 modes, 1 % damping)
    through the whole stream solver (landing on the vibrating plate, the active set with its
    modal block) against the two-way coupled single-ball solver without residual flexibility
    (an independent integrator, 2nd order in its step: Richardson from 800 and 1600 steps
    per contact)."""
    from tailbeam import Ball, ball_plate_law
    from tailbeam.physics.materials import CARBON_STEEL
    from tailbeam.solvers.coupled import simulate_coupled
    from tailbeam.solvers.stream.plate import StreamPlate

    basis = _ssss()
    r = 0.03
    ball = Ball("s", SANDSTONE, r, (0.07, -0.05, r + 1e-4), (0.0, 0.0, -2.0))
    law = ball_plate_law(SANDSTONE, r, CARBON_STEEL, damping=damping)

    def coupled(steps):
        res = simulate_coupled([ball], basis, [law], 1e-3, gravity=InclinedPlate().gravity,
                               damping_ratio=0.01, residual_flexibility=False,
                               steps_per_contact=steps)  # fmt: skip
        imp = res.impacts[0]
        return np.array([imp.t_end, imp.v_out, imp.peak_force])

    plate = StreamPlate(basis, np.full(basis.n_modes, 0.01), residual_flexibility=False)
    run = solve_stream(_particles([ball]), InclinedPlate(), 1e-3, damping=damping, rtol=1e-12,
                       progress=False, plate=plate)  # fmt: skip
    first = run.contacts[0]
    ours = np.array([first.t_end, first.v_out, first.peak_force])
    a, b = coupled(800), coupled(1600)
    truth = b + (b - a) / 3.0
    assert np.all(np.abs(ours - truth) < 1e-8 * np.abs(truth))
    assert run.stats["late_starts"] == 0


@pytest.mark.parametrize("residual", [True, False], ids=["residual", "no_residual"])
def test_two_way_energy_is_conserved(residual):
    """c = 0 and undamped modes: the energy released is found in the balls that left, the
    balls at the end (their contacts' elastic energy with the residual spring's C F^2 / 2)
    and the plate's vibration (the modes took part in every contact)."""
    from tailbeam.solvers.stream.plate import StreamPlate

    basis = _ssss(3000.0)
    particles, incline = _stream(rate=100.0, stop=0.2, seed=2)
    plate = StreamPlate(basis, np.zeros(basis.n_modes), residual_flexibility=residual)
    run = solve_stream(particles, incline, 0.3, rtol=1e-12, rest_speed=0.0, progress=False,
                       plate=plate)  # fmt: skip
    st = run.stats
    assert len(run.contacts) > 20 and st["energy_plate_final"] > 1e-6 * st["energy_released"]
    imbalance = _imbalance(run) - st["energy_plate_final"]
    print(f"two-way energy imbalance / released: {imbalance / st['energy_released']:.2e}")
    assert abs(imbalance) < 1e-9 * st["energy_released"]
    assert st["late_starts"] == 0
