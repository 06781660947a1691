"""The stream solvers as ``tailbeam.simulate`` runs them: the fast solver (``Stream``, the
driver in ``driver/``) and its slow all-pairs reference (``StreamReference``, ``reference/``),
each run as a ``tailbeam.Result``.

On the modal plate the fast solver runs two-way (the modes in its active set, the plate's
state between sets in a ``StreamPlate``) or, with ``plate.coupling = "one-way"``, on the rigid
plate; either way the plate force histories it records drive the modes exactly for the
sensors (``LoadResponse``, the Result's ``plate`` part).
"""

import contextlib

from tailbeam.errors import WorkLimitError
from tailbeam.physics.contacts import contact_table
from tailbeam.physics.incline import InclinedPlate
from tailbeam.preflight import MAX_PARTICLES, check_streams
from tailbeam.progress import note, task
from tailbeam.results.result import Result
from tailbeam.solvers.base import Options, Solver, why_stream
from tailbeam.solvers.plate_loads.response import LoadResponse
from tailbeam.solvers.stream.driver.loop import (
    DEFAULT_MAX_STEPS,
    DEFAULT_REST_SPEED,
    DEFAULT_RTOL,
    solve_stream,
)
from tailbeam.solvers.stream.numbering import number_contacts
from tailbeam.solvers.stream.plate import StreamPlate
from tailbeam.solvers.stream.reference.solver import simulate_stream_reference
from tailbeam.streams.delivery import delivery, delivery_line

MAX_STREAM_MEMORY = 2e9  # bytes a stream run may be estimated to keep (the work bound's)
REFERENCE_MAX_PARTICLES = 20  # the reference watches every pair: O(N^2) per step
REFERENCE_MAX_STEPS = 100_000  # its default step budget (memory: every step's state is kept)
REFERENCE_RTOL = 1e-10
# Wall time of one reference step, s, measured at 10-13 particles on the 2-core machine
# (examples/small_stream.toml: 1082 steps); it grows ~N^2 (all pairs).
REFERENCE_STEP_SECONDS = 3e-3
REFERENCE_STEP_PARTICLES = 12


class Stream(Solver):
    """The fast stream solver: event-driven, closed-form flights, active sets of the balls
    in contact integrated by a compiled DOP853 (``tailbeam.solvers.stream.driver``)."""

    name = "stream"
    stream = True
    label = "fast stream solver"
    max_particles = MAX_PARTICLES
    rtol, max_steps = DEFAULT_RTOL, DEFAULT_MAX_STEPS

    def estimate(self, n_particles: int, max_steps: int) -> tuple[float, float]:
        """Upper-bound-style estimates (bytes, s): per particle ~30 contact records and force
        histories (~40 kB), and ~5 ms of wall time per particle (benchmarks/bench_stream.py)
        x 4."""
        return 4e4 * n_particles + 5e7, 2e-2 * n_particles

    def refusal(self, scene) -> str | None:
        if scene.friction is not None and scene.friction.coulomb:
            return (
                "contact.friction: stiction_velocity = 0 (Coulomb's law, stick and slip as "
                "events) is modelled by the 'stream-reference' solver only (rigid plate); the "
                "fast stream solver needs stiction_velocity > 0"
            )
        return None

    def check(self, scene, options: Options) -> None:
        check_streams(scene, self.max_particles, self.label)
        max_steps = _setting(options.max_steps, self.max_steps)
        memory, _ = self.estimate(len(scene.particles), max_steps)
        if memory > MAX_STREAM_MEMORY:
            raise WorkLimitError(
                f"max_steps: {max_steps} steps of {len(scene.particles)} particles could keep "
                f"{memory / 1e9:.3g} GB (limit {MAX_STREAM_MEMORY / 1e9:g} GB); lower max_steps"
            )

    def run(self, scene, plate, options: Options) -> Result:
        rtol, max_steps = (
            _setting(options.rtol, self.rtol),
            _setting(options.max_steps, self.max_steps),
        )
        self._announce(scene, rtol, max_steps)
        with _bar(scene) as advance:
            return simulate_stream(
                scene.particles, scene.incline, scene.duration, laws=scene.contacts(),
                rtol=rtol, max_steps=max_steps, progress=advance, setup=plate,
                sensors=scene.sensors, info={"solver_choice": self.name}, streams=scene.streams,
                frames=options.frames,
                friction=scene.friction,
            )  # fmt: skip

    def _announce(self, scene, rtol, max_steps):
        memory, _ = self.estimate(len(scene.particles), max_steps)
        note(
            f"{why_stream(scene)}: stream solver = {self.label}, {len(scene.particles)} "
            f"particles, rtol {rtol:g}, work bound {max_steps} steps (<= {memory / 1e6:.0f} MB "
            "at the bound)"
        )


