"""Which solver runs a stream scene: the one switch the fast stream solver replaces.

``stream_engine()`` returns the fast solver ``tailbeam.solvers.stream.driver.loop.simulate_stream`` if
that module exists, else the slow reference (``simulate_stream_reference``, every pair
watched, fine for 3-10 balls, refused beyond ``REFERENCE_MAX_PARTICLES``). Both are called
as ``run(particles, incline, duration, *, laws, rtol, max_steps, progress)`` and return a
``StreamResult``; ``laws`` is the particles' contact table (``Scene.contacts()``,
``tailbeam.physics.contacts``) or the IMPACT settings shared by every pair (exponent,
damping, penetration, clamp: ``tailbeam.scene.ContactSettings``).

The fast solver plugs in by existing: a module ``tailbeam/solvers/stream/driver/loop.py`` with
``simulate_stream`` (same call, same result) and optionally ``MAX_PARTICLES``,
``DEFAULT_RTOL``, ``DEFAULT_MAX_STEPS`` and ``estimate``; nothing else changes.
"""

import importlib
from collections.abc import Callable
from dataclasses import dataclass

from tailbeam.physics.contacts import contact_table
from tailbeam.solvers.stream.stream_result import StreamResult

FAST_MODULE = "tailbeam.solvers.stream.solver"
REFERENCE_MAX_PARTICLES = 20  # the reference watches every pair: O(N^2) per step
REFERENCE_MAX_STEPS = 100_000  # default step budget (memory: every step's state is kept)
REFERENCE_RTOL = 1e-10
# Wall time of one reference step, s, measured at 10-13 particles on the shared 2-core
# machine (examples/small_stream.toml: 1082 steps, 2.9 ms each); it grows ~N^2 (all pairs).
REFERENCE_STEP_SECONDS = 3e-3
REFERENCE_STEP_PARTICLES = 12


@dataclass(frozen=True)
class StreamEngine:
    """A stream solver: its name, the function, the most particles it accepts (None: no
    limit of its own), its default rtol and step budget, and ``estimate(n_particles,
    max_steps) -> (bytes, seconds)``: upper bounds of its memory and wall time."""

    name: str
    run: Callable
    max_particles: int | None
    rtol: float
    max_steps: int
    estimate: Callable


def stream_engine() -> StreamEngine:
    """The fast stream solver if it exists, else the reference (module docstring)."""
    try:
        fast = importlib.import_module(FAST_MODULE)
    except ModuleNotFoundError as err:
        if err.name != FAST_MODULE:
            raise
        return reference_engine()
    return StreamEngine(
        "fast stream solver",
        fast.simulate_stream,
        getattr(fast, "MAX_PARTICLES", None),
        getattr(fast, "DEFAULT_RTOL", REFERENCE_RTOL),
        getattr(fast, "DEFAULT_MAX_STEPS", REFERENCE_MAX_STEPS),
        getattr(fast, "estimate", reference_estimate),
    )


def reference_engine() -> StreamEngine:
    """The slow independent reference (``simulate_stream_reference``), as a StreamEngine."""
    return StreamEngine(
        "stream reference (scipy DOP853, all pairs watched)",
        run_reference,
        REFERENCE_MAX_PARTICLES,
        REFERENCE_RTOL,
        REFERENCE_MAX_STEPS,
        reference_estimate,
    )


def reference_estimate(n_particles: int, max_steps: int) -> tuple[float, float]:
    """Upper bounds (bytes, s) of the reference's memory and wall time for ``max_steps``.

    Memory: per accepted step it keeps the time, the energy and every present ball's
    position and velocity (2 arrays of n x 3 floats plus ~300 bytes of Python objects).
    Time: REFERENCE_STEP_SECONDS per step at REFERENCE_STEP_PARTICLES, growing as N^2."""
    memory = max_steps * (48.0 * n_particles + 300.0)
    per_step = REFERENCE_STEP_SECONDS * max(1.0, (n_particles / REFERENCE_STEP_PARTICLES) ** 2)
    return memory, max_steps * per_step


def run_reference(particles, incline, duration, *, laws, rtol, max_steps, progress=None):
    """Run ``particles`` through ``simulate_stream_reference``; returns a StreamResult."""
    from tailbeam.solvers.stream.reference.solver import simulate_stream_reference

    ref = simulate_stream_reference(
        [p.ball() for p in particles],
        incline,
        duration,
        contacts=contact_table(particles, laws, incline.plate.material),
        rtol=rtol,
        max_steps=max_steps,
        release_times=[p.t_release for p in particles],
        progress=progress,
    )
    stats = {"n_steps": ref.steps, "n_contacts": len(ref.contacts), "n_leaves": len(ref.leaves)}
    return StreamResult(
        list(particles), ref.contacts, ref.leaves, ref.events, incline, duration,
        status=0, message="reached the end of the simulation", stats=stats, info=dict(ref.info),
    )  # fmt: skip
