"""``tailbeam.simulate(scene, **how)``: the one library call that runs a scene.

What to simulate (a ``tailbeam.scene.Scene``) is positional; how (the solver, rtol,
max_steps, progress) is keyword-only. It returns one result type, ``tailbeam.results.result.Result``,
whichever solver runs. The solver is a swappable part (``solver=``, ``SOLVERS``):

- ``"single-ball"``: the exact per-ball solvers, for scenes without streams, without
  inclination and without two balls that can touch (their horizontal paths never come within
  the sum of the radii): on the rigid plate ``tailbeam.solvers.rigid.simulate_rigid`` (its
  ``Result`` is a ``RigidResult``), on the modal plate the coupled modal solver
  (``tailbeam.solvers.coupled.simulate_scene_modal``, a ``CoupledResult``);
- ``"stream"``: the fast stream solver (``tailbeam.solvers.stream.engine``, a
  ``StreamResult``), on the rigid or the modal plate; it runs every scene;
- ``"stream-reference"``: the slow independent reference of the stream solver (scipy DOP853,
  every pair watched, at most ``REFERENCE_MAX_PARTICLES`` bodies), on the rigid plate;
- ``"auto"`` (the default): ``"single-ball"`` where it can run, else ``"stream"``.

Running one scene through two solvers is how a user checks one against the other.
"""

import contextlib
import math

from tailbeam.errors import InputError, WorkLimitError
from tailbeam.progress import note, quiet, task

STREAM_MIN_BAND_HZ = 10_000.0  # modal band of a stream scene without sensors or plate.fmax
MAX_STREAM_MEMORY = 2e9  # bytes the reference may keep (its step budget x state size)
SOLVERS = ("auto", "single-ball", "stream", "stream-reference")


def simulate(scene, *, solver="auto", rtol=None, max_steps=None, progress=True):
    """Simulate ``scene`` and return its result.

    Parameters
    ----------
    scene : tailbeam.scene.Scene
        What to simulate (e.g. from ``tailbeam.io.scene_file.load_scene``).
    solver : str
        Which solver runs it, one of ``SOLVERS`` (module docstring); ``"auto"`` by default.
        The choice is in ``result.info["solver_choice"]``; ``result.info["solver"]`` keeps
        the chosen solver's own description (method, tolerance).
    rtol : float, optional
        Relative tolerance of the solver (rigid: its default 1e-10; stream reference 1e-10).
    max_steps : int, optional
        Step budget (rigid: per ball; stream solver: in all); WorkLimitError beyond it.
    progress : bool
        Show progress and the automatic choices on stderr (``tailbeam.progress``).

    Returns
    -------
    tailbeam.Result
        One interface for every solver: ``status``, ``message``, ``stats``, ``info``,
        ``impacts_table()`` (impacts.csv as numpy columns), ``particles_table()``
        (particles.csv), ``events_of(name, kind)``, ``impacts_of(name)``, ``leaves``,
        ``sensor_outputs`` / ``sensor_signals``, ``plate_model``; ``sample(times)`` for the
        single-ball solvers (``keeps_states``). The subclass (``RigidResult``,
        ``CoupledResult``, ``StreamResult``) adds what is its solver's own (the modal replay
        of ``CoupledResult``, ...).
    """
    from tailbeam.scene import Scene

    if not isinstance(scene, Scene):
        raise InputError("scene", f"must be a tailbeam.scene.Scene, got {type(scene).__name__}")
    how = {k: v for k, v in (("rtol", rtol), ("max_steps", max_steps)) if v is not None}
    method = choose_solver(scene, solver)
    with contextlib.nullcontext() if progress else quiet():
        if method == "single-ball":
            result = _modal(scene, how) if scene.plate_model == "modal" else _rigid(scene, how)
            result.labels = scene.labels  # the scene's coal / gangue labels of its balls
        else:
            result = _through_stream(scene, how, method == "stream-reference")
    result.info["solver_choice"] = method
    return result


