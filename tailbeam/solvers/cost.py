"""What a run will cost: one model per piece of work, and the run as their sum.

``tailbeam.solvers.run_cost.estimate_run(scene, solver)`` returns a ``RunCost``: one ``Part``
per piece of work, each with its own model here and its time (s), peak memory (bytes), what
drives it and whether it is already cached:

- ``eigen-solve``: the modal basis of the band (DOFs counted on the mesh, modes by Weyl's
  count): the assembly, two factorisations and the shift-invert solves with their
  orthogonalisation (``tailbeam.plate.fe.cost.solve_time``), nothing if the basis is cached
  (loading it: CACHE_LOAD_BYTES_PER_S);
- ``contact tails``: a stream's wider basis to the tails' band on the band's own mesh, the
  same model;
- ``simulation``: the solver's steps. Single balls on the modal plate: every impact
  ``steps_per_contact`` steps, each O(modes x balls^2) (the certified flights and event
  checks of every flying ball); on the rigid plate a fixed time per impact. The stream
  solver: per particle, and per particle and mode on the modal plate. The stream reference:
  its expected steps (per contact and per particle), each O(N^2) (all pairs). The impacts of
  a ball: its bounces, from the restitution of its hardest impact, until it rests or the run
  ends (``expected_impacts``);
- ``sensor replay``: every sensor's chain on its fine grid (``tailbeam.signals.sensor``):
  the exact modal response at each fine sample (O(modes)), the resonance's FFT and the
  anti-alias filter (O(taps));
- ``writing``: the CSV files (per value) and one figure per sensor (per sample).

- ``set-up`` (single balls): the band's contact pulses and, where ``plate.tail`` builds it,
  the Ritz tail's pre-pass (FE solves: DOF^1.5 per contact point).

Every time is the CPU time of one core (one BLAS thread): what the run takes on an idle
machine; under load the wall time is longer by about the load average over the cores
(``load_stretch``). The eigen-solves' rates are measured in CPU time
(``tailbeam.plate.fe.cost``); the other constants were fitted to wall times of
``benchmarks/bench_cost_model.py`` at load averages ~3-10 and checked against its CPU times
at 14-19 (docs/band-and-cost.md's table); those marked (c) were set from those CPU times,
where the wall-time fit was more than 2x off. They estimate, they do not bound.
"""

import math
import os
from dataclasses import dataclass

from tailbeam.errors import InputError
from tailbeam.plate.fe.cost import solve_time