class StreamReference(Stream):
    """The slow independent reference of the stream solver: scipy's DOP853, every pair
    watched, on the rigid plate (``tailbeam.solvers.stream.reference``)."""

    name = "stream-reference"
    label = "stream reference (scipy DOP853, all pairs watched)"
    frames = False  # it keeps its steps, not states at chosen times
    max_particles = REFERENCE_MAX_PARTICLES
    rtol, max_steps = REFERENCE_RTOL, REFERENCE_MAX_STEPS

    def refusal(self, scene) -> str | None:
        if scene.plate_model == "rigid":
            return None
        if scene.friction is not None and scene.friction.coulomb:
            return (
                "contact.friction: stiction_velocity = 0 (Coulomb's law) runs on the rigid "
                "plate only (plate.model = \"rigid\", the 'stream-reference' solver)"
            )
        return (
            "'stream-reference' runs on the rigid plate (plate.model = \"rigid\"), with or "
            "without friction; its modal "
            "plate (tailbeam.solvers.stream.reference.plate) has no residual flexibility or "
            "sensors, and is used by the tests"
        )

    def estimate(self, n_particles: int, max_steps: int) -> tuple[float, float]:
        """Upper bounds (bytes, s) of the reference's memory and wall time for ``max_steps``:
        per accepted step it keeps the time, the energy and every present ball's position and
        velocity (2 arrays of n x 3 floats plus ~300 bytes of Python objects); each step
        takes REFERENCE_STEP_SECONDS at REFERENCE_STEP_PARTICLES, growing as N^2."""
        memory = max_steps * (48.0 * n_particles + 300.0)
        per_step = REFERENCE_STEP_SECONDS * max(1.0, (n_particles / REFERENCE_STEP_PARTICLES) ** 2)
        return memory, max_steps * per_step

    def run(self, scene, plate, options: Options) -> Result:
        rtol, max_steps = (
            _setting(options.rtol, self.rtol),
            _setting(options.max_steps, self.max_steps),
        )
        self._announce(scene, rtol, max_steps)
        with _bar(scene) as advance:
            return simulate_reference(
                scene.particles, scene.incline, scene.duration, laws=scene.contacts(),
                rtol=rtol, max_steps=max_steps, progress=advance,
                info={"solver_choice": self.name}, friction=scene.friction,
            )  # fmt: skip


def simulate_stream(particles, incline: InclinedPlate, duration: float, *, laws,
                    rtol: float = DEFAULT_RTOL, max_steps: int = DEFAULT_MAX_STEPS,
                    progress=True, rest_speed: float = DEFAULT_REST_SPEED, setup=None,
                    sensors=(), info=None, streams=(), frames=(),
                    friction=None) -> Result:  # fmt: skip
    """The fast stream solver on ``particles`` (``tailbeam.streams.generator.Particle``).

    Parameters
    ----------
    particles, incline, duration
        What to simulate (plate frame, SI units).
    laws : ContactTable or ContactSettings
        The particles' contact table (``Scene.contacts()``) or the IMPACT settings shared by
        every pair.
    rtol, max_steps, rest_speed
        The driver's tolerance, work bound (steps and events) and rest speed (m/s).
    progress : bool or callable
        A bar, nothing, or a callable taking the simulated time reached (s).
    setup : tailbeam.solvers.modal_setup.setup.ModalSetup, optional
        The modal plate (None: the rigid plate): two-way, its modes in the active sets, or
        one-way; either way the plate loads drive its modes for the sensors.
    sensors : tuple of SensorSpec
        The sensors the result's plate response is read at.
    info : dict, optional
        More entries for ``Result.info``.
    streams : sequence of StreamSettings
        The streams ``particles`` come from: what each delivered goes to ``info["streams"]``
        (``tailbeam.streams.delivery``) and is said on stderr; the largest release delay (s)
        of any particle to ``stats["release_delay_max"]``.
    frames : sequence of float
        Frame times (s): every ball's state there goes to the result's ``frames``.
    friction : FrictionModel, optional
        Friction, rolling resistance and the balls' rotation (``solve_stream``; on the
        two-way modal plate the force's moment drives the modes); None: frictionless.
    """
    run = solve_stream(
        particles, incline, duration, rtol=rtol, rest_speed=rest_speed, max_work=max_steps,
        progress=progress, plate=_stream_plate(setup),
        contacts=contact_table(particles, laws, incline.plate.material), frames=frames,
        friction=friction, loads=setup is not None,  # (only a modal plate replays them)
    )  # fmt: skip
    number_contacts(run.contacts, run.leaves, incline)
    flow = _delivered(streams, particles, run, duration)
    return Result(
        duration=duration, particles=tuple(run.particles),
        impacts=sorted(run.contacts, key=lambda r: (r.t_start, r.ball)), events=run.events,
        leaves=run.leaves, status=run.status, message=run.message, stats=run.stats,
        info={"solver": "fast stream solver (event-driven, active-set DOP853)",
              **(setup.info() if setup else {}), **flow, **_friction_info(friction),
              **(info or {})},
        sensors=tuple(sensors), plate=_response(setup, run), frames=run.frames,
        angular_velocity=run.angular_velocity,
    )  # fmt: skip


