"""The rest rule's statics in heaps (``tailbeam.solvers.stream.driver.sleep``): a cluster is
frozen when its balls' centres are slow and its rigid statics hold, whatever its contacts
creep at; a contact sliding at v_s or faster is held to what sliding friction gives.

Each check against an independent truth: the statics of a frictional triangle in closed
form, the same scene integrated without sleeping (the regularised law's creep), the closed
form of a ball sliding down a slope, and a one-set run (loads). Coal balls, r = 30 mm,
v_s = 1e-3 m/s, v_d = 2e-3 m/s, rtol 1e-10, as ``test_friction_rest``.
"""

import math

import numpy as np
import pytest
from test_friction_rest import COAL, V_S, G, R, ball, ledger_gap, pile

from tailbeam.physics.bodies import Ball, Plate
from tailbeam.physics.friction import FrictionModel, FrictionSettings
from tailbeam.physics.incline import InclinedPlate
from tailbeam.results.records import End
from tailbeam.solvers.stream.active.plate.forces import THIN
from tailbeam.solvers.stream.driver import loop
from tailbeam.solvers.stream.driver.statics import in_equilibrium
from tailbeam.streams.generator import Particle, default_label


def run(balls, theta, duration, *, static, dynamic, rolling, sleep=True, frames=()):
    """Simulate ``balls`` on the plate inclined ``theta`` degrees (damping 300 N s/m)."""
    model = FrictionModel(FrictionSettings(static, dynamic, V_S, 2 * V_S, rolling))
    particles = [Particle.from_ball(b, default_label(b)) for b in balls]
    return loop.solve_stream(particles, InclinedPlate(Plate(), theta, G), duration,
                             damping=300.0, rtol=1e-10, friction=model, progress=False,
                             sleep=sleep, frames=frames)  # fmt: skip


def triangle_mu_min(alpha: float) -> float:
    """The least friction coefficient (plate and balls alike) at which two balls on the
    horizontal plate hold a third resting on them, its contacts at ``alpha`` (rad) from the
    vertical, rolling resistance ample. The top ball's weight W takes N (cos a + mu sin a) =
    W / 2 at each contact with its friction at the limit mu N; the horizontal push
    N (sin a - mu cos a) on a bottom ball is held by the plate under 3 W / 2 when it is at
    most mu 3 W / 2: 3 sin(a) mu^2 + 4 cos(a) mu - sin(a) >= 0."""
    s, c = math.sin(alpha), math.cos(alpha)
    return (-4.0 * c + math.sqrt(16.0 * c * c + 12.0 * s * s)) / (6.0 * s)


def test_triangle_statics_is_the_closed_form():
    """The linear program holds the triangle of ``pile`` iff mu >= ``triangle_mu_min`` (the
    forces lie along the octagons' vertices: exact)."""
    balls = pile()
    x = np.array([b.position for b in balls])
    d = x[2] - x[0]
    mu_min = triangle_mu_min(math.acos(d[2] / np.linalg.norm(d)))
    assert 0.13 < mu_min < 0.15
    mass = [b.mass for b in balls]
    g = np.array([0.0, 0.0, -G])

    def holds(mu):
        share = 0.5
        rows = [(0, -1, 1.0, mu, 0.5, R), (1, -1, 1.0, mu, 0.5, R),
                (2, 0, share, mu, 0.5, R / 2), (2, 1, share, mu, 0.5, R / 2)]  # fmt: skip
        return in_equilibrium(x, mass, g, rows)

    assert holds(1.01 * mu_min) and not holds(0.99 * mu_min)


