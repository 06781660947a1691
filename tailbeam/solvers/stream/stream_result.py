"""What a stream simulation returns: particles, contacts, leave events, as columns.

``StreamResult`` is built by every stream solver (the slow reference today, the fast solver
when it lands) from the shared records of ``tailbeam.results.records``. Its two tables are
the outputs ``impacts.csv`` and ``particles.csv`` (tailbeam.io.results_io), column for column.

A ``tailbeam.results.result.Result``: the columns of ``impacts_table()`` and ``particles_table()``
are documented there (``IMPACT_TABLE_COLUMNS``, ``PARTICLE_COLUMNS``); this module fills the
twelve historical ones from the stream records (``tailbeam.results.records.Impact``, the
record of every solver), of which it numbers ``index`` and sets ``next_apex_height`` when
built (``number_contacts``: both need the whole run):
``restitution`` is approach_out / approach_in of the pair (v_out / v_in for a plate row),
nan unless the contact ended by separation (or rest) and approach_in > 0;
``next_apex_height`` (plate rows): v_out^2 / (2 g cos theta), nan if the contact did not end
by separation, if there is no normal gravity, if the ball touches anything or leaves the
plate before that apex, or for ball rows; ``ends_at_rest``: ``end`` = ``rest``; ``t_end``
nan if the simulation ended during the contact.

Not here: ``sample(times)`` (the states on a time grid, which ``timeseries.csv`` of the
single-ball solvers is made of). A stream solver keeps only its records, never every
ball's state at every step (memory must not grow with steps x particles), so stream scenes
write no timeseries.csv.
"""

import math
from dataclasses import dataclass, field

import numpy as np

from tailbeam.results.records import PLATE
from tailbeam.results.result import (  # noqa: F401 - the column names, as imported before
    IMPACT_COLUMNS,
    IMPACT_TABLE_COLUMNS,
    IMPACT_TABLE_UNITS,
    IMPACT_UNITS,
    PARTICLE_COLUMNS,
    PARTICLE_UNITS,
    TEXT_COLUMNS,
    Result,
)

# The stream columns were named so before every scene wrote them (kept for importers).
STREAM_IMPACT_COLUMNS = IMPACT_TABLE_COLUMNS
STREAM_IMPACT_UNITS = IMPACT_TABLE_UNITS


@dataclass
class StreamResult(Result):
    """Result of a stream simulation (see the module docstring).

    particles: ``tailbeam.streams.generator.Particle`` of every body, ``[[balls]]`` included
    (stream "", t_release 0); contacts: ``Impact`` records (one per ball per contact);
    leaves: ``LeaveEvent``; events: ``tailbeam.results.records.Event`` in time order; incline:
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
    def plate_model(self) -> str:
        """``modal`` once the modal plate's sensors were computed (tailbeam.simulation),
        else ``rigid``."""
        return "rigid" if self.sensors is None else "modal"

    @property
    def sensor_outputs(self) -> dict:
        """name -> ``tailbeam.signals.sensor.SensorOutput`` of the sensors (modal plate; else
        empty)."""
        return self.sensors or {}

    @property
    def impacts(self) -> list:
        """The contact records (``len(result.impacts)`` counts impacts.csv rows)."""
        return self.contacts

    def particle_records(self) -> list:
        return list(self.particles)

    def __post_init__(self):
        number_contacts(self.contacts, self.leaves, self.incline)

    def _impact_rows(self):
        return sorted(self.contacts, key=lambda r: (r.t_start, r.ball))


def number_contacts(contacts, leaves, incline) -> None:
    """Fill ``index`` (1, 2, ... per ball in time order) and ``next_apex_height`` of a stream
    solver's ``Impact`` records (``contacts``), which need the whole run: the ball's later
    contacts and its ``LeaveEvent`` (``leaves``) on ``incline``. Idempotent."""
    leave = {e.ball: e.time for e in leaves}
    starts = _starts_by_ball(contacts)
    g_n = incline.gravity * math.cos(math.radians(incline.inclination))
    count: dict = {}
    for rec in sorted(contacts, key=lambda r: (r.t_start, r.ball)):
        count[rec.ball] = count.get(rec.ball, 0) + 1
        rec.index = count[rec.ball]
        rec.next_apex_height = _next_apex(rec, g_n, starts.get(rec.ball), leave.get(rec.ball))


def _starts_by_ball(contacts) -> dict:
    out: dict = {}
    for rec in contacts:
        out.setdefault(rec.ball, []).append(rec.t_start)
    return {k: np.sort(v) for k, v in out.items()}


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
