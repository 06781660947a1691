"""The one result type of ``tailbeam.simulate``: ``Result``, whichever solver ran.

In the spirit of scipy's ``OdeResult`` and diffrax's ``Solution``: one interface, its fields
filled by the solver that ran. ``Result`` implements everything common once; the solvers'
results are thin subclasses that add only what is theirs:

- ``tailbeam.solvers.rigid.RigidResult`` (rigid plate, balls that cannot touch) and
  ``tailbeam.solvers.coupled.CoupledResult`` (modal plate; adds the modal replay ``modal_sample``,
  ``plate_sample``, the sensors), both through ``BallsResult`` (the single-ball solvers:
  ``sample(times)`` exact at any times, ``rest_time``);
- ``tailbeam.solvers.stream.stream_result.StreamResult`` (streams, an inclined plate, balls that
  may touch; keeps its records only, so no ``sample``).

Common interface (every result):

- ``status`` (0: reached the end), ``message``, ``stats`` (dict: the solver's work counts),
  ``info`` (dict: what was chosen automatically), ``duration`` (s), ``plate_model``;
- ``impacts`` (the solver's contact records, ``tailbeam.results.records.Impact``, the one
  record of every solver; ``len`` counts impacts.csv rows),
  ``impacts_table()`` (impacts.csv as numpy columns, ``IMPACT_TABLE_COLUMNS``),
  ``particles_table()`` (particles.csv, ``PARTICLE_COLUMNS``: one row per ball, streams
  and ``[[balls]]`` alike), ``impacts_of(name)``, ``events_of(name, kind)``, ``leaves``;
- ``sample(times)`` (ball states; single-ball solvers only), ``time_grid(rate)``;
- ``sensor_outputs`` (name -> ``tailbeam.signals.sensor.SensorOutput``; empty on the rigid plate),
  ``sensor_signals`` (name -> (t s, acceleration m/s^2)).

Columns of ``impacts_table()`` (one row per ball per contact; a ball-ball contact gives one
row for each of the two balls), in this order:

- the twelve historical columns (``IMPACT_COLUMNS``, the contract's first twelve):
  ``ball``; ``index`` (1, 2, ... the ball's contacts with the plate and with balls, in time
  order); ``t_start``, ``t_end`` (s); ``v_in``, ``v_out`` (m/s: the ball's own velocity along
  the contact normal n, pointing from the partner to the ball: v_in = -v.n at first touch,
  > 0 approaching; v_out = v.n at the end, > 0 leaving; for a plate row the ball's normal
  speeds); ``restitution``; ``peak_force`` (N) at ``t_peak`` (s); ``max_penetration`` (m,
  of the pair); ``next_apex_height`` (m); ``ends_at_rest``. The single-ball solvers write
  these exactly as before (docs/scene-files.md gives each solver's conventions);
- then ``partner`` (``plate`` or the other ball's name), ``x``, ``y`` (contact point in the
  plate frame at first touch, m: for a plate contact the ball centre's x, y then),
  ``material``, ``radius`` (m) of the row's ball;
- then ``label`` (coal / gangue), ``stream`` (empty for ``[[balls]]``), ``end``
  (``separated``; ``rest``: the ball came to rest on the plate; ``left``: the ball left the
  plate during the contact; ``duration``: the simulation ended during it),
  ``approach_in``, ``approach_out`` (m/s, the pair's normal approach speed at first touch
  and its separation speed at the end; for a plate contact the ball's own normal speeds,
  the plate's motion not subtracted, as the stream solver records them on either plate).
"""

import math

import numpy as np

from tailbeam.errors import InputError, require_positive
from tailbeam.results.records import LeaveEvent