def choose_solver(scene, solver: str = "auto", field: str = "solver") -> str:
    """The solver that runs ``scene`` (one of ``SOLVERS`` but "auto"): ``solver`` itself,
    checked against the scene before any work, or for "auto" the single-ball solvers where
    they can run, else the stream solver. InputError naming ``field`` (the caller's name,
    e.g. ``--solver``) for a solver that cannot run the scene."""
    if solver not in SOLVERS:
        raise InputError(field, f"must be one of {', '.join(SOLVERS)}; got {solver!r}")
    if solver == "auto":
        return "stream" if scene.needs_stream_solver else "single-ball"
    if solver == "single-ball" and scene.needs_stream_solver:
        raise InputError(
            field,
            f"'single-ball' cannot run this scene ({_why_stream(scene)}): streams, an inclined "
            "plate and ball-ball contact need 'stream' or 'stream-reference'",
        )
    if solver == "stream-reference" and scene.plate_model != "rigid":
        raise InputError(
            field,
            "'stream-reference' runs on the rigid plate (plate.model = \"rigid\"); its modal "
            "plate (tailbeam.solvers.stream.reference.plate) has no residual flexibility or "
            "sensors, and is used by the tests",
        )
    return solver


def _through_stream(scene, how, reference: bool):
    """``scene`` through the fast stream solver (or its reference), then its sensors."""
    from tailbeam.solvers.coupled.ritz_prepass import check_tail_scene

    check_tail_scene(scene)  # before any work
    band = stream_band(scene) if scene.plate_model == "modal" else None
    if band and band["tail_band_hz"] is None and scene.modal.tail != "quasi-static":
        note(f"tail: quasi-static (plate.tail {scene.modal.tail}: {band['tail_reason']})")
    if band:  # (here, not in stream_band, which a sweep's client calls for every case)
        warning = check_stream_band(scene, band)
        if warning:
            note(warning)
    plate = _stream_plate(scene, band) if band and band["two_way"] else None
    result = _stream(scene, how, plate, reference)
    if band:
        _modal_sensors(scene, result, band, plate)
    return result


def check_stream_band(scene, band: dict) -> str | None:
    """Add the band check of a stream scene to its ``band`` (``stream_band``; the keys of
    ``tailbeam.solvers.coupled.auto.stream_band_estimate``); the one line to show when the
    band is below what the shortest plate contact needs, else None."""
    from tailbeam.solvers.coupled.auto import stream_band_estimate

    # with the contact tail the contacts see the modes to its band (tailbeam.solvers.stream.
    # contact_tail; its own error, measured <= 0.33 %, is not in the estimate)
    seen = band.get("tail_band_hz") or band["fmax_hz"]
    band.update(stream_band_estimate(scene, seen, band["residual_flexibility"]))
    if band.get("truncation_force_error", 0.0) > band["accuracy"]:
        return _band_warning(band)
    return None


def _band_warning(band) -> str:
    """One line: the band the stream's contacts see (its modal band, or its contact tails')
    is below what its shortest plate contact needs."""
    error = band["truncation_force_error"]
    estimate = (
        f"estimated error up to {error:.1%} (an upper estimate: measured 0.04-0.85 of it"
        if math.isfinite(error)
        else "the band stops below that contact's own frequency (no error estimate"
    )
    tails = band.get("tail_band_hz")
    tails = f", contact tails to {tails / 1e3:g} kHz" if tails else ""
    return (
        f"modal band 0-{band['fmax_hz'] / 1e3:g} kHz ({band['reason']}{tails}): the shortest plate "
        f"contacts ({band['hardest_contact']}, {band['contact_duration_min_s'] * 1e6:.0f} us) "
        f"would need {band['fmax_contact_hz'] / 1e3:.1f} kHz for a {band['accuracy']:.1%} peak "
        f"force; {estimate}; docs/streams.md, band and particle size)"
    )


def _rigid(scene, how):
    from tailbeam.solvers.rigid import simulate_rigid

    with task(f"simulating {scene.duration:g} s, {len(scene.balls)} balls, rigid plate"):
        return simulate_rigid(
            scene.balls, scene.plate, scene.contacts(), scene.duration, gravity=scene.gravity, **how
        )


def _modal(scene, how):
    from tailbeam.solvers.coupled import simulate_scene_modal

    if how:
        raise InputError(next(iter(how)), "is not a setting of the modal plate solver")
    # The modal path chooses its band from the scene (contact durations, sensor bandwidths),
    # the theory from the band, and records both choices in result.info.
    return simulate_scene_modal(scene)


