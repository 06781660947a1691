"""``tailbeam.simulate(scene, **how)``: the one library call that runs a scene.

What to simulate (a ``tailbeam.scene.Scene``) is positional; how (the solver, rtol,
max_steps, progress) is keyword-only. Whichever solver runs, it returns one
``tailbeam.results.result.Result``. The solver is a swappable part (``solver=``, ``SOLVERS``),
each following one protocol (``tailbeam.solvers.base.Solver``):

- ``"single-ball"``: the exact per-ball solvers, for scenes without streams, without
  inclination and without two balls that can touch (their horizontal paths never come within
  the sum of the radii), on the rigid or the modal plate;
- ``"stream"``: the fast stream solver, on the rigid or the modal plate; it runs every scene;
- ``"stream-reference"``: the slow independent reference of the stream solver (scipy DOP853,
  every pair watched, at most ``REFERENCE_MAX_PARTICLES`` bodies), on the rigid plate;
- ``"auto"`` (the default): ``"single-ball"`` where it can run, else ``"stream"``; a scene
  with friction (``[contact.friction]``): ``"stream"`` (rigid or modal plate; on the rigid
  plate ``"stream-reference"`` models it too), or with Coulomb's law (stiction_velocity = 0)
  ``"stream-reference"`` (rigid plate).

Running one scene through two solvers is how a user checks one against the other.
"""

import contextlib

from tailbeam.errors import InputError
from tailbeam.plate.blas import limited
from tailbeam.progress import quiet
from tailbeam.results.frames import check_frame_times
from tailbeam.scene import Scene
from tailbeam.solvers.base import Options, Solver
from tailbeam.solvers.modal_setup.setup import single_ball_setup, stream_setup
from tailbeam.solvers.run_cost import announce_run
from tailbeam.solvers.single_ball import SingleBall
from tailbeam.solvers.stream.solver import Stream, StreamReference

SOLVERS = {s.name: s for s in (SingleBall(), Stream(), StreamReference())}
CHOICES = ("auto", *SOLVERS)


def simulate(scene, *, solver="auto", rtol=None, max_steps=None, progress=True, frames=()):
    """Simulate ``scene`` and return its result.

    Parameters
    ----------
    scene : tailbeam.scene.Scene
        What to simulate (e.g. from ``tailbeam.io.scene_file.load_scene``).
    solver : str
        Which solver runs it, one of ``CHOICES`` (module docstring); ``"auto"`` by default.
        The choice is in ``result.info["solver_choice"]``; ``result.info["solver"]`` keeps
        the chosen solver's own description (method, tolerance).
    rtol : float, optional
        Relative tolerance of the solver (rigid: its default 1e-10; stream reference 1e-10).
    max_steps : int, optional
        Step budget (rigid: per ball; stream solver: in all); WorkLimitError beyond it.
    progress : bool
        Show progress and the automatic choices on stderr (``tailbeam.progress``).
        The run holds BLAS to one thread, or ``$TAILBEAM_BLAS_THREADS``
        (``tailbeam.plate.blas``), and restores the caller's limit after it.
    frames : sequence of float
        Times (s, increasing, within [0, duration]) at which the result keeps every body's
        position and velocity (``result.frames``, ``tailbeam.results.frames``); memory
        frames x bodies x 48 bytes. Refused for a solver that cannot (stream-reference).

    Returns
    -------
    tailbeam.Result
        One type for every solver (``tailbeam.results.result``): ``status``, ``message``,
        ``stats``, ``info``, ``impacts_table()``, ``particles_table()``, ``events_of(name,
        kind)``, ``impacts_of(name)``, ``leaves``, ``sensor_outputs`` / ``sensor_signals``,
        ``plate_model``; ``sample(times)`` where the solver keeps the balls' states.
    """
    if not isinstance(scene, Scene):
        raise InputError("scene", f"must be a tailbeam.scene.Scene, got {type(scene).__name__}")
    method = choose_solver(scene, solver)
    frames = check_frame_times(frames, scene.duration) if len(frames) else ()
    if frames and not method.frames:
        raise InputError("frames", f"the {method.name!r} solver keeps no states at frame times")
    options = Options(rtol=rtol, max_steps=max_steps, frames=frames)
    with contextlib.nullcontext() if progress else quiet(), limited():
        method.check(scene, options)
        cost = announce_run(scene, method)
        result = method.run(scene, plate_setup(scene, method), options)
    result.info["run_cost_estimate"] = cost.as_dict()
    return result


def choose_solver(scene, solver: str = "auto", field: str = "solver") -> Solver:
    """The solver that runs ``scene``: ``solver`` itself, checked against the scene before
    any work, or for "auto" the single-ball solvers where they can run, else the stream
    solver. InputError naming ``field`` (the caller's name, e.g. ``--solver``) for a solver
    that does not exist or cannot run the scene."""
    if solver not in CHOICES:
        raise InputError(field, f"must be one of {', '.join(CHOICES)}; got {solver!r}")
    if solver == "auto" and scene.friction is not None:
        return _friction_solver(scene, field)
    if solver == "auto":
        solver = "stream" if scene.needs_stream_solver else "single-ball"
    method = SOLVERS[solver]
    why = method.refusal(scene)
    if why:
        raise InputError(field, why)
    return method


def _friction_solver(scene, field: str) -> Solver:
    """The solver "auto" picks for a scene with friction: the fast stream solver, or an
    InputError naming ``contact.friction`` when it cannot run the scene (the modal plate)."""
    method = SOLVERS["stream-reference" if scene.friction.coulomb else "stream"]
    why = method.refusal(scene)
    if why:
        raise InputError(
            "contact.friction", "the solvers that model friction cannot run this scene "
            f"({why.removeprefix('contact.friction: ')})"
        )  # fmt: skip
    return method


def plate_setup(scene, method: Solver):
    """The modal plate ``method`` runs ``scene`` on (``tailbeam.solvers.modal_setup``), or
    None on the rigid plate."""
    if scene.plate_model != "modal":
        return None
    return stream_setup(scene) if method.stream else single_ball_setup(scene)