# The single-ball solvers' impacts.csv columns (the contract's first twelve) and units.
IMPACT_COLUMNS = (
    "ball", "index", "t_start", "t_end", "v_in", "v_out", "restitution", "peak_force",
    "t_peak", "max_penetration", "next_apex_height", "ends_at_rest",
)  # fmt: skip
IMPACT_UNITS = {
    "t_start": "s", "t_end": "s", "v_in": "m/s", "v_out": "m/s", "restitution": "1",
    "peak_force": "N", "t_peak": "s", "max_penetration": "m", "next_apex_height": "m",
}  # fmt: skip
# impacts.csv of every scene: the twelve, then the contact and its ball.
IMPACT_TABLE_COLUMNS = IMPACT_COLUMNS + (
    "partner", "x", "y", "material", "radius",
    "label", "stream", "end", "approach_in", "approach_out",
)  # fmt: skip
IMPACT_TABLE_UNITS = {
    **IMPACT_UNITS, "x": "m", "y": "m", "radius": "m", "approach_in": "m/s", "approach_out": "m/s",
}  # fmt: skip
PARTICLE_COLUMNS = (
    "name", "stream", "material", "label", "radius", "mass", "t_release",
    "x0", "y0", "z0", "vx0", "vy0", "vz0", "t_leave", "leave_edge",
)  # fmt: skip
PARTICLE_UNITS = {
    "radius": "m", "mass": "kg", "t_release": "s", "x0": "m", "y0": "m", "z0": "m",
    "vx0": "m/s", "vy0": "m/s", "vz0": "m/s", "t_leave": "s",
}  # fmt: skip
TEXT_COLUMNS = {"ball", "partner", "material", "label", "stream", "end", "name", "leave_edge"}


class Result:
    """What ``tailbeam.simulate`` returns, whichever solver ran (see the module docstring).

    A subclass provides ``duration`` (s), ``status``, ``message``, ``info``, ``impacts``,
    ``events`` (``tailbeam.results.records.Event`` records in time order), ``leaves`` and the
    two hooks ``particle_records()`` (every body as a ``tailbeam.streams.generator.Particle``)
    and ``_impact_rows()`` (the ``tailbeam.results.records.Impact`` of every impacts.csv row,
    in row order).
    """

    plate_model = "rigid"  # "rigid" or "modal": the plate the solver ran
    keeps_states = False  # True: sample(times) gives the balls' states (timeseries.csv)

    def particle_records(self) -> list:
        raise NotImplementedError

    def _impact_rows(self):
        raise NotImplementedError

    def impacts_table(self) -> dict:
        """impacts.csv as columns: name -> numpy array, in ``IMPACT_TABLE_COLUMNS`` order."""
        by_name = {p.name: p for p in self.particle_records()}
        rows = []
        for rec in self._impact_rows():
            p = by_name[rec.ball]
            rows.append(
                (*(getattr(rec, c) for c in IMPACT_COLUMNS), rec.partner, rec.x, rec.y,
                 p.material.name, p.radius, p.label, p.stream, rec.end, rec.approach_in,
                 rec.approach_out)
            )  # fmt: skip
        return columns(IMPACT_TABLE_COLUMNS, rows)

    def particles_table(self) -> dict:
        """particles.csv as columns: name -> numpy array, in ``PARTICLE_COLUMNS`` order: the
        release state of every body (plate frame), its leave time (s, nan if it never left)
        and edge (empty if it never left)."""
        leave = {e.ball: e for e in self.leaves}
        rows = []
        for p in self.particle_records():
            e = leave.get(p.name)
            rows.append(
                (p.name, p.stream, p.material.name, p.label, p.radius, p.mass, p.t_release,
                 *p.position, *p.velocity,
                 e.time if e else math.nan, e.edge if e else "")
            )  # fmt: skip
        return columns(PARTICLE_COLUMNS, rows)

    def impacts_of(self, name: str) -> list:
        """The contact records (``impacts``) of the ball called ``name``, in time order."""
        names = [p.name for p in self.particle_records()]
        if name not in names:
            raise InputError("name", f"no ball called {name!r}; balls: {names[:10]}")
        return [imp for imp in self.impacts if imp.ball == name]

    def events_of(self, name: str, kind: str | None = None) -> list:
        """(t s, kind) of the ball's events in time order, optionally only those of ``kind``
        (``contact_start``, ``contact_end``, ``rest``, ...: the ``EventKind`` of
        tailbeam.results.records, which equals its value string)."""
        kind = None if kind is None else str(getattr(kind, "value", kind))
        return [(e.t, e.kind) for e in self.events if e.ball == name and kind in (None, e.kind)]

    def sample(self, times) -> dict:
        """Ball states at ``times``: only the single-ball solvers keep them (BallsResult)."""
        raise InputError(
            "times",
            "this result keeps contact records, not states (a stream solver's result has no "
            "sample; impacts_table() and particles_table() hold what it recorded)",
        )

    def time_grid(self, sample_rate: float) -> np.ndarray:
        """Uniform times k / ``sample_rate`` (Hz) on [0, duration] s merged with every
        finite t_peak of ``impacts`` inside it."""
        rate = require_positive("sample_rate", sample_rate)
        n = int(math.floor(self.duration * rate * (1.0 + 1e-12))) + 1
        grid = np.arange(n, dtype=float) / rate
        peaks = [imp.t_peak for imp in self.impacts if 0.0 <= imp.t_peak <= self.duration]
        return np.unique(np.concatenate([grid[grid <= self.duration], np.asarray(peaks)]))

    @property
    def sensor_outputs(self) -> dict:
        """name -> ``tailbeam.signals.sensor.SensorOutput`` of every sensor (none on a rigid
        plate)."""
        return {}

    @property
    def sensor_signals(self) -> dict:
        """name -> (t array s, acceleration array m/s^2) as sampled by each sensor."""
        return {name: (out.t, out.acceleration) for name, out in self.sensor_outputs.items()}