EIGEN_WORDS = 6.0  # doubles per DOF per mode held during the solve (and by a loaded basis)
BASE_MEMORY = 2.0e8  # bytes: interpreter, numpy, scipy, numba
MODAL_BASE_MEMORY = 3.0e8  # bytes: the same with the FE assembly and the modal kernels
CACHE_LOAD_BYTES_PER_S = 5e8  # reading a cached basis (npz)
SETUP_BASE = 0.02  # s: building the basis' probes
SETUP_PULSE = 0.01  # s per ball: its hardest impact's force pulse (the automatic band)
STREAM_SETUP = 0.4  # s: a stream's modal set-up on cached bases (c: 0.34 and 0.55 s measured)
RITZ_DOF_POINT = 5.5e-7  # s per DOF^1.5 and contact point: the Ritz tail's pre-pass (FE solves)
COUPLED_BASE = 0.03  # s: a coupled run's set-up and result
COUPLED_BALL = 0.066  # s per ball: its residual compliance (an FE load solve), its records
COUPLED_STEP = 1.6e-9  # s per step, mode and ball^2 (single balls on the modal plate) (c)
COUPLED_FACTOR = 4e-8  # s per DOF^1.5: factorising K for the residual compliance (c)
COUPLED_STEP_BASE = 1.6e-6  # s per step
COUPLED_OVERHEAD = 1.3  # steps per contact step: event location, flights
RIGID_BASE = 0.01  # s
RIGID_IMPACT = 2.8e-4  # s per impact (rigid plate, one DOP853 contact integration)
STREAM_BASE = 0.8  # s: the stream solver's set-up (contact table, driver, kernels)
STREAM_PARTICLE = 4.4e-3  # s per particle, fast stream solver, rigid plate
STREAM_PARTICLE_MODE = 3.5e-2  # s per particle and 100 modes in the active sets (two-way)
STREAM_PARTICLE_TAIL = 8e-4  # s per particle and tail oscillator (two-way, contact tails)
REFERENCE_STEP = 4.5e-3  # s per step of the stream reference at REFERENCE_PARTICLES
REFERENCE_PARTICLES = 12
REFERENCE_STEPS_PER_CONTACT = 20
REFERENCE_STEPS_PER_PARTICLE = 20
REPLAY_BASE = 0.35  # s: importing scipy.signal, once
REPLAY_SENSOR = 0.25  # s per sensor: its chain's filters
REPLAY_SENSOR_MODE = 6e-4  # s per sensor, mode and sqrt(balls): quasi-static correction (c)
REPLAY_RITZ = 2e-8  # s per sensor and DOF^1.5: the Ritz tail's static part (FE solves) (c)
REPLAY_SAMPLE_MODE = 1.0e-8  # s per fine sample and mode (modal response at the sensor)
REPLAY_SAMPLE = 2.0e-7  # s per fine sample: resonance FFT, anti-alias filter, spectrum
REPLAY_PARTICLE_MODE = 3e-5  # s per stream particle and mode: its loads' modal response (c)
REPLAY_WORDS = 12.0  # doubles held per fine sample (signal, padded FFT, filtered copies)
WRITE_BASE = 0.015  # s: impacts.csv, particles.csv, impacts.json (c)
WRITE_VALUE = 1.8e-6  # s per CSV value written (numbers formatted by Python)
PLOT_BASE = 1.2  # s: importing matplotlib, once, when a sensor is plotted
FIGURE_BASE = 1.2  # s per figure
FIGURE_SAMPLE = 2e-6  # s per sample plotted (a sensor's figure: signal and spectrum)
SENSOR_TIME_LIMIT = 30.0  # s: refuse a sensor whose replay and outputs would take longer
SENSOR_MEMORY_LIMIT = 3.0e9  # bytes: or hold more


@dataclass(frozen=True)
class Part:
    """One piece of a run's work: its name, estimated time (s) and peak memory (bytes),
    what drives it (words), whether its result is already cached (time ~0), and whether it
    is estimated at all (``estimated`` False: time and memory count as 0, said so)."""

    name: str
    time_s: float
    memory_bytes: float
    driver: str = ""
    cached: bool = False
    estimated: bool = True

    def describe(self) -> str:
        what = f" ({self.driver})" if self.driver else ""
        if not self.estimated:
            return f"{self.name}{what} not estimated"
        return f"{self.name}{what} {'cached' if self.cached else _seconds(self.time_s)}"


@dataclass(frozen=True)
class RunCost:
    """The parts of a run and the main alternative (``alternative``: one phrase, or "")."""

    parts: tuple
    alternative: str = ""

    @property
    def time_s(self) -> float:
        """The whole run's estimated time, s: the sum of the parts."""
        return sum(p.time_s for p in self.parts)

    @property
    def memory_bytes(self) -> float:
        """The run's estimated peak memory, bytes: the largest part's."""
        return max((p.memory_bytes for p in self.parts), default=BASE_MEMORY)

    def part(self, name: str) -> Part | None:
        return next((p for p in self.parts if p.name == name), None)

    def describe(self) -> str:
        """One line: the total (naming the parts it leaves out, if any are not estimated),
        then each part, then the alternative."""
        parts = ", ".join(p.describe() for p in self.parts)
        unknown = [p.name for p in self.parts if not p.estimated]
        head = "estimated cost"
        if unknown:
            head = f"estimated cost without the {' and '.join(unknown)} (not estimated)"
        total = f"{head} {_seconds(self.time_s)}, ~{self.memory_bytes / 1e6:.0f} MB"
        line = f"{total}: {parts}"
        return f"{line}; {self.alternative}" if self.alternative else line

    def as_dict(self) -> dict:
        return {
            "time_s": self.time_s,
            "memory_bytes": self.memory_bytes,
            "parts": {p.name: {"time_s": p.time_s, "memory_bytes": p.memory_bytes,
                               "cached": p.cached, "driver": p.driver} for p in self.parts},
            "alternative": self.alternative,
        }  # fmt: skip


