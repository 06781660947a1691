"""What a stream simulation returns: particles, contacts, leave events, as columns.

``StreamResult`` is built by every stream solver (the slow reference today, the fast solver
when it lands) from the shared records of ``tailbeam.solvers.records``. Its two tables are
the outputs ``impacts.csv`` and ``particles.csv`` (tailbeam.results_io), column for column.

Not here: ``sample(times)`` (the states on a time grid, which ``timeseries.csv`` of the
single-ball solvers is made of). A stream solver keeps only its records, never every
ball's state at every step (memory must not grow with steps x particles), so stream scenes
write no timeseries.csv.

Columns of ``impacts_table()`` (one row per ball per contact; a ball-ball contact gives one
row for each of the two balls), in this order:

- the twelve columns of the single-ball solvers' impacts.csv (``IMPACT_COLUMNS``):
  ``ball``; ``index`` (1, 2, ... the ball's contacts with the plate and with balls, in time
  order); ``t_start``, ``t_end`` (s; t_end nan if the simulation ended during the contact);
  ``v_in``, ``v_out`` (m/s: the ball's own velocity along the contact normal n, pointing from
  the partner to the ball: v_in = -v.n at first touch, > 0 approaching; v_out = v.n at the
  end, > 0 leaving; for a plate row these are the ball's normal speeds as in the rigid
  solver); ``restitution`` (approach_out / approach_in of the pair, which is v_out / v_in for
  a plate row; nan unless the contact ended by separation or approach_in is 0);
  ``peak_force`` (N) at ``t_peak`` (s); ``max_penetration`` (m, of the pair);
  ``next_apex_height`` (plate rows: the height of the ball's lowest point above the plate at
  the apex of the following normal flight, v_out^2 / (2 g cos theta); nan if the contact did
  not end by separation, if there is no normal gravity, if the ball touches anything or
  leaves the plate before that apex, or for ball rows); ``ends_at_rest`` (true when the
  contact ended with the ball at rest on the plate: ``end`` = ``rest``, see
  ``tailbeam.solvers.stream``; the reference solver never declares rest);
- then ``partner`` (``plate`` or the other ball's name), ``x``, ``y`` (contact point in the
  plate frame at first touch, m), ``material``, ``radius`` (m) of the row's ball;
- then ``label`` (coal / gangue), ``stream`` (empty for ``[[balls]]``), ``end``
  (``separated``; ``rest``: the ball came to rest on the plate and slides on as a dead load;
  ``left``: the ball left the plate during the contact; ``duration``),
  ``approach_in``, ``approach_out`` (m/s, the pair's normal approach speed at first touch
  and its separation speed at the end).
"""

import math
from dataclasses import dataclass, field

import numpy as np

from tailbeam.solvers.records import PLATE

