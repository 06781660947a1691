"""The one result type of ``tailbeam.simulate``: ``Result``, built once by the solver that ran.

In the spirit of scipy's ``OdeResult`` and diffrax's ``Solution``: one type for every solver,
its fields filled once, when the run ends. What only some solvers can give is a part the
result holds, not a subclass:

- ``states`` (``BallStates``): the balls' states at any time, ``sample(times)``, and when each
  came to rest; the single-ball solvers keep it (rigid and modal plate), the stream solvers
  keep their records only (memory must not grow with steps x particles);
- ``plate`` (``PlateResponse``): the modal plate's response, which gives the sensors' signals
  (``sensor_outputs``) and the modal coordinates at any times; None on the rigid plate;
- ``frames`` (``tailbeam.results.frames.BallFrames``): every body's position and velocity at
  the frame times a run was asked for (``simulate(scene, frames=times)``), else None.

Columns of ``impacts_table()`` (one row per ball per contact; a ball-ball contact gives one
row for each of the two balls), in this order:

- ``IMPACT_COLUMNS``: ``ball``; ``index`` (1, 2, ... the ball's contacts with the plate and
  with balls, in time order); ``t_start``, ``t_end`` (s); ``v_in``, ``v_out`` (m/s: the ball's
  own velocity along the contact normal n, pointing from the partner to the ball: v_in = -v.n
  at first touch, > 0 approaching; v_out = v.n at the end, > 0 leaving); ``restitution``;
  ``peak_force`` (N) at ``t_peak`` (s); ``max_penetration`` (m, of the pair);
  ``next_apex_height`` (m); ``ends_at_rest``;
- then ``partner`` (``plate`` or the other ball's name), ``x``, ``y`` (contact point in the
  plate frame at first touch, m), ``material``, ``radius`` (m) of the row's ball;
- then ``label`` (coal / gangue), ``stream`` (empty for ``[[balls]]``), ``end`` (``End``),
  ``approach_in``, ``approach_out`` (m/s, the pair's normal approach speed at first touch and
  its separation speed at the end);
- then ``normal_impulse`` (N s, the integral of the pair's normal force; nan where the solver
  does not integrate it), ``tangential_impulse`` (N s, the magnitude of the friction force's
  integral on the row's ball; 0 without friction) and ``tangential_end`` (``sliding``,
  ``sticking`` or ``frictionless``).

``particles_table()`` ends with ``wx``, ``wy``, ``wz``: the body's angular velocity (rad/s,
plate frame) when it left the plate or at the end (``Result.angular_velocity``; without
friction its initial one, which frictionless contacts never change).
"""

import functools
import math
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from tailbeam.errors import InputError, require_positive
from tailbeam.results.frames import BallFrames

IMPACT_COLUMNS = (
    "ball", "index", "t_start", "t_end", "v_in", "v_out", "restitution", "peak_force",
    "t_peak", "max_penetration", "next_apex_height", "ends_at_rest",
)  # fmt: skip
IMPACT_UNITS = {
    "t_start": "s", "t_end": "s", "v_in": "m/s", "v_out": "m/s", "restitution": "1",
    "peak_force": "N", "t_peak": "s", "max_penetration": "m", "next_apex_height": "m",
}  # fmt: skip
IMPACT_TABLE_COLUMNS = IMPACT_COLUMNS + (
    "partner", "x", "y", "material", "radius",
    "label", "stream", "end", "approach_in", "approach_out",
    "normal_impulse", "tangential_impulse", "tangential_end",
)  # fmt: skip
IMPACT_TABLE_UNITS = {
    **IMPACT_UNITS, "x": "m", "y": "m", "radius": "m", "approach_in": "m/s", "approach_out": "m/s",
    "normal_impulse": "N s", "tangential_impulse": "N s",
}  # fmt: skip
PARTICLE_COLUMNS = (
    "name", "stream", "material", "label", "radius", "mass", "t_release",
    "x0", "y0", "z0", "vx0", "vy0", "vz0", "t_leave", "leave_edge", "wx", "wy", "wz",
)  # fmt: skip
PARTICLE_UNITS = {
    "radius": "m", "mass": "kg", "t_release": "s", "x0": "m", "y0": "m", "z0": "m",
    "vx0": "m/s", "vy0": "m/s", "vz0": "m/s", "t_leave": "s",
    "wx": "rad/s", "wy": "rad/s", "wz": "rad/s",
}  # fmt: skip
TEXT_COLUMNS = {
    "ball", "partner", "material", "label", "stream", "end", "name", "leave_edge",
    "tangential_end",
}  # fmt: skip


