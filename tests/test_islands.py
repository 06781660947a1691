"""The active set as islands (``tailbeam.solvers.stream.active.islands``; friction, rigid
plate), each against an independent truth: lumps far apart integrated together are each the
lump integrated alone, and lumps that collide meet as in one set integrating them all (the
private switch ``loop._ISLANDS`` off), the contact between them found.

Coal balls, r = 30 mm, set down rolling on the plate inclined 20 degrees, friction
mu_s = 0.5, mu_d = 0.4, mu_r = 0.1, damping 300 N s/m, rtol 1e-10.
"""

import math

import numpy as np

from tailbeam.physics.bodies import STANDARD_GRAVITY, Ball, Plate
from tailbeam.physics.contact_law import ball_plate_law
from tailbeam.physics.friction import FrictionModel, FrictionSettings
from tailbeam.physics.incline import InclinedPlate
from tailbeam.physics.materials import CARBON_STEEL, get_material
from tailbeam.solvers.stream.driver import loop
from tailbeam.streams.generator import Particle, default_label

R = 0.03
THETA = math.radians(20.0)
DAMPING = 300.0  # N s/m
COAL = get_material("coal")
# m, m/s: two runs of one lump whose steps differ (cut at another island's events, or at
# the stiffest contact of the whole set) agree to the tolerance's scale, far below these
X_TOL, V_TOL = 1e-8, 1e-6


def run(balls, duration=0.25):
    model = FrictionModel(FrictionSettings(0.5, 0.4, 1e-3, 2e-3, 0.1))
    particles = [Particle.from_ball(b, default_label(b)) for b in balls]
    incline = InclinedPlate(Plate(), math.degrees(THETA), STANDARD_GRAVITY)
    return loop.solve_stream(particles, incline, duration, damping=DAMPING, rtol=1e-10,
                             friction=model, progress=False)  # fmt: skip


def lump(name, x, y=0.0, velocity=(0.0, 0.0, 0.0)):
    """A lump set down on the plate at its static penetration (its contact from the start)."""
    law = ball_plate_law(COAL, R, CARBON_STEEL, damping=DAMPING)
    weight = Ball(name, COAL, R, (0.0, 0.0, R)).mass * STANDARD_GRAVITY * math.cos(THETA)
    pen = (weight / law.stiffness) ** (1.0 / law.exponent)
    return Ball(name, COAL, R, (x, y, R - pen), velocity)


def close(a, b, names):
    for name in names:
        (xa, va), (xb, vb) = a.final[name], b.final[name]
        assert np.max(np.abs(xa - xb)) < X_TOL, name
        assert np.max(np.abs(va - vb)) < V_TOL, name


def test_lumps_far_apart_are_each_the_lump_alone():
    """Two lumps 0.3 m apart roll down side by side, one thrown across: integrated together
    (two islands) each ends where it ends alone, with the same contacts."""
    a, b = lump("a", -0.3, -0.1), lump("b", -0.3, 0.2, velocity=(0.3, 0.2, 0.0))
    both, alone_a, alone_b = run([a, b]), run([a]), run([b])
    assert both.stats["islands_max"] >= 2
    close(both, alone_a, ["a"])
    close(both, alone_b, ["b"])
    for name, alone in (("a", alone_a), ("b", alone_b)):
        mine = [c for c in both.contacts if c.ball == name]
        assert len(mine) == len(alone.contacts) > 0


def test_lumps_that_collide_meet_as_in_one_set(monkeypatch):
    """A lump rolling into a slower one: the islands merge before they touch (no late
    start), and the run is the run of one set (same contacts, same final states)."""
    balls = [lump("a", -0.3, velocity=(1.0, 0.0, 0.0)), lump("b", -0.15)]
    islands = run(balls, 0.4)
    monkeypatch.setattr(loop, "_ISLANDS", False)
    one = run(balls, 0.4)
    assert islands.stats["late_starts"] == 0
    pairs = [(c.ball, c.partner) for c in islands.contacts]
    assert ("a", "b") in pairs or ("b", "a") in pairs
    assert pairs == [(c.ball, c.partner) for c in one.contacts]
    close(islands, one, ["a", "b"])