def _stream(scene, how, plate=None, reference=False):
    from tailbeam.preflight import check_streams
    from tailbeam.solvers.stream.engine import reference_engine, stream_engine

    engine = reference_engine() if reference else stream_engine()
    check_streams(scene, engine)  # (load_scene checked for the fast solver; not Python scenes)
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
        f"rtol {rtol:g}, work bound {max_steps} steps (estimated <= {memory / 1e6:.0f} MB, "
        f"~{worst:.0f} s or less)"
    )
    with task(f"simulating {scene.duration:g} s", total=scene.duration, unit="s") as bar:
        reached = [0.0]

        def advance(t):
            bar.update(t - reached[0])
            reached[0] = t

        extra = {} if plate is None else {"plate": plate}
        return engine.run(
            particles, scene.incline, scene.duration, laws=scene.contacts(), rtol=rtol,
            max_steps=max_steps, progress=advance, **extra,
        )  # fmt: skip


def stream_band(scene) -> dict:
    """The modal band of a stream scene: plate.fmax, else the sensors' bandwidth (at least
    STREAM_MIN_BAND_HZ), and the coupling (plate.coupling: two-way by default)."""
    from tailbeam.scene import ModalPlateSettings
    from tailbeam.signals.sensor import resolve
    from tailbeam.solvers.coupled.auto import BAND_ACCURACY

    settings = scene.modal or ModalPlateSettings()
    f_sensor = max((resolve(s).bandwidth_hz for s in scene.sensors), default=0.0)
    fmax = settings.fmax_hz or max(f_sensor, STREAM_MIN_BAND_HZ)
    two_way = settings.coupling == "two-way"
    return {**_stream_tail(settings, fmax, two_way),
        "fmax_hz": float(fmax), "user_fmax": settings.fmax_hz is not None,
        "reason": "plate.fmax" if settings.fmax_hz else "the sensors' bandwidth",
        "sensor_band_covered": bool(fmax >= f_sensor),
        "accuracy": BAND_ACCURACY, "residual_flexibility": settings.residual_flexibility,
        "two_way": two_way,
        "coupling": (
            "two-way (the modes in the stream solver's active set; residual flexibility at "
            f"the contacts {'on' if settings.residual_flexibility else 'off'})" if two_way
            else "one-way (stream contacts on the rigid plate drive the modes)"
        ),
    }  # fmt: skip


def _stream_tail(settings, fmax: float, two_way: bool) -> dict:
    """The stream's contact tail (plate.tail, tailbeam.plate.contact_tail): with
    "ritz" or "auto" (the default), where it applies (two-way coupling, residual flexibility,
    a band below TAIL_MAX_HZ / 1.5), k oscillators per contact for the modes up to
    ``tail_band_hz`` (TAIL_BAND_FACTOR x the band, at most TAIL_MAX_HZ); else None: the
    static spring alone, for ``tail_reason``."""
    from tailbeam.plate.contact_tail import TAIL_BAND_FACTOR, TAIL_MAX_HZ

    why = None
    wide = min(TAIL_BAND_FACTOR * fmax, TAIL_MAX_HZ)
    if settings.tail == "quasi-static":
        why = "plate.tail"
    elif not (two_way and settings.residual_flexibility):
        why = "one-way coupling" if not two_way else "residual flexibility off"
    elif wide < 1.5 * fmax:
        why = f"the band is within 1.5x of {TAIL_MAX_HZ / 1e3:g} kHz, where contact tails stop"
    k = settings.tail_modes_for(stream=True)
    return {
        "tail_band_hz": None if why else wide,
        "tail_oscillators": 0 if why else int(k), "tail_reason": why or "",
    }  # fmt: skip


def _basis_and_damping(scene, band):
    from tailbeam.plate.basis import modal_damping
    from tailbeam.scene import ModalPlateSettings
    from tailbeam.solvers.coupled.auto import build_basis

    settings = scene.modal or ModalPlateSettings()
    basis = build_basis(scene, band)
    return basis, modal_damping(basis.omega, settings.damping_ratio, settings.rayleigh)