def load_stretch() -> tuple:
    """(stretch, load average, cores): how many times longer than the estimate (the CPU
    time of one core, which the run gets whole on an idle machine) its wall time may be on
    this machine now: the 1-minute load average over the cores, at least 1 (the run shares
    the cores with that many running processes)."""
    cores = os.cpu_count() or 1
    try:
        load = os.getloadavg()[0]
    except (AttributeError, OSError):  # not on every platform
        return 1.0, 0.0, cores
    return max(1.0, load / cores), load, cores


def _seconds(t: float) -> str:
    return f"~{t:.0f} s" if t >= 10 else f"~{t:.1f} s"


# -- the parts ---------------------------------------------------------------------------------


def eigen_part(name: str, n_dofs: int, n_modes: int, cached_bytes: float | None, driver: str):
    """The eigen-solve of ``n_modes`` modes of an ``n_dofs`` model (``cached_bytes``: the
    cached basis' file size, None when it must be computed)."""
    memory = MODAL_BASE_MEMORY + 8.0 * EIGEN_WORDS * n_dofs * n_modes
    if cached_bytes is not None:
        return Part(name, cached_bytes / CACHE_LOAD_BYTES_PER_S, memory, driver, cached=True)
    return Part(name, solve_time(n_dofs, n_modes), memory, driver)


def setup_part(n_dofs: int, ritz_points: int, pulses: int = 0) -> Part:
    """The rest of a single-ball modal set-up: the band's ``pulses`` (one per ball when the
    band is chosen automatically), the basis' probes and, on ``ritz_points`` contact
    points, the Ritz tail's pre-pass (an FE solve per vector)."""
    time_s = SETUP_BASE + SETUP_PULSE * pulses + RITZ_DOF_POINT * n_dofs**1.5 * ritz_points
    what = f"Ritz tail at {ritz_points} points" if ritz_points else "quasi-static tail"
    return Part("set-up", time_s, MODAL_BASE_MEMORY, what)


def stream_setup_part() -> Part:
    """The rest of a stream's modal set-up: its band's check, the bases' probes."""
    return Part("set-up", STREAM_SETUP, MODAL_BASE_MEMORY, "stream")


def coupled_part(impacts: float, n_balls: int, n_modes: int, steps_per_contact: int,
                 fe_dofs: int = 0) -> Part:  # fmt: skip
    """Single balls on the modal plate: ``impacts`` contacts of ``steps_per_contact`` steps;
    ``fe_dofs``: the flat plate's FE DOFs, factorised for the residual compliance (0: none)."""
    steps = COUPLED_OVERHEAD * impacts * steps_per_contact
    per_step = COUPLED_STEP_BASE + COUPLED_STEP * n_modes * max(n_balls, 1) ** 2
    memory = MODAL_BASE_MEMORY + 8.0 * steps * (1 + 4 * n_balls)  # the recorded nodes
    time_s = COUPLED_BASE + COUPLED_BALL * n_balls + steps * per_step
    time_s += COUPLED_FACTOR * fe_dofs**1.5
    return Part("simulation", time_s, memory,
                f"{impacts:.0f} impacts x {steps_per_contact} steps, {n_modes} modes")  # fmt: skip


def rigid_part(impacts: float) -> Part:
    return Part("simulation", RIGID_BASE + RIGID_IMPACT * impacts, BASE_MEMORY,
                f"{impacts:.0f} impacts")  # fmt: skip


def stream_part(n_particles: int, n_modes: int = 0, tail_oscillators: int = 0) -> Part:
    """The fast stream solver: per particle, and per particle and mode / tail oscillator in
    the active sets on the two-way modal plate."""
    per = STREAM_PARTICLE + STREAM_PARTICLE_MODE * n_modes / 100.0
    per += STREAM_PARTICLE_TAIL * tail_oscillators
    modal = f", {n_modes} modes" if n_modes else ""
    base = MODAL_BASE_MEMORY if n_modes else BASE_MEMORY
    return Part("simulation", STREAM_BASE + n_particles * per, base + 4e4 * n_particles,
                f"{n_particles} particles{modal}")  # fmt: skip


