"""Frozen lumps as FIXED obstacles (``tailbeam.solvers.stream.driver.sleep``): the kernel's
FIXED ball against closed forms, and a lump settling on frozen ones against the same scene
integrated without sleeping.

The kernel (``ActiveSet`` with ``Model.fix``): a ball striking a FIXED ball feels the pair's
IMPACT law and friction as from a ball that does not move, so the collision is that of the
striking ball alone with the pair's law: its own mass in Hertz's contact duration, an elastic
rebound, the impulse all its own; the FIXED ball's state does not change at all.
"""

import math
import sys
from pathlib import Path

import numpy as np

from tailbeam.physics.bodies import STANDARD_GRAVITY as G
from tailbeam.physics.bodies import Ball
from tailbeam.physics.contact_law import ball_plate_law
from tailbeam.physics.friction import FrictionModel, FrictionSettings
from tailbeam.physics.hertz import hertz_contact_duration
from tailbeam.physics.materials import CARBON_STEEL, get_material
from tailbeam.results.records import PLATE, EventCode
from tailbeam.solvers.stream.active.compiled.friction import IMP_N, IMP_T, IMP_WORK
from tailbeam.solvers.stream.active.friction_pairs import FrictionPairs
from tailbeam.solvers.stream.active.integrator.set import ActiveSet, pair_laws

sys.path.insert(0, str(Path(__file__).parent))
from test_friction_rest import V_S, R, ball, ledger_gap, run, static_pen  # noqa: E402

COAL = get_material("coal")
V0 = 0.5  # m/s


def strike(velocity, friction=None):
    """Ball 0 (coal, r = 30 mm) striking FIXED ball 1 at ``velocity`` (m/s), no gravity, far
    from the plate: (the set, contact start time s, end time s)."""
    balls = [Ball("s", COAL, R, (-2 * R - 1e-7, 0.0, 0.5), velocity), Ball("f", COAL, R,
             (0.0, 0.0, 0.5))]  # fmt: skip
    pairs = [(0, 1)]
    laws = pair_laws(
        balls, pairs, CARBON_STEEL, damping=0.0, penetration=1e-4, exponent=1.5, clamp=True
    )
    table = None
    if friction is not None:
        fp = FrictionPairs(friction, ["coal", "coal"], [R, R], CARBON_STEEL.name)
        table = fp.table(pairs)
    s = ActiveSet([b.position for b in balls], [b.velocity for b in balls],
                  [b.mass for b in balls], [R, R], pairs, laws, np.zeros(3), (0.6, 0.3),
                  rtol=1e-10, friction=table)  # fmt: skip
    s.model.fix(1)
    t, times = 0.0, []
    while len(times) < 2:
        out = s.advance(t, 1.0)
        t = out.t
        assert out.code in (EventCode.CONTACT_START, EventCode.CONTACT_END)
        times.append(t)
    return s, balls, times


def test_head_on_strike_of_a_fixed_ball_is_an_elastic_rebound_off_a_wall():
    """c = 0, head on: the striking ball leaves at -v0 (energy conserved), after Hertz's
    duration with its own mass (a free partner of equal mass would halve the mass: a 2^(2/5)
    shorter contact); the FIXED ball's position and velocity are exactly what they were."""
    s, balls, (t0, t1) = strike((V0, 0.0, 0.0))
    law = pair_laws(
        balls, [(0, 1)], CARBON_STEEL, damping=0.0, penetration=1e-4, exponent=1.5, clamp=True
    )[0]
    expected = hertz_contact_duration(balls[0].mass, V0, law.stiffness, law.exponent)
    assert abs((t1 - t0) - expected) <= 1e-6 * expected
    assert np.allclose(s.v[0], [-V0, 0.0, 0.0], rtol=0.0, atol=1e-8 * V0)
    assert np.array_equal(s.x[1], [0.0, 0.0, 0.5]) and np.array_equal(s.v[1], np.zeros(3))