def test_creeping_triangle_is_frozen_where_the_full_integration_was():
    """mu = 0.2: the triangle can stand (``triangle_mu_min`` = 0.14), but the regularised law
    never holds it: its bottom balls creep apart at ~0.8 v_s for ever and its top contacts
    slip faster than v_s. The rule freezes it (a rule asking every contact to creep below
    v_s never would); it is frozen exactly where the full integration was at that instant
    (the same run until then), and the full integration creeps on after it."""
    mu = 0.2
    r = run(pile(), 0.0, 0.3, static=mu, dynamic=mu, rolling=0.5)
    assert r.stats["sleeps"] == 1 and r.stats["asleep_final"] == 3
    rests = [c.t_end for c in r.contacts if c.end == End.REST]
    t_freeze = rests[0]
    assert len(rests) >= 5 and all(t == t_freeze for t in rests)  # 3 plate + 2 ball pairs
    assert t_freeze < 0.05
    free = run(pile(), 0.0, 0.3, static=mu, dynamic=mu, rolling=0.5, sleep=False,
               frames=(t_freeze,))  # fmt: skip
    for q, name in enumerate("abc"):
        assert np.array_equal(r.final[name][1], np.zeros(3))
        at_freeze = free.frames.position[0][q]
        # the same run until the freeze (the frame stops the integration there: rtol)
        assert np.linalg.norm(r.final[name][0] - at_freeze) <= 1e-9
    bottom_speed = np.linalg.norm(free.final["a"][1])
    assert 0.5 * V_S < bottom_speed < 2 * V_S  # creeps on (0.88 v_s measured)
    crept = np.linalg.norm(free.final["a"][0] - free.frames.position[0][0])
    assert crept > 0.5 * V_S * (0.3 - t_freeze)
    assert r.stats["kernel_steps"] < 0.3 * free.stats["kernel_steps"]
    assert 0.0 <= ledger_gap(r) and 0.0 <= ledger_gap(free)


def test_slow_slide_steeper_than_dynamic_friction_is_not_frozen():
    """tan(theta) = 0.31 lies between mu_d = 0.3 and mu_s = 0.5: a ball sliding at 3 mm/s
    (rolling held by mu_r = 0.5) stays slower than the rest speed for ~75 ms, but sliding
    friction cannot hold it, so its statics (the sliding contact at mu_d) refuse it. It
    slides on at g (sin - mu_d cos) (closed form, to 1e-9), bit for bit as the run without
    sleeping; held to mu_s the statics would freeze it at ~20 ms."""
    theta = math.degrees(math.atan(0.31))
    v0 = 3e-3
    b = Ball("a", COAL, R, ball("a", -0.25, theta).position, (v0, 0.0, 0.0))
    kw = dict(static=0.5, dynamic=0.3, rolling=0.5, frames=(0.05, 0.1))
    r = run([b], theta, 0.1, **kw)
    off = run([b], theta, 0.1, sleep=False, **kw)
    assert r.stats.get("sleeps", 0) == 0 and r.stats["sleep_refused"] >= 1
    t = math.radians(theta)
    a = G * (math.sin(t) - 0.3 * math.cos(t))
    v1, v2 = (r.frames.velocity[k][0][0] for k in range(2))
    assert v1 < 0.01  # slow (below the rest speed) for the dwell and more
    assert (v2 - v1) / 0.05 == pytest.approx(a, rel=1e-9)
    assert np.array_equal(r.final["a"][0], off.final["a"][0])
    assert np.array_equal(r.final["a"][1], off.final["a"][1])


def test_lazy_force_rows_give_the_one_set_loads(monkeypatch):
    """Islands drain their plate force rows lazily (when a ball's history is taken); a lump
    landing and rolling alone is one island, integrated as one set is: its plate load has
    the same impulse and peak as the one set's, drained after every call (within what the
    thinning of either may move them: THIN of the peak over the contact's duration)."""
    b = Ball("a", COAL, R, (-0.25, 0.0, 0.05), (0.2, 0.0, -0.5))
    kw = dict(static=0.5, dynamic=0.4, rolling=0.05)
    lazy = run([b], 20.0, 0.15, **kw)
    monkeypatch.setattr(loop, "_ISLANDS", False)
    eager = run([b], 20.0, 0.15, **kw)

    def impulse_and_peak(r):
        total, peak = 0.0, 0.0
        for _x, _y, t, f in r.loads:
            total += float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(t)))
            peak = max(peak, float(np.max(f)))
        return total, peak

    (j_lazy, p_lazy), (j_eager, p_eager) = impulse_and_peak(lazy), impulse_and_peak(eager)
    assert j_lazy > 0.0 and len(lazy.loads) >= 1
    assert j_lazy == pytest.approx(j_eager, rel=0.0, abs=2.0 * THIN * p_eager * 0.15)
    assert p_lazy == pytest.approx(p_eager, rel=1e-12)
