"""Balls at rest with friction in the fast stream solver (rigid plate): resting clusters are
frozen (``tailbeam.solvers.stream.driver.sleep``), each check against an independent truth:
rigid-body closed forms with Coulomb friction and rolling resistance, the energy ledger, the
same scene integrated without sleeping (the regularised law's creep), and a run where the
struck ball never slept.

Coal balls, r = 30 mm, v_s = 1e-3 m/s, v_d = 2e-3 m/s, rtol 1e-10, set down at their static
penetration. The bound on a frozen ball's displacement is the creep it can make before it is
frozen: slip plus rolling, each below v_s at a contact within its limits (the rule itself
asks only a centre slower than the rest speed: ``test_friction_rest_heap``), for
SLEEP_DWELL plus one refresh interval (SET_HORIZON).
"""

import math
from dataclasses import replace

import numpy as np
import pytest

from tailbeam.physics.bodies import STANDARD_GRAVITY, Ball, Plate
from tailbeam.physics.contact_law import ball_plate_law
from tailbeam.physics.friction import FrictionModel, FrictionSettings
from tailbeam.physics.incline import InclinedPlate
from tailbeam.physics.materials import CARBON_STEEL, get_material
from tailbeam.solvers.stream.driver.loop import solve_stream
from tailbeam.solvers.stream.driver.membership import SET_HORIZON
from tailbeam.solvers.stream.driver.sleep import SLEEP_DWELL
from tailbeam.solvers.stream.driver.statics import in_equilibrium
from tailbeam.streams.generator import Particle, default_label

G = STANDARD_GRAVITY
R = 0.03
COAL = get_material("coal")
V_S = 1e-3
# m: the most a ball creeps before it is frozen where its contacts are within their limits:
# slip plus rolling, each below v_s
CREEP_BOUND = 2.0 * V_S * (SLEEP_DWELL + SET_HORIZON)


def static_pen(theta_deg: float) -> float:
    law = ball_plate_law(COAL, R, CARBON_STEEL, damping=300.0)
    m = Ball("m", COAL, R, (0.0, 0.0, R)).mass
    return (m * G * math.cos(math.radians(theta_deg)) / law.stiffness) ** (1.0 / law.exponent)


def ball(name, x, theta=0.0, velocity=(0.0, 0.0, 0.0), spin=(0.0, 0.0, 0.0), z=None):
    z = R - static_pen(theta) if z is None else z
    return Ball(name, COAL, R, (x, 0.0, z), velocity, spin)


def run(balls, theta, duration, *, rolling, static=0.5, sleep=True, frames=(), damping=300.0,
        release=None):  # fmt: skip
    """Simulate ``balls`` on the plate inclined ``theta`` degrees; ``release``: name -> its
    release time (s; default 0)."""
    model = FrictionModel(FrictionSettings(static, 0.4, V_S, 2 * V_S, rolling))
    particles = [Particle.from_ball(b, default_label(b)) for b in balls]
    times = release or {}
    particles = [replace(p, t_release=times.get(p.name, p.t_release)) for p in particles]
    return solve_stream(particles, InclinedPlate(Plate(), theta, G), duration, damping=damping,
                        rtol=1e-10, friction=model, progress=False, sleep=sleep,
                        frames=frames)  # fmt: skip


def ledger_gap(r) -> float:
    """Energy released minus every booked line (J): what damping took (>= 0: no gain), over
    the energy released; round-off (1e-12 of it) is taken off, so that no gain is >= 0."""
    s = r.stats
    booked = s["energy_final"] + s["energy_left"] + s["rest_energy_removed"]
    gap = (s["energy_released"] - booked - s["energy_friction"]) / abs(s["energy_released"])
    return gap + 1e-12