def test_oblique_strike_in_gross_slip_gives_the_fixed_ball_nothing():
    """Friction mu = 0.3 (static = dynamic), c = 0, the strike sliding throughout (v_t = 3
    m/s: the slip it can lose, mu J_n (1/m + R^2/I) = 2.6 m/s, is less): the tangential
    force is mu times the normal one (Coulomb), so the tangential impulse is mu J_n shortened
    by at most the cosine of the turn of the contact normal during the strike; the striking
    ball's kinetic energy, rotation included, falls by exactly the work friction did (the
    FIXED ball does none: the ledger of a fixed obstacle); its momentum along the line of
    centres turns by the normal impulse (to the normal's turn during the contact); the
    FIXED ball's state, spin too, is exactly unchanged."""
    mu, vt = 0.3, 3.0
    model = FrictionModel(FrictionSettings(mu, mu, 1e-3, 2e-3, 0.0))
    s, balls, _ = strike((V0, 0.0, vt), model)
    imp = s.contacts.imp[0]
    jn, jt = imp[IMP_N], imp[IMP_T : IMP_T + 3]
    turn = math.acos(float(np.clip((s.x[0] - s.x[1])[0] / np.linalg.norm(s.x[0] - s.x[1]),
                                   -1.0, 1.0)))  # (the normal's turn from -x)  # fmt: skip
    assert math.cos(turn) * mu * jn * (1 - 1e-9) <= np.linalg.norm(jt) <= mu * jn * (1 + 1e-9)
    m = balls[0].mass
    before = 0.5 * m * (V0**2 + vt**2)
    after = 0.5 * m * float(s.v[0] @ s.v[0]) + 0.2 * m * R * R * float(s.w[0] @ s.w[0])
    assert abs(before - after - imp[IMP_WORK]) <= 1e-8 * before
    assert abs(m * (s.v[0][0] - V0) - (-jn + jt[0])) <= 5e-3 * jn
    assert np.array_equal(s.x[1], [0.0, 0.0, 0.5]) and np.array_equal(s.v[1], np.zeros(3))
    assert np.array_equal(s.w[1], np.zeros(3))


def late_triangle():
    """Two coal balls 1 mm apart on the horizontal plate (frozen at 20 ms) and a third
    released at 30 ms 1 µm above where it rests on them: it lands at 4 mm/s (below
    WAKE_SPEED), so the two stay asleep, FIXED obstacles, until its load says otherwise."""
    h = R + 5e-4
    zb = R - static_pen(0.0)
    zt = zb + math.sqrt(4 * R * R - h * h) + 1e-6
    return [ball("a", -h, z=zb), ball("b", h, z=zb), ball("c", 0.0, z=zt)]


def test_lump_settling_on_frozen_ones_against_full_integration():
    """c lands slowly on a and b while they are asleep (FIXED obstacles: no wake at the
    touch); under its landing's loads their statics fail and they wake at the next check,
    and the three are frozen together once all are ready. Truths: while a ball is asleep it
    does not move (every 2 ms frame where its velocity is exactly 0 finds it where the last
    one did); the full integration (``sleep=False``), identical until a and b freeze, where
    they then creep on (the regularised law): c's path differs from it by at most twice the
    largest distance D(t) a or b has crept there since their freeze (c rests on them at
    60 deg from the horizontal: its rest point follows their centres by 1/sin 60 = 1.15 of
    their displacement; the factor 2 leaves room for its landing's transient), plus what
    they sink into the plate under c's weight in the full integration, (Hertz) the static
    penetration under 1.5 m g less that under m g (fixed obstacles do not sink: the
    compliance of a frozen ball's own contacts is what a fixed obstacle leaves out) and,
    after c is frozen, the creep 2 v_s per second it makes on them in the full integration.
    The ledger never gains."""
    frames = tuple(np.round(np.arange(0.02, 0.0801, 0.002), 6))
    late = {"c": 0.03}
    r = run(late_triangle(), 0.0, 0.08, rolling=0.2, release=late, frames=frames)
    free = run(late_triangle(), 0.0, 0.08, rolling=0.2, release=late, sleep=False,
               frames=frames)  # fmt: skip
    assert r.stats["fixed_obstacles"] >= 1 and r.stats["asleep_final"] == 3
    touch = min(k.t_start for k in r.contacts if k.ball == "c" and k.partner in "ab")
    woke = min(k.t_start for k in r.contacts if k.ball in "ab" and k.partner == PLATE
               and k.t_start > 0.0)  # (a woken ball's plate contact starts again)  # fmt: skip
    assert touch < woke  # c touched them while they slept (FIXED obstacles)
    t_c = max(k.t_end for k in r.contacts if k.ball == "c")  # c frozen (records end rest)
    pos, vel = r.frames.position, r.frames.velocity
    for k in range(1, len(frames)):
        for i in range(3):
            if not vel[k][i].any() and not vel[k - 1][i].any():
                assert np.array_equal(pos[k][i], pos[k - 1][i])
    law = ball_plate_law(COAL, R, CARBON_STEEL, damping=300.0)
    m = Ball("m", COAL, R, (0.0, 0.0, R)).mass
    pen = [(w * m * G / law.stiffness) ** (1.0 / law.exponent) for w in (1.0, 1.5)]
    sink = pen[1] - pen[0]  # a and b sink under half of c's weight each; fixed, they do not
    fp = free.frames.position
    for k, t in enumerate(frames):
        if t < late["c"]:  # (c not released yet)
            continue
        crept = max(np.linalg.norm(fp[k][i] - fp[0][i]) for i in range(2))
        bound = 2.0 * crept + sink + 2.0 * V_S * max(0.0, t - t_c)  # (c creeps after t_c)
        assert np.linalg.norm(pos[k][2] - fp[k][2]) <= bound
    assert r.stats["kernel_steps"] < free.stats["kernel_steps"]
    assert 0.0 <= ledger_gap(r)
