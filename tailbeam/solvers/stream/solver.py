"""The stream solver as ``tailbeam.simulate`` runs it: the driver's run, as a Result."""

from tailbeam.physics.contacts import contact_table
from tailbeam.physics.incline import InclinedPlate
from tailbeam.solvers.stream.driver.loop import (
    DEFAULT_MAX_STEPS,
    DEFAULT_REST_SPEED,
    DEFAULT_RTOL,
    MAX_PARTICLES,
    solve_stream,
)

__all__ = ["DEFAULT_MAX_STEPS", "DEFAULT_RTOL", "MAX_PARTICLES", "estimate", "simulate_stream"]
from tailbeam.solvers.stream.stream_result import StreamResult


def simulate_stream(
    particles, incline: InclinedPlate, duration: float, *, laws, rtol: float = DEFAULT_RTOL,
    max_steps: int = DEFAULT_MAX_STEPS, progress=True, rest_speed: float = DEFAULT_REST_SPEED,
    plate=None,
):  # fmt: skip
    """The stream solver as ``tailbeam.solvers.stream.engine`` calls it: a ``StreamResult``.

    laws: the particles' ``ContactTable`` (``Scene.contacts()``) or the IMPACT settings
    shared by every pair (``tailbeam.scene.ContactSettings``: exponent, damping,
    penetration, clamp). progress: True (a bar), False, or a callable taking the simulated
    time reached (s)."""
    contacts = contact_table(particles, laws, incline.plate.material)
    run = solve_stream(
        particles, incline, duration, rtol=rtol, rest_speed=rest_speed,
        max_work=max_steps, progress=progress, plate=plate, contacts=contacts,
    )  # fmt: skip
    result = StreamResult(
        run.particles, run.contacts, run.leaves, run.events, incline, duration,
        status=run.status, message=run.message, stats=run.stats,
        info={"solver": "fast stream solver (event-driven, active-set DOP853)"},
    )  # fmt: skip
    result.loads = (run.loads, run.dead_loads)
    return result


def estimate(n_particles: int, max_steps: int) -> tuple[float, float]:
    """Upper-bound-style estimates (bytes, s) for ``tailbeam.simulation``'s preflight: per
    particle ~30 contact records and force histories (~40 kB), and the measured ~5 ms of
    wall time per particle of the reference stream (benchmarks/bench_stream.py) x 4."""
    return 4e4 * n_particles + 5e7, 2e-2 * n_particles