class BallsResult(Result):
    """The single-ball solvers' common part (rigid and modal plate): ``impacts`` are ``Impact``
    records (partner ``plate``, in time order), ``events`` ``Event`` records (partner ``plate``),
    the balls move laterally at their constant initial velocity. A subclass provides ``balls``,
    ``labels`` (one per ball; empty: ``tailbeam.scene.default_label``), ``_plate()`` (the
    ``tailbeam.physics.bodies.Plate``, or None when unknown) and ``nfev``, ``n_steps``."""

    keeps_states = True

    @property
    def stats(self) -> dict:
        """The solver's work: ``nfev`` (contact-law evaluations), ``n_steps``."""
        return {"nfev": self.nfev, "n_steps": self.n_steps}

    def particle_records(self) -> list:
        from tailbeam.scene import default_label
        from tailbeam.streams.generator import Particle

        labels = tuple(self.labels) or tuple(default_label(b) for b in self.balls)
        return [
            Particle(b.name, "", label, b.material, b.radius, b.mass, 0.0, b.position, b.velocity)
            for b, label in zip(self.balls, labels, strict=True)
        ]

    @property
    def leaves(self) -> list:
        """``LeaveEvent`` of every ball whose centre passes an edge of the plate before the
        end (closed form: the lateral motion is uniform); empty if the plate is unknown."""
        plate = self._plate()
        if plate is None:
            return []
        out = [_leave(b, plate, self.duration) for b in self.balls]
        return sorted((e for e in out if e is not None), key=lambda e: e.time)

    def _impact_rows(self):
        return self.impacts

    def _times(self, times, slack: float = 0.0) -> np.ndarray:
        """``times`` (s) as a 1-D float array, checked finite and within [0, duration]
        (``slack``: relative allowance beyond the end for rounding)."""
        t = np.atleast_1d(np.asarray(times, dtype=float))
        if t.ndim != 1 or not np.all(np.isfinite(t)):
            raise InputError("times", "must be a 1-D array of finite times in s")
        if t.size and (t.min() < 0.0 or t.max() > self.duration * (1.0 + slack)):
            raise InputError("times", f"must lie within [0, duration = {self.duration!r}] s")
        return t


def _leave(ball, plate, duration):
    """When and where the centre of ``ball`` (uniform lateral motion from its start) passes
    an edge of ``plate`` (edges as tailbeam.physics.incline.EDGES), or None by ``duration``."""
    (x, y, _z), (vx, vy, _vz) = ball.position, ball.velocity
    ha, hb = 0.5 * plate.size_x, 0.5 * plate.size_y
    best = None
    for edge, dist, rate in (
        ("x-", x + ha, vx), ("x+", ha - x, -vx), ("y-", y + hb, vy), ("y+", hb - y, -vy)
    ):  # fmt: skip
        if rate < 0.0:
            t = dist / -rate
            if t <= duration and (best is None or t < best.time):
                best = LeaveEvent(ball.name, t, edge)
    return best


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
