"""What the solvers report: event kinds, event records, contact (impact) records, leaves.

``EventKind`` is the one table of event kinds and ``Event`` the one event record of every
solver (rigid, coupled two-way and one-way, stream, and their references): each appends
``Event(t, ball, kind, partner)`` to its ``events``. ``ContactRecord`` and ``LeaveEvent``
are the stream solvers' records (the refactor of issue 7 extends them to every solver).
"""

from dataclasses import asdict, dataclass
from enum import Enum
from typing import NamedTuple

PLATE = "plate"  # the partner name of a ball-plate contact


class EventKind(str, Enum):
    """Kinks and changes a solver stops at. A member equals its value (``EventKind.REST ==
    "rest"``) and prints as it (``str``, f-strings): the value is what the outputs write."""

    CONTACT_START = "contact_start"
    CONTACT_END = "contact_end"
    FULL_DAMPING = "full_damping"  # penetration crosses d (the STEP ramp ends/starts)
    CLAMP_ON = "clamp_on"
    CLAMP_OFF = "clamp_off"
    LEAVE = "leave"  # a ball's centre passed an edge of the plate
    RELEASE = "release"  # a ball entered the scene (a stream particle's release time)
    REST = "rest"  # a ball came to rest on the plate (rigid and coupled solvers' rest rules)

    def __str__(self) -> str:
        return self.value

    def __format__(self, spec: str) -> str:
        return format(self.value, spec)


class Event(NamedTuple):
    """One event of one ball, as every solver records it (``result.events``, time order).

    Parameters
    ----------
    t : float
        Time of the event (s).
    ball : str
        Name of the ball the event belongs to.
    kind : EventKind
        What happened (contact start or end, a kink of the law, leave, release, rest).
    partner : str
        The other body: ``plate`` (``PLATE``) or the other ball's name for the contact
        events and kinks, and for ``rest`` (on the plate); the edge passed (``x+``, ...) for
        ``leave``; ``""`` for ``release``.
    """

    t: float
    ball: str
    kind: EventKind
    partner: str


@dataclass
class ContactRecord:
    """One contact of one ball (a ball-ball contact gives one record per ball).

    partner: ``plate`` or the other ball's name. Times in s. Speeds in m/s along the contact
    normal n (from the partner to the ball): v_in = -v . n at first touch (> 0 approaching),
    v_out = v . n at the end (> 0 leaving); approach_in / approach_out: the same for the
    relative velocity of the pair (penetration rate at start, minus it at the end).
    peak_force (N) at t_peak, max_penetration (m); x, y: contact point in the plate frame
    at first touch (m). end: ``separated``, ``rest`` (the ball came to rest on the plate: the
    fast stream solver's rest rules), ``left`` (a ball left the plate during the contact) or
    ``duration`` (the simulation ended during it; v_out etc. are nan).
    """

    ball: str
    partner: str
    t_start: float
    x: float
    y: float
    v_in: float
    approach_in: float
    t_end: float = float("nan")
    v_out: float = float("nan")
    approach_out: float = float("nan")
    peak_force: float = 0.0
    t_peak: float = float("nan")
    max_penetration: float = 0.0
    end: str = "duration"

    def as_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class LeaveEvent:
    """Ball ``ball`` left the plate over ``edge`` (``x+`` downhill, ...) at ``time`` s."""

    ball: str
    time: float
    edge: str
