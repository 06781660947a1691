"""``tailbeam.simulate(scene, **how)``: the one library call that runs a scene.

What to simulate (a ``tailbeam.scene.Scene``) is positional; how (rtol, max_steps,
progress) is keyword-only. The scene chooses the solver:

- rigid plate, no streams, no inclination, no two balls that can touch (their horizontal
  paths never come within the sum of the radii): ``tailbeam.rigid.simulate_rigid``, exact
  per ball (a ``RigidResult``);
- modal plate: the coupled modal solver (``tailbeam.coupled.simulate_scene_modal``);
  streams, inclination and ball-ball contact are refused there for now (InputError);
- otherwise (streams, an inclined plate, balls that may touch): the stream solver of
  ``tailbeam.solvers.engine`` (a ``StreamResult``).
"""

import contextlib

from tailbeam.errors import InputError, WorkLimitError
from tailbeam.progress import note, quiet, task

MAX_STREAM_MEMORY = 2e9  # bytes the reference may keep (its step budget x state size)


def simulate(scene, *, rtol=None, max_steps=None, progress=True):
    """Simulate ``scene`` and return its result.

    Parameters
    ----------
    scene : tailbeam.scene.Scene
        What to simulate (e.g. from ``tailbeam.scene_file.load_scene``).
    rtol : float, optional
        Relative tolerance of the solver (rigid: its default 1e-10; stream reference 1e-10).
    max_steps : int, optional
        Step budget (rigid: per ball; stream solver: in all); WorkLimitError beyond it.
    progress : bool
        Show progress and the automatic choices on stderr (``tailbeam.progress``).

    Returns
    -------
    RigidResult, the coupled solver's result, or StreamResult (tailbeam.solvers.stream_result).
    """
    from tailbeam.scene import Scene

    if not isinstance(scene, Scene):
        raise InputError("scene", f"must be a tailbeam.scene.Scene, got {type(scene).__name__}")
    how = {k: v for k, v in (("rtol", rtol), ("max_steps", max_steps)) if v is not None}
    with contextlib.nullcontext() if progress else quiet():
        if scene.plate_model == "modal":
            return _modal(scene, how)
        if scene.needs_stream_solver:
            return _stream(scene, how)
        return _rigid(scene, how)


def _rigid(scene, how):
    from tailbeam.rigid import simulate_rigid

    with task(f"simulating {scene.duration:g} s, {len(scene.balls)} balls, rigid plate"):
        return simulate_rigid(
            scene.balls, scene.plate, scene.laws(), scene.duration, gravity=scene.gravity, **how
        )


def _modal(scene, how):
    from tailbeam.coupled import simulate_scene_modal
    from tailbeam.scene import check_no_ball_contact

    if how:
        raise InputError(next(iter(how)), "is not a setting of the modal plate solver")
    check_no_ball_contact(scene.balls, scene.duration)
    # The modal path chooses its band from the scene (contact durations, sensor bandwidths),
    # the theory from the band, and records both choices in result.info.
    return simulate_scene_modal(scene)


def _stream(scene, how):
    from tailbeam.preflight import check_streams
    from tailbeam.solvers.engine import stream_engine

    check_streams(scene)  # (already done by load_scene; a Scene built in Python needs it)
    engine = stream_engine()
    particles = scene.particles
    rtol, max_steps = how.get("rtol", engine.rtol), how.get("max_steps", engine.max_steps)
    memory, worst = engine.estimate(len(particles), max_steps)
    if memory > MAX_STREAM_MEMORY:
        raise WorkLimitError(
            f"max_steps: {max_steps} steps of {len(particles)} particles could keep "
            f"{memory / 1e9:.3g} GB (limit {MAX_STREAM_MEMORY / 1e9:g} GB); lower max_steps"
        )
    note(
        f"{_why_stream(scene)}: stream solver = {engine.name}, {len(particles)} particles, "
        f"rtol {rtol:g}, at most {max_steps} steps (<= {memory / 1e6:.0f} MB, <= ~{worst / 60:.0f}"
        " min at the measured cost per step; examples/small_stream.toml takes ~1400 steps per"
        " simulated second)"
    )
    with task(f"simulating {scene.duration:g} s", total=scene.duration, unit="s") as bar:
        reached = [0.0]

        def advance(t):
            bar.update(t - reached[0])
            reached[0] = t

        return engine.run(
            particles, scene.incline, scene.duration, laws=scene.contact, rtol=rtol,
            max_steps=max_steps, progress=advance,
        )  # fmt: skip


def _why_stream(scene) -> str:
    if scene.streams:
        return f"{len(scene.streams)} stream(s)"
    if scene.inclination != 0.0:
        return f"plate inclined {scene.inclination:g} degrees"
    return "balls that may touch each other"