def _stream_plate(scene, band):
    """The two-way modal plate of a stream scene (tailbeam.solvers.stream.plate)."""
    from tailbeam.scene import ModalPlateSettings
    from tailbeam.solvers.stream.plate import StreamPlate

    basis, zeta = _basis_and_damping(scene, band)
    settings = scene.modal or ModalPlateSettings()
    tail = _contact_tail(scene, band, basis) if band["tail_band_hz"] else None
    return StreamPlate(basis, zeta, residual_flexibility=settings.residual_flexibility, tail=tail)


def _contact_tail(scene, band, basis):
    """The oscillators of a stream's contacts (tailbeam.plate.contact_tail), from a
    basis to TAIL_BAND_FACTOR x the band (computed once, cached)."""
    from tailbeam.plate.basis import modal_damping
    from tailbeam.plate.contact_tail import ContactTail

    settings = scene.modal
    wide_hz, k = band["tail_band_hz"], band["tail_oscillators"]
    wide = tail_basis(scene, band, basis)
    how = "plate.tail" if settings.tail == "ritz" else "plate.tail auto"
    note(
        f"tail: {k} oscillators at each plate contact for the modes between "
        f"{band['fmax_hz'] / 1e3:g} and {wide_hz / 1e3:g} kHz ({wide.n_modes - basis.n_modes} "
        f"modes; {how}), a static spring for those above"
    )

    def damping(nu):
        return modal_damping(nu, settings.damping_ratio, settings.rayleigh)

    return ContactTail(basis.omega, wide, k, damping)


def tail_basis(scene, band, basis):
    """The basis of a stream's contact tails: to band["tail_band_hz"] on the band basis' own
    FE mesh (its modes below the band are the band's; the mesh the wider band alone would
    choose is ~5x larger and takes minutes), or a closed form."""
    from tailbeam.plate import compute_modes
    from tailbeam.solvers.coupled.auto import build_basis

    wide_hz = band["tail_band_hz"]
    if "divisions" not in basis.info:  # a closed form
        return build_basis(scene, {**band, "fmax_hz": wide_hz})
    return compute_modes(scene.plate, basis.boundary, theory=basis.info["theory"],
                         fmax_hz=wide_hz, divisions=basis.info["divisions"])  # fmt: skip


def _modal_sensors(scene, result, band, plate):
    """The sensors of a stream on the modal plate: the stream's plate forces (two-way, or
    one-way from the rigid plate: ``result.loads``) drive the modes exactly; the sensors read
    the plate there (tailbeam.solvers.plate_loads.response)."""
    from tailbeam.scene import ModalPlateSettings
    from tailbeam.solvers.coupled.auto import _choices
    from tailbeam.solvers.plate_loads.loads import PlateLoads
    from tailbeam.solvers.plate_loads.response import sensor_outputs

    settings = scene.modal or ModalPlateSettings()
    if plate is None:
        basis, zeta = _basis_and_damping(scene, band)
    else:
        basis, zeta = plate.basis, plate.zeta
    result.info.update(_choices(band, basis))
    note(
        f"modal plate under a stream: {band['coupling']}, band 0-{band['fmax_hz'] / 1e3:.1f} kHz"
        f" ({band['reason']}), {basis.theory}, {basis.n_modes} modes"
    )
    contacts, dead = result.loads
    loads = PlateLoads()
    for x, y, t, f in contacts:
        loads.add_contact(x, y, t, f)
    for x, y, t0, t1, f in dead:
        loads.add_dead_load(x, y, t0, t1, f)
    with task(f"sensor signals, {len(scene.sensors)} sensors, {loads.n_nodes} load nodes"):
        result.sensors = sensor_outputs(
            basis, zeta, loads, scene.sensors, scene.duration,
            quasi_static=settings.residual_flexibility,
        )  # fmt: skip


def _why_stream(scene) -> str:
    if not scene.needs_stream_solver:
        return "solver requested"
    if scene.streams:
        return f"{len(scene.streams)} stream(s)"
    if scene.inclination != 0.0:
        return f"plate inclined {scene.inclination:g} degrees"
    return "balls that may touch each other"