def test_statics_single_ball_is_the_closed_form():
    """A ball alone on the plate holds iff tan(theta) <= min(mu_s, mu_r R / (R - delta))."""
    x = [[0.0, 0.0, R]]
    cases = ((20, 0.5, True), (20, 0.3, False), (26, 0.5, True), (27, 0.5, False))
    for theta, mu_r, holds in cases:
        t = math.radians(theta)
        g = G * np.array([math.sin(t), 0.0, -math.cos(t)])
        assert in_equilibrium(x, [0.1], g, [(0, -1, 1.0, 0.7, mu_r, R)]) is holds
    g = G * np.array([math.sin(0.5), 0.0, -math.cos(0.5)])  # tan = 0.546 > mu_s = 0.5
    assert not in_equilibrium(x, [0.1], g, [(0, -1, 1.0, 0.5, 1.0, R)])


def test_held_ball_stays_exactly_at_rest():
    """tan 4 deg = 0.07 < mu_r = 0.1: frozen; from then on exactly still, where the
    regularised law alone creeps at ~0.87 v_s."""
    frames = (0.1, 0.2, 0.3)
    r = run([ball("a", -0.25, 4.0)], 4.0, 0.3, rolling=0.1, frames=frames)
    free = run([ball("a", -0.25, 4.0)], 4.0, 0.3, rolling=0.1, sleep=False)
    assert r.stats["sleeps"] == 1 and r.stats["asleep_final"] == 1
    x = [r.frames.position[k][0] for k in range(3)]
    assert np.array_equal(x[0], x[1]) and np.array_equal(x[1], x[2])
    assert np.array_equal(r.final["a"][1], np.zeros(3))
    moved = x[2][0] - (-0.25)
    assert 0.0 <= moved <= CREEP_BOUND
    crept = free.final["a"][0][0] - (-0.25)
    assert crept > 0.5 * V_S * 0.3  # the regularised law's creep (0.87 v_s measured)
    assert 0.0 <= ledger_gap(r) and r.stats["rest_energy_removed"] >= 0.0


def test_rolls_down_when_slope_beats_rolling_resistance():
    """tan 20 deg = 0.36 > mu_r = 0.1: never frozen, rolls at 5/7 g (sin - mu_r cos) from
    rest; the run is bit-identical to one with sleeping off (it never triggers)."""
    theta = math.radians(20.0)
    frames = (0.04, 0.08)
    r = run([ball("a", -0.25, 20.0)], 20.0, 0.08, rolling=0.1, frames=frames)
    off = run([ball("a", -0.25, 20.0)], 20.0, 0.08, rolling=0.1, frames=frames, sleep=False)
    assert r.stats.get("sleeps", 0) == 0 and r.stats["asleep_final"] == 0
    v1, v2 = (r.frames.velocity[k][0][0] for k in range(2))
    a = 5.0 / 7.0 * G * (math.sin(theta) - 0.1 * math.cos(theta))
    assert (v2 - v1) / 0.04 == pytest.approx(a, rel=1e-4)
    assert np.array_equal(r.final["a"][0], off.final["a"][0])
    assert np.array_equal(r.final["a"][1], off.final["a"][1])


def test_rolling_ball_stops_at_the_closed_form_time_and_stays():
    """On the horizontal plate a ball rolling at v0 = 0.1 m/s decelerates at 5/7 mu_r g and
    stops after v0 / (5/7 mu_r g) = 71 ms, s* = v0^2 / (2 a) = 3.6 mm; then it is frozen.
    Without damping the ledger closes: released = final + friction + removed (to 1e-9 of
    the energy released)."""
    v0, mu_r = 0.1, 0.2
    a = 5.0 / 7.0 * mu_r * G
    t_stop, s_stop = v0 / a, v0 * v0 / (2.0 * a)
    frames = tuple(np.arange(0.005, 0.2, 0.005))
    b = ball("a", 0.0, 0.0, velocity=(v0, 0.0, 0.0), spin=(0.0, v0 / R, 0.0))
    r = run([b], 0.0, 0.2, rolling=mu_r, frames=frames, damping=0.0)
    speed = np.array([abs(r.frames.velocity[k][0][0]) for k in range(len(frames))])
    x = np.array([r.frames.position[k][0][0] for k in range(len(frames))])
    # above v_s the deceleration is the closed form's
    fast = speed > 2 * V_S
    fit = np.polyfit(np.array(frames)[fast], speed[fast], 1)
    # the deceleration to the lever arm's r - delta; the stop time to v_s / a: rolling is
    # held by a slip below v_s, so the centre's speed is off the rim's by less than v_s
    assert -fit[0] == pytest.approx(a, rel=1e-4)
    assert fit[1] / a == pytest.approx(t_stop, abs=V_S / a)
    assert r.stats["sleeps"] == 1
    assert x[-1] == x[-2] and speed[-1] == 0.0  # frozen: exactly still
    assert abs(x[-1] - s_stop) <= CREEP_BOUND + V_S**2 / (2 * a) + 1e-4 * s_stop
    assert abs(ledger_gap(r)) <= 1e-9