class BallStates(Protocol):
    """The balls' states at any time (a part of ``Result``: the single-ball solvers').

    ``rest_time`` maps each ball's name to the time (s) it came to rest (nan if it did not);
    ``sample(times)`` gives name -> {"z" m, "vz" m/s, "force" N} arrays at ``times`` (s).
    """

    rest_time: dict

    def sample(self, times: np.ndarray) -> dict: ...


class PlateResponse(Protocol):
    """The modal plate's response during a run (a part of ``Result`` on the modal plate).

    ``sensor_outputs(sensors, duration)`` gives name -> ``tailbeam.signals.sensor.SensorOutput``
    of the ``SensorSpec``s ``sensors`` over [0, duration] s; ``modal_coordinates(times)`` the
    kept modes' coordinates q (n_modes, len(times)) (sqrt(kg) m) at uniform ``times`` (s) of
    the mass-normalised shapes of ``basis``."""

    basis: object

    def sensor_outputs(self, sensors, duration: float) -> dict: ...

    def modal_coordinates(self, times) -> np.ndarray: ...


@dataclass(eq=False)
class Result:
    """What ``tailbeam.simulate`` returns, whichever solver ran (see the module docstring).

    Parameters
    ----------
    duration : float
        Simulated time (s).
    particles : tuple
        Every body as a ``tailbeam.streams.generator.Particle`` (release state, label,
        stream), in release order: the ``[[balls]]`` first.
    impacts : list
        The contact records (``tailbeam.results.records.Impact``) in the row order of
        impacts.csv: one per ball per contact, by start time.
    events : list
        ``tailbeam.results.records.Event`` records in time order.
    leaves : list
        ``tailbeam.results.records.LeaveEvent`` of every ball that left the plate.
    status : int
        0: the run reached ``duration``.
    message : str
        How the run ended.
    stats : dict
        The solver's work counts.
    info : dict
        What was chosen automatically (``solver``, ``solver_choice``, ``band``, ...).
    sensors : tuple
        The ``SensorSpec``s the plate response is read at.
    states : BallStates or None
        The balls' states at any time (single-ball solvers).
    plate : PlateResponse or None
        The modal plate's response; None on the rigid plate.
    angular_velocity : dict
        Name -> angular velocity (3,) rad/s of the bodies whose spin the solver followed
        (friction), when they left or at the end; the others keep their initial one.
    frames : BallFrames or None
        Every body's state at the frame times the run was asked for.
    """

    duration: float
    particles: tuple
    impacts: list
    events: list
    leaves: list = field(default_factory=list)
    status: int = 0
    message: str = ""
    stats: dict = field(default_factory=dict)
    info: dict = field(default_factory=dict)
    sensors: tuple = ()
    states: BallStates | None = field(default=None, repr=False)
    plate: PlateResponse | None = field(default=None, repr=False)
    angular_velocity: dict = field(default_factory=dict, repr=False)
    frames: BallFrames | None = field(default=None, repr=False)

    @property
    def plate_model(self) -> str:
        """``modal`` when the result holds the modal plate's response, else ``rigid``."""
        return "rigid" if self.plate is None else "modal"

    @property
    def keeps_states(self) -> bool:
        """True if ``sample(times)`` gives the balls' states (timeseries.csv)."""
        return self.states is not None

    def impacts_table(self) -> dict:
        """impacts.csv as columns: name -> numpy array, in ``IMPACT_TABLE_COLUMNS`` order."""
        by_name = {p.name: p for p in self.particles}
        rows = []
        for rec in self.impacts:
            p = by_name[rec.ball]
            rows.append(
                (*(getattr(rec, c) for c in IMPACT_COLUMNS), rec.partner, rec.x, rec.y,
                 p.material.name, p.radius, p.label, p.stream, str(rec.end), rec.approach_in,
                 rec.approach_out, rec.normal_impulse, rec.tangential_impulse,
                 rec.tangential_end)
            )  # fmt: skip
        return columns(IMPACT_TABLE_COLUMNS, rows)

    def particles_table(self) -> dict:
        """particles.csv as columns: name -> numpy array, in ``PARTICLE_COLUMNS`` order: the
        release state of every body (plate frame), its leave time (s, nan if it never left)
        and edge (empty if it never left), its final angular velocity (rad/s)."""
        leave = {e.ball: e for e in self.leaves}
        rows = []
        for p in self.particles:
            e = leave.get(p.name)
            spin = self.angular_velocity.get(p.name, p.angular_velocity)
            rows.append(
                (p.name, p.stream, p.material.name, p.label, p.radius, p.mass, p.t_release,
                 *p.position, *p.velocity,
                 e.time if e else math.nan, e.edge if e else "", *(float(w) for w in spin))
            )  # fmt: skip
        return columns(PARTICLE_COLUMNS, rows)

    def impacts_of(self, name: str) -> list:
        """The contact records of the ball called ``name``, in time order."""
        names = [p.name for p in self.particles]
        if name not in names:
            raise InputError("name", f"no ball called {name!r}; balls: {names[:10]}")
        return [imp for imp in self.impacts if imp.ball == name]

    def events_of(self, name: str, kind: str | None = None) -> list:
        """(t s, kind) of the ball's events in time order, optionally only those of ``kind``
        (an ``EventKind`` or its value string)."""
        kind = None if kind is None else str(getattr(kind, "value", kind))
        return [(e.t, e.kind) for e in self.events if e.ball == name and kind in (None, e.kind)]

    def sample(self, times) -> dict:
        """Ball states at ``times`` (s, within [0, duration]): name -> {"z" m, "vz" m/s,
        "force" N} arrays; only results that keep states (``keeps_states``) have them."""
        if self.states is None:
            raise InputError(
                "times",
                "this result keeps contact records, not states (a stream solver's result has no "
                "sample; impacts_table() and particles_table() hold what it recorded)",
            )
        return self.states.sample(self._times(times))

    def _times(self, times) -> np.ndarray:
        """``times`` (s) as a 1-D float array, checked finite and within [0, duration]."""
        t = np.atleast_1d(np.asarray(times, dtype=float))
        if t.ndim != 1 or not np.all(np.isfinite(t)):
            raise InputError("times", "must be a 1-D array of finite times in s")
        if t.size and (t.min() < 0.0 or t.max() > self.duration * (1.0 + 1e-12)):
            raise InputError("times", f"must lie within [0, duration = {self.duration!r}] s")
        return t

    def time_grid(self, sample_rate: float) -> np.ndarray:
        """Uniform times k / ``sample_rate`` (Hz) on [0, duration] s merged with every
        finite t_peak of ``impacts`` inside it."""
        rate = require_positive("sample_rate", sample_rate)
        n = int(math.floor(self.duration * rate * (1.0 + 1e-12))) + 1
        grid = np.arange(n, dtype=float) / rate
        peaks = [imp.t_peak for imp in self.impacts if 0.0 <= imp.t_peak <= self.duration]
        return np.unique(np.concatenate([grid[grid <= self.duration], np.asarray(peaks)]))

    @functools.cached_property
    def sensor_outputs(self) -> dict:
        """name -> ``tailbeam.signals.sensor.SensorOutput`` of every sensor (computed on
        first use from the plate's response; empty on the rigid plate)."""
        if self.plate is None or not self.sensors:
            return {}
        return self.plate.sensor_outputs(self.sensors, self.duration)

    @property
    def sensor_signals(self) -> dict:
        """name -> (t array s, acceleration array m/s^2) as sampled by each sensor."""
        return {name: (out.t, out.acceleration) for name, out in self.sensor_outputs.items()}


def columns(names, rows) -> dict:
    """Rows (tuples in ``names`` order) as numpy columns: text as object arrays, ``index``
    int, ``ends_at_rest`` bool, the rest float."""
    cols = list(zip(*rows, strict=True)) if rows else [()] * len(names)
    out = {}
    for name, col in zip(names, cols, strict=True):
        if name in TEXT_COLUMNS:
            out[name] = np.array(col, dtype=object)
        elif name == "index":
            out[name] = np.array(col, dtype=int)
        elif name == "ends_at_rest":
            out[name] = np.array(col, dtype=bool)
        else:
            out[name] = np.array(col, dtype=float)
    return out
