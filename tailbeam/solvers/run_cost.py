"""The estimated cost of a whole run, before any work (``estimate_run``), from the part
models of ``tailbeam.solvers.cost``: the bases (``modal_setup.plan``), the solver's
simulation from the impacts the scene will have (``expected_impacts``), the sensor replay and
writing the outputs."""

import math

from tailbeam.physics.hertz import hertz_contact_duration
from tailbeam.progress import note
from tailbeam.solvers.cost import (
    RunCost,
    check_replay,
    coupled_part,
    load_stretch,
    reference_part,
    replay_part,
    rigid_part,
    stream_part,
    write_part,
)
from tailbeam.solvers.coupled.solver import DEFAULT_REST_SPEED, DEFAULT_STEPS_PER_CONTACT
from tailbeam.solvers.modal_setup.band import impact_pulse
from tailbeam.solvers.modal_setup.plan import plan_bases
from tailbeam.solvers.modal_setup.ritz_prepass import check_tail_scene


def expected_impacts(scene, rest_speed: float = DEFAULT_REST_SPEED) -> float:
    """The plate impacts of the scene's balls over its duration: each ball falls, then
    rebounds with the restitution of its hardest impact (``ball_restitution``) until its
    rebound is slower than ``rest_speed`` or the run ends."""
    g = scene.gravity
    total = 0.0
    for ball, law in zip(scene.balls, scene.laws(), strict=True):
        vz, gap = ball.velocity[2], max(ball.gap, 0.0)
        speed = math.sqrt(vz * vz + 2 * g * gap)
        t = (speed + vz) / g if g > 0 else gap / max(-vz, 1e-9)  # to the first impact
        e = ball_restitution(ball.mass, max(speed, 1e-3), law)
        while t < scene.duration:
            total += 1.0
            speed *= e
            if speed < rest_speed:
                break
            t += 2.0 * speed / g + hertz_contact_duration(ball.mass, speed, law.stiffness,
                                                          law.exponent)  # fmt: skip
    return total


def ball_restitution(mass: float, speed: float, law) -> float:
    """Restitution of an impact at ``speed`` (m/s) on a rigid plate under ``law``: the
    IMPACT law's energy loss, from its force pulse (``modal_setup.band.impact_pulse``)."""
    return impact_pulse(mass, speed, law)["restitution"]


def stream_impacts(scene) -> float:
    """Plate impacts of a stream scene: ~3 per particle (a fall and its rebounds), plus the
    balls' own."""
    return 3.0 * (len(scene.particles) - len(scene.balls)) + expected_impacts(scene)


# -- the run -----------------------------------------------------------------------------------


def estimate_run(scene, solver, *, band: dict | None = None, writes: bool = True) -> RunCost:
    """The estimated cost of running ``scene`` with ``solver`` (a ``tailbeam.solvers.base.
    Solver``), part by part (module docstring). ``band``: the band already chosen (else it
    is chosen here); ``writes``: include writing the outputs (``tailbeam simulate``).
    InputError naming ``sensors[i].sample_rate`` for a sensor whose replay is beyond the
    limits (``cost.check_replay``)."""
    parts, alternative, plan = [], "", None
    n_modes, top_hz = 0, 0.0
    if scene.plate_model == "modal":
        check_tail_scene(scene)  # the set-up's own refusals first
        plan = plan_bases(scene, solver.stream, band)
        parts += plan.parts
        n_modes, top_hz = plan.n_modes, plan.fmax_hz
        alternative = plan.alternative
    parts.append(_simulation(scene, solver, n_modes, plan))
    modal_sensors = scene.plate_model == "modal" and bool(scene.sensors)
    if modal_sensors:
        check_replay(scene, n_modes, top_hz)
        particles = len(scene.particles) if solver.stream else 0
        ritz_dofs = plan.n_dofs if plan.ritz_points else 0
        balls = 0 if solver.stream else len(scene.balls)
        signals = [c for s in scene.sensors for c in s.channels()]  # one per axis
        parts.append(replay_part(signals, scene.duration, n_modes, top_hz, particles,
                                 ritz_dofs, balls))  # fmt: skip
    if writes:
        parts.append(write_part(scene, not solver.stream, modal_sensors))
    return RunCost(tuple(parts), alternative)


def _simulation(scene, solver, n_modes: int, plan):
    if solver.name == "stream-reference":
        return reference_part(len(scene.particles), stream_impacts(scene))
    if solver.stream:
        if plan is None or not plan.two_way:
            return stream_part(len(scene.particles))
        return stream_part(len(scene.particles), n_modes, plan.tail_oscillators)
    if scene.plate_model == "rigid":
        return rigid_part(expected_impacts(scene))
    settings = scene.modal
    flexible = settings is None or (settings.residual_flexibility and settings.mesh is None)
    return coupled_part(expected_impacts(scene), len(scene.balls), n_modes,
                        DEFAULT_STEPS_PER_CONTACT, plan.n_dofs if flexible else 0)  # fmt: skip


def announce_run(scene, solver) -> RunCost:
    """Estimate the run (``estimate_run``, which refuses what is beyond the limits) and say
    the estimate on stderr, before any work, with the stretch of the machine's current load
    (``cost.load_stretch``) when it is 1.5 or more."""
    cost = estimate_run(scene, solver)
    stretch, load, cores = load_stretch()
    busy = ""
    if stretch >= 1.5:
        busy = (f"; on this machine's load ({load:.1f} on {cores} cores) the wall time may be "
                f"~{stretch:.1f}x that")  # fmt: skip
    note(cost.describe() + busy)
    return cost