def pile(mu_s=0.5):
    """Three coal balls in a triangle on the horizontal plate: two on the plate 1 mm apart,
    one on top of them."""
    h = R + 5e-4
    zb = R - static_pen(0.0)
    zt = zb + math.sqrt(4 * R * R - h * h)
    return [ball("a", -h, z=zb), ball("b", h, z=zb), ball("c", 0.0, z=zt)]


def test_pile_frozen_against_full_integration():
    """The triangle is frozen as one cluster; integrated without sleeping its bottom balls
    creep apart (the regularised law). Both runs are the same run until the freeze, so their
    final difference is the creep the full integration made after it."""
    t_end = 0.5
    r = run(pile(), 0.0, t_end, rolling=0.2, frames=(0.1,))
    free = run(pile(), 0.0, t_end, rolling=0.2, sleep=False, frames=(0.1,))
    assert r.stats["sleeps"] == 1 and r.stats["asleep_final"] == 3
    for name in "abc":
        assert np.array_equal(r.final[name][1], np.zeros(3))
    k = 0  # the frame at 0.1 s: the pile is frozen by then
    creep = max(np.linalg.norm(free.final[n][0] - free.frames.position[k][i])
                for i, n in enumerate("abc"))  # fmt: skip
    diff = max(np.linalg.norm(r.final[n][0] - free.final[n][0]) for n in "abc")
    assert creep > 1e-5  # the full integration creeps (~0.4 mm/s)
    assert diff <= creep + 2 * CREEP_BOUND
    assert r.stats["kernel_steps"] < 0.2 * free.stats["kernel_steps"]
    assert 0.0 <= ledger_gap(r) and 0.0 <= ledger_gap(free)


def test_struck_sleeper_wakes_as_if_it_never_slept():
    """Ball a rests (frozen after ~20 ms); ball b rolls into it at 0.5 m/s (mu_r = 0: no
    deceleration). a wakes, and after the strike both balls move as in the run where a was
    integrated all along (it stays exactly at rest there too: no tangential load)."""
    v0 = 0.5
    balls = [ball("a", 0.0), ball("b", -0.2, velocity=(v0, 0.0, 0.0), spin=(0.0, v0 / R, 0.0))]
    r = run(balls, 0.0, 0.4, rolling=0.0)
    ref = run(balls, 0.0, 0.4, rolling=0.0, sleep=False)
    assert r.stats["sleeps"] >= 1 and r.stats["wakes"] >= 1
    ball_ball = [c for c in r.contacts if c.partner == "a"]
    assert len(ball_ball) == 1 and ball_ball[0].t_start == pytest.approx(0.28, abs=0.01)
    m = balls[0].mass
    p = sum(m * r.final[n][1] for n in "ab")
    p_ref = sum(m * ref.final[n][1] for n in "ab")
    assert np.allclose(p, p_ref, rtol=0, atol=1e-6 * m * v0)
    for n in "ab":
        assert np.allclose(r.final[n][0], ref.final[n][0], rtol=0, atol=1e-6 * R)