# The single-ball solvers' impacts.csv columns (the contract's first twelve) and units.
IMPACT_COLUMNS = (
    "ball", "index", "t_start", "t_end", "v_in", "v_out", "restitution", "peak_force",
    "t_peak", "max_penetration", "next_apex_height", "ends_at_rest",
)  # fmt: skip
IMPACT_UNITS = {
    "t_start": "s", "t_end": "s", "v_in": "m/s", "v_out": "m/s", "restitution": "1",
    "peak_force": "N", "t_peak": "s", "max_penetration": "m", "next_apex_height": "m",
}  # fmt: skip
STREAM_IMPACT_COLUMNS = IMPACT_COLUMNS + (
    "partner", "x", "y", "material", "radius",
    "label", "stream", "end", "approach_in", "approach_out",
)  # fmt: skip
STREAM_IMPACT_UNITS = {
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


@dataclass
class StreamResult:
    """Result of a stream simulation (see the module docstring).

    particles: ``tailbeam.streams.generator.Particle`` of every body, ``[[balls]]`` included
    (stream "", t_release 0); contacts: ``ContactRecord`` (one per ball per contact);
    leaves: ``LeaveEvent``; events: (t, ball, EventKind, partner) in time order; incline:
    ``tailbeam.physics.incline.InclinedPlate``; duration in s; status 0 = reached the end;
    message; stats: solver statistics (steps, ...); sensors: sensor outputs by name once
    the modal plate carries streams (None until then); info: what was chosen.
    """

    particles: list
    contacts: list
    leaves: list
    events: list
    incline: object
    duration: float
    status: int = 0
    message: str = ""
    stats: dict = field(default_factory=dict)
    sensors: dict | None = None
    info: dict = field(default_factory=dict)
    loads: tuple | None = None  # (contact force histories, dead loads): fast solver only

    @property
    def sensor_signals(self) -> dict:
        """name -> (t s, acceleration m/s^2) of the sensors (modal plate), for sensors.csv."""
        from tailbeam.coupled.load_response import sensor_signals

        return sensor_signals(self.sensors or {})

    @property
    def impacts(self) -> list:
        """The contact records (``len(result.impacts)`` counts impacts.csv rows)."""
        return self.contacts

    def impacts_table(self) -> dict:
        """impacts.csv as columns: name -> numpy array, in ``STREAM_IMPACT_COLUMNS`` order."""
        by_name = {p.name: p for p in self.particles}
        leave = {e.ball: e.time for e in self.leaves}
        starts = _starts_by_ball(self.contacts)
        g_n = self.incline.gravity * math.cos(math.radians(self.incline.inclination))
        count: dict = {}
        rows = []
        for rec in sorted(self.contacts, key=lambda r: (r.t_start, r.ball)):
            count[rec.ball] = count.get(rec.ball, 0) + 1
            p = by_name[rec.ball]
            rows.append(_impact_row(rec, count[rec.ball], p, g_n, starts, leave))
        return _columns(STREAM_IMPACT_COLUMNS, rows)

    def particles_table(self) -> dict:
        """particles.csv as columns: name -> numpy array, in ``PARTICLE_COLUMNS`` order."""
        leave = {e.ball: e for e in self.leaves}
        rows = []
        for p in self.particles:
            e = leave.get(p.name)
            rows.append(
                (p.name, p.stream, p.material.name, p.label, p.radius, p.mass, p.t_release,
                 *p.position, *p.velocity,
                 e.time if e else math.nan, e.edge if e else "")
            )  # fmt: skip
        return _columns(PARTICLE_COLUMNS, rows)


def _starts_by_ball(contacts) -> dict:
    out: dict = {}
    for rec in contacts:
        out.setdefault(rec.ball, []).append(rec.t_start)
    return {k: np.sort(v) for k, v in out.items()}


def _impact_row(rec, index, particle, g_n, starts, leave) -> tuple:
    separated = rec.end in ("separated", "rest")
    restitution = (
        rec.approach_out / rec.approach_in if separated and rec.approach_in > 0.0 else math.nan
    )
    return (
        rec.ball, index, rec.t_start, rec.t_end, rec.v_in, rec.v_out, restitution,
        rec.peak_force, rec.t_peak, rec.max_penetration,
        _next_apex(rec, g_n, starts.get(rec.ball), leave.get(rec.ball)), rec.end == "rest",
        rec.partner, rec.x, rec.y, particle.material.name, particle.radius,
        particle.label, particle.stream, rec.end, rec.approach_in, rec.approach_out,
    )  # fmt: skip


def _next_apex(rec, g_n, starts, t_leave) -> float:
    """v_out^2 / (2 g_n) for a plate contact whose ball then flies freely to its apex."""
    if rec.partner != PLATE or rec.end != "separated" or g_n <= 0.0 or rec.v_out < 0.0:
        return math.nan
    t_apex = rec.t_end + rec.v_out / g_n
    later = starts[starts > rec.t_start]
    if later.size and later[0] <= t_apex:
        return math.nan  # it touched the plate or a ball before the apex
    if t_leave is not None and t_leave <= t_apex:
        return math.nan
    return rec.v_out**2 / (2.0 * g_n)


def _columns(names, rows) -> dict:
    cols = list(zip(*rows, strict=True)) if rows else [()] * len(names)
    out = {}
    for name, col in zip(names, cols, strict=True):
        if name in TEXT_COLUMNS:
            out[name] = np.array(col, dtype=object)
        elif name in ("index",):
            out[name] = np.array(col, dtype=int)
        elif name == "ends_at_rest":
            out[name] = np.array(col, dtype=bool)
        else:
            out[name] = np.array(col, dtype=float)
    return out