def _delivered(streams, particles, run, duration) -> dict:
    """``{"streams": delivery}`` of the run's streams (said on stderr; empty without streams);
    sets ``run.stats["release_delay_max"]`` (s)."""
    delays = [r.t_release - p.t_release for p, r in zip(particles, run.particles, strict=True)]
    run.stats["release_delay_max"] = max(delays, default=0.0)
    if not streams:
        return {}
    flow = delivery(streams, particles, run.particles, duration)
    for name, entry in flow.items():
        note(delivery_line(name, entry))
    return {"streams": flow}


def simulate_reference(
    particles, incline, duration, *, laws, rtol=REFERENCE_RTOL, max_steps=REFERENCE_MAX_STEPS,
    progress=None, info=None, friction=None,
) -> Result:  # fmt: skip
    """The slow reference (``simulate_stream_reference``) on ``particles``, as a Result;
    arguments as ``simulate_stream``'s (``info``: more entries for ``Result.info``;
    ``friction``: a ``FrictionModel`` or None)."""
    ref = simulate_stream_reference(
        [p.ball() for p in particles], incline, duration,
        contacts=contact_table(particles, laws, incline.plate.material), rtol=rtol,
        max_steps=max_steps, release_times=[p.t_release for p in particles], progress=progress,
        friction=friction,
    )  # fmt: skip
    stats = {"n_steps": ref.steps, "n_contacts": len(ref.contacts), "n_leaves": len(ref.leaves)}
    number_contacts(ref.contacts, ref.leaves, incline)
    return Result(
        duration=duration, particles=tuple(particles),
        impacts=sorted(ref.contacts, key=lambda r: (r.t_start, r.ball)), events=ref.events,
        leaves=ref.leaves, message="reached the end of the simulation", stats=stats,
        info={**ref.info, **(info or {})},
        angular_velocity={} if friction is None else ref.angular_velocity,
    )  # fmt: skip


def _friction_info(friction) -> dict:
    """The Result.info entry of a run with friction (none without)."""
    if friction is None:
        return {}
    return {"friction": "Adams CONTACT friction and rolling resistance, rotation"}


def _setting(value, default):
    return default if value is None else value


def _stream_plate(setup) -> StreamPlate | None:
    """The two-way modal plate of the active sets, from the scene's modal set-up."""
    if setup is None or not setup.two_way:
        return None
    return StreamPlate(setup.basis, setup.zeta, tail=setup.contact_tail,
                       residual_flexibility=setup.settings.residual_flexibility)  # fmt: skip


def _response(setup, run) -> LoadResponse | None:
    """The modal plate's response to the run's plate loads (None on the rigid plate)."""
    if setup is None:
        return None
    return LoadResponse.from_records(setup.basis, setup.zeta, run.loads, run.dead_loads,
                                     quasi_static=setup.settings.residual_flexibility)  # fmt: skip


@contextlib.contextmanager
def _bar(scene):
    """The progress bar of a stream run: yields the callable the solvers report the simulated
    time reached (s) to."""
    with task(f"simulating {scene.duration:g} s", total=scene.duration, unit="s") as bar:
        reached = [0.0]

        def advance(t):
            bar.update(t - reached[0])
            reached[0] = t

        yield advance