def reference_part(n_particles: int, impacts: float) -> Part:
    """The stream reference: its expected steps, each O(N^2)."""
    steps = REFERENCE_STEPS_PER_CONTACT * impacts + REFERENCE_STEPS_PER_PARTICLE * n_particles
    per_step = REFERENCE_STEP * max(1.0, (n_particles / REFERENCE_PARTICLES) ** 2)
    memory = BASE_MEMORY + steps * (48.0 * n_particles + 300.0)
    return Part("simulation", steps * per_step, memory,
                f"~{steps:.0f} steps of {n_particles} bodies")  # fmt: skip


def replay_part(sensors, duration: float, n_modes: int, top_hz: float, particles: int = 0,
                ritz_dofs: int = 0, balls: int = 0):  # fmt: skip
    """Every sensor's chain on its fine grid (``tailbeam.signals.sensor.measure``); a stream's
    ``particles``: the modal response to their recorded loads; ``ritz_dofs``: the FE model's
    DOFs when the basis carries the Ritz tail (its static part at each sensor); ``balls``:
    the single balls whose contact forces the quasi-static correction reads."""
    fines = [_fine_samples(s, duration, top_hz) for s in sensors]
    per = REPLAY_SAMPLE + REPLAY_SAMPLE_MODE * n_modes
    per_sensor = REPLAY_SENSOR + REPLAY_SENSOR_MODE * n_modes * math.sqrt(max(balls, 1))
    per_sensor += REPLAY_RITZ * ritz_dofs**1.5
    time_s = REPLAY_BASE + per_sensor * len(sensors) + per * sum(fines)
    time_s += REPLAY_PARTICLE_MODE * particles * n_modes
    memory = MODAL_BASE_MEMORY + 8.0 * REPLAY_WORDS * max(fines, default=0)
    what = f"{len(sensors)} sensors, {sum(fines):.3g} fine samples x {n_modes} modes"
    return Part("sensor replay", time_s, memory, what)


def write_part(scene, timeseries: bool, sensors: bool) -> Part:
    """The CSV files and the sensors' figures (one column and figure per signal: per axis)."""
    signals = [c for s in scene.sensors for c in s.channels()] if sensors else []
    values = 0.0
    if timeseries:
        values += (scene.duration * scene.sample_rate + 1) * (1 + 3 * len(scene.balls))
    samples = sum(scene.duration * s.sample_rate + 1 for s in signals)
    values += 1.5 * samples  # sensors.csv and the spectra (half the samples)
    figures = len(signals)
    time_s = WRITE_BASE + WRITE_VALUE * values + FIGURE_SAMPLE * samples
    time_s += (PLOT_BASE + figures * FIGURE_BASE) if figures else 0.0
    return Part("writing", time_s, BASE_MEMORY + 8.0 * 3 * values, f"{values:.3g} values")


def _fine_samples(sensor, duration: float, top_hz: float) -> float:
    fs = sensor.sample_rate
    oversample = max(2, math.ceil(2.5 * top_hz / fs))
    return (duration * fs + 1) * oversample


def check_replay(scene, n_modes: int, top_hz: float) -> None:
    """InputError naming ``sensors[i].sample_rate`` (1-based, as the scene file lists them)
    when one sensor's replay and outputs would exceed SENSOR_TIME_LIMIT or
    SENSOR_MEMORY_LIMIT."""
    for i, sensor in enumerate(scene.sensors, start=1):
        n = scene.duration * sensor.sample_rate + 1
        replay = replay_part((sensor,), scene.duration, n_modes, top_hz)
        time_s = replay.time_s + (WRITE_VALUE * 1.5 + FIGURE_SAMPLE) * n
        if time_s > SENSOR_TIME_LIMIT or replay.memory_bytes > SENSOR_MEMORY_LIMIT:
            raise InputError(
                f"sensors[{i}].sample_rate",
                f"{sensor.sample_rate:g} Hz over {scene.duration:g} s on {n_modes} modes: its "
                f"replay and outputs would take ~{time_s:.0f} s and "
                f"~{replay.memory_bytes / 1e9:.1f} GB (estimated; limits "
                f"{SENSOR_TIME_LIMIT:.0f} s, {SENSOR_MEMORY_LIMIT / 1e9:.0f} GB); lower it or "
                "the duration",
            )