def test_resting_lump_does_not_wake_its_frozen_neighbour():
    """Ball a is frozen; ball b is set down at rest 1 mm beside it (slow for 20 ms before it
    is frozen too) while ball c rolls at 1 m/s 0.2 m away. b can reach a within the set's
    horizon only with c's energy (1.3 mm in 1 ms), which no contact can bring to it before
    the set's next event: a is not woken. The full integration is the truth that a and b
    never touch."""
    gap, v0 = 1e-3, 1.0
    c = Ball("c", COAL, R, (-0.25, 0.2, R - static_pen(0.0)), (v0, 0.0, 0.0), (0.0, v0 / R, 0.0))
    balls = [ball("a", 0.0), ball("b", 2 * R + gap), c]
    late = {"b": 0.03}
    r = run(balls, 0.0, 0.12, rolling=0.2, release=late)
    free = run(balls, 0.0, 0.12, rolling=0.2, release=late, sleep=False)
    assert r.stats["sleeps"] >= 2 and r.stats.get("wakes", 0) == 0
    assert np.array_equal(r.final["a"][1], np.zeros(3))
    assert not [k for k in free.contacts if k.partner in "ab" and k.ball in "ab"]
    assert 0.0 <= ledger_gap(r)


def beside(gap: float, v0: float = 0.014) -> list:
    """Ball a at rest; ball b ``gap`` beside it (along x), rolling along y at ``v0``: rolling
    resistance stops it in v0 / (5/7 mu_r g) (10 ms at mu_r = 0.2) after 70 µm, so b is slow
    about 10 ms after a and the gap stays within 0.05 µm of ``gap``."""
    b = ball("b", 2 * R + gap, velocity=(0.0, v0, 0.0), spin=(-v0 / R, 0.0, 0.0))
    return [ball("a", 0.0), b]


def test_lump_resting_close_beside_a_frozen_one_leaves_it_asleep():
    """a is frozen (at ~20 ms) while b, 0.1 mm beside it, still comes to rest (frozen ~10 ms
    later). Touching nothing else, b can gain only what gravity gives it within the set's
    horizon (``reach``: at most 2 g h plus its own energy's speed, ~25 µm in 1 ms), so it
    cannot reach a and a is not woken. The full integration is the truth that they never
    touch; both end where it holds them, up to the creep before freezing."""
    balls = beside(1e-4)
    r = run(balls, 0.0, 0.1, rolling=0.2)
    free = run(balls, 0.0, 0.1, rolling=0.2, sleep=False)
    assert r.stats["sleeps"] == 2 and r.stats.get("wakes", 0) == 0
    assert not [k for k in free.contacts if k.partner in "ab" and k.ball in "ab"]
    for n in "ab":
        assert np.linalg.norm(r.final[n][0] - free.final[n][0]) <= CREEP_BOUND
    assert 0.0 <= ledger_gap(r)


def test_resting_neighbours_are_frozen_without_waking_each_other():
    """As above 5 µm apart, within the reach of b: a is frozen first and is a FIXED obstacle
    of the set while b could reach it; b never touches it, so a is not woken, and b is
    frozen ~10 ms later. The full integration is the truth that they never touch; both end
    where it holds them, up to the creep before freezing."""
    balls = beside(5e-6)
    r = run(balls, 0.0, 0.1, rolling=0.2)
    free = run(balls, 0.0, 0.1, rolling=0.2, sleep=False)
    assert r.stats["sleeps"] == 2 and r.stats.get("wakes", 0) == 0
    assert r.stats["asleep_final"] == 2 and r.stats["fixed_obstacles"] >= 1
    assert not [k for k in free.contacts if k.partner in "ab" and k.ball in "ab"]
    for n in "ab":
        assert np.linalg.norm(r.final[n][0] - free.final[n][0]) <= CREEP_BOUND
    assert 0.0 <= ledger_gap(r)
