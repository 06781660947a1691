"""The stream driver's plate loads: kept only for a replay, and bounded.

Each against an independent truth: a run that keeps no loads (``solve_stream(loads=False)``,
what the rigid plate's ``Result`` runs) is the run that keeps them, output for output, with
no loads (frictionless and with friction); the rigid plate's ``simulate_stream`` keeps none;
the count of force nodes kept is the count of nodes in the run's loads, and the driver stops
with an error naming ``duration`` once it passes the bound (``MAX_LOAD_NODES``), and not
below it.

Coal balls, r = 30 mm, on the plate inclined 20 degrees, damping 300 N s/m; with friction
mu_s = 0.5, mu_d = 0.4, mu_r = 0.1, one lump rolling into another (as ``test_islands``).
"""

import dataclasses
import math

import numpy as np
import pytest

from tailbeam.errors import WorkLimitError
from tailbeam.physics.bodies import STANDARD_GRAVITY, Ball, Plate
from tailbeam.physics.contact_law import ball_plate_law
from tailbeam.physics.friction import FrictionModel, FrictionSettings
from tailbeam.physics.incline import InclinedPlate
from tailbeam.physics.materials import CARBON_STEEL, get_material
from tailbeam.solvers.stream import solver
from tailbeam.solvers.stream.driver import loads as loads_mod
from tailbeam.solvers.stream.driver import loop
from tailbeam.streams.generator import Particle, default_label

R = 0.03
THETA = 20.0  # degrees
DAMPING = 300.0  # N s/m
COAL = get_material("coal")
INCLINE = InclinedPlate(Plate(), THETA, STANDARD_GRAVITY)


def lump(name, x, velocity=(0.0, 0.0, 0.0)):
    """A lump set down on the plate at its static penetration (its contact from the start)."""
    law = ball_plate_law(COAL, R, CARBON_STEEL, damping=DAMPING)
    weight = Ball(name, COAL, R, (0.0, 0.0, R)).mass * STANDARD_GRAVITY
    pen = (weight * math.cos(math.radians(THETA)) / law.stiffness) ** (1.0 / law.exponent)
    return Ball(name, COAL, R, (x, 0.0, R - pen), velocity)


def particles(friction: bool):
    if friction:  # a lump rolling into a slower one, both touching the plate throughout
        balls = [lump("a", -0.3, velocity=(1.0, 0.0, 0.0)), lump("b", -0.15)]
    else:  # a lump set down (it slides: dead loads) and a ball dropped (it bounces)
        balls = [lump("a", -0.3), Ball("b", COAL, R, (0.1, 0.1, 0.08), (0.0, 0.0, -0.5))]
    return [Particle.from_ball(b, default_label(b)) for b in balls]


def run(friction: bool, loads: bool = True, duration: float = 0.3):
    model = FrictionModel(FrictionSettings(0.5, 0.4, 1e-3, 2e-3, 0.1)) if friction else None
    return loop.solve_stream(particles(friction), INCLINE, duration, damping=DAMPING,
                             rtol=1e-10, friction=model, progress=False, loads=loads)  # fmt: skip


def _same(a, b) -> None:
    """Bit for bit: a == b, arrays by their bytes."""
    if isinstance(a, np.ndarray):
        assert a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()
    elif isinstance(a, dict):
        assert a.keys() == b.keys()
        for k in a:
            _same(a[k], b[k])
    elif isinstance(a, list | tuple):
        assert len(a) == len(b)
        for x, y in zip(a, b, strict=True):
            _same(x, y)
    elif dataclasses.is_dataclass(a):
        _same(dataclasses.asdict(a), dataclasses.asdict(b))
    else:
        assert a == b or (a != a and b != b)  # (NaN is NaN)


@pytest.mark.parametrize("friction", [False, True])
def test_a_run_without_loads_is_the_run_with_them(friction):
    """No loads kept: the loads are empty, every other output bit for bit the same."""
    kept, dropped = run(friction), run(friction, loads=False)
    assert kept.loads and dropped.loads == [] and dropped.dead_loads == []
    if not friction:
        assert kept.dead_loads  # (the case covers the dead loads)
    for name in ("particles", "contacts", "leaves", "events", "angular_velocity", "final"):
        _same(getattr(kept, name), getattr(dropped, name))
    stats = [{k: v for k, v in r.stats.items() if k != "wall_s"} for r in (kept, dropped)]
    _same(*stats)


def test_the_rigid_plate_result_keeps_no_loads(monkeypatch):
    """``simulate_stream`` on the rigid plate (no modal set-up): its run keeps no loads."""
    runs = []

    def spy(*args, **kwargs):
        runs.append(loop.solve_stream(*args, **kwargs))
        return runs[-1]

    monkeypatch.setattr(solver, "solve_stream", spy)
    model = FrictionModel(FrictionSettings(0.5, 0.4, 1e-3, 2e-3, 0.1))
    laws = loop.LawOptions(loop.HERTZ_EXPONENT, DAMPING, 1e-4, True)
    result = solver.simulate_stream(particles(True), INCLINE, 0.05, laws=laws, friction=model,
                                    progress=False)  # fmt: skip
    assert result.impacts and runs[0].contacts
    assert runs[0].loads == [] and runs[0].dead_loads == []


def test_kept_nodes_are_counted_and_bounded(monkeypatch):
    """The nodes counted are the nodes in the run's loads; a bound below them stops the run
    with an error naming ``duration``, a bound at them does not."""
    made = []

    class Spy(loads_mod.PlateLoads):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            made.append(self)

    monkeypatch.setattr(loop, "PlateLoads", Spy)
    full = run(True)
    nodes = sum(len(t) for _x, _y, t, _f in full.loads)
    assert nodes > 1000 and made[-1].forces.kept == nodes
    monkeypatch.setattr(loads_mod, "MAX_LOAD_NODES", nodes // 2)
    with pytest.raises(WorkLimitError, match=r"^duration: .* force nodes by t = "):
        run(True)
    monkeypatch.setattr(loads_mod, "MAX_LOAD_NODES", nodes)
    assert sum(len(t) for _x, _y, t, _f in run(True).loads) == nodes
