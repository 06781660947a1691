"""What the solvers report: event kinds and codes, event records, contact records, leaves.

``EventKind`` names the events every solver records and ``EventCode`` numbers them, one code
per kind: the compiled kernels write codes, the solvers turn them into kinds with
``EventCode(code).kind``. ``Event`` is the one event record of every solver (rigid, coupled,
stream and their references): each appends ``Event(t, ball, kind, partner)`` to its
``events``. ``Impact`` is the one contact record of every solver; ``End`` says how a contact
ended. ``LeaveEvent`` records a ball leaving the plate.
"""

import math
from dataclasses import dataclass, fields
from enum import Enum, IntEnum
from typing import NamedTuple

from tailbeam.physics.contacts import PLATE  # the partner name of a ball-plate contact


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
    STICK = "stick"  # Coulomb's law: a contact's slip stopped and is held
    SLIP = "slip"  # Coulomb's law: a stuck contact broke loose (its force reached mu_s F_n)
    ROLL_HOLD = "roll_hold"  # Coulomb's law: a contact's rolling stopped and is held
    ROLL_FREE = "roll_free"  # Coulomb's law: held rolling broke loose (mu_r R F_n reached)

    def __str__(self) -> str:
        return self.value

    def __format__(self, spec: str) -> str:
        return format(self.value, spec)

    @property
    def code(self) -> "EventCode":
        """The integer code of this kind (``EventCode``)."""
        return EventCode[self.name]


class EventCode(IntEnum):
    """The integer code of each ``EventKind``, as the compiled kernels write and compare them
    (numba takes the members as constants); ``NONE`` (-1) is "no event"."""

    NONE = -1
    CONTACT_START = 0
    CONTACT_END = 1
    FULL_DAMPING = 2
    CLAMP_ON = 3
    CLAMP_OFF = 4
    LEAVE = 5
    RELEASE = 6
    REST = 7
    STICK = 8
    SLIP = 9
    ROLL_HOLD = 10
    ROLL_FREE = 11

    @property
    def kind(self) -> EventKind:
        """The ``EventKind`` of this code (KeyError for ``NONE``)."""
        return EventKind[self.name]


class End(str, Enum):
    """How a contact ended (``Impact.end``; the ``end`` column of impacts.csv). A member
    equals its value and prints as it, as ``EventKind``."""

    SEPARATED = "separated"  # the bodies parted
    REST = "rest"  # the ball came to rest on the plate (the solver's rest rules)
    LEFT = "left"  # the ball left the plate during the contact
    DURATION = "duration"  # the simulation ended during the contact

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


@dataclass(kw_only=True)
class Impact:
    """One contact of one ball, as every solver records it (``result.impacts``).

    Created by every solver and reference (rigid, coupled two-way and one-way, stream, FE
    reference) with keyword arguments only; a ball-ball contact gives one record per ball.
    The stream solvers create it at first touch and fill the end later: the defaults are
    those of a contact still in progress.

    Parameters
    ----------
    ball : str
        Name of the ball the record belongs to.
    t_start : float
        Time of first touch (s).
    x, y : float
        Contact point in the plate frame at first touch (m); for a single-ball solver the
        ball centre's lateral position then (its lateral motion is uniform).
    v_in : float
        The ball's speed along the contact normal n (from the partner to the ball) at
        first touch, v_in = -v . n (m/s, > 0 approaching).
    partner : str
        ``plate`` (``PLATE``) or the other ball's name.
    index : int
        The ball's contacts counted 1, 2, ... in time order, with the plate and with balls
        (0 until the stream result numbers them, ``number_contacts``).
    approach_in : float
        The pair's normal approach speed at first touch (m/s, the penetration rate); for a
        plate contact the ball's own v_in (the plate's motion not subtracted).
    t_end : float
        Time the contact ended (s); nan while in progress, and in the stream solvers if
        the simulation ended during it.
    v_out : float
        The ball's speed along n at the end, v_out = v . n (m/s, > 0 leaving); 0.0 if a
        single-ball solver declared the ball at rest in contact, nan if the simulation
        ended during the contact.
    approach_out : float
        The pair's separation speed at the end (m/s); for a plate contact the ball's v_out.
    peak_force : float
        Largest contact force (N), at ``t_peak`` (s).
    t_peak : float
        Time of the peak force (s).
    max_penetration : float
        Largest penetration of the pair (m).
    next_apex_height : float
        Height (m) of the ball's lowest point above the plate at the apex of the flight
        that follows (nan if there is none, if the ball touches anything or leaves the
        plate first, for ball-ball rows, and in the FE reference, which does not fly on).
    end : End
        How the contact ended: ``separated``, ``rest`` (the ball came to rest on the plate:
        the solver's rest rules), ``left`` (the ball left the plate during the contact) or
        ``duration`` (the simulation ended during it); equal to these strings.
    normal_impulse : float
        Integral of the pair's normal contact force over the contact (N s); nan where the
        solver does not integrate it (the single-ball and the fast stream solvers).
    tangential_impulse : float
        Magnitude of the integral of the tangential (friction) force on the row's ball over
        the contact (N s); 0 for a frictionless contact.
    tangential_end : str
        How the contact ended tangentially: ``sliding`` (slip speed at least the stiction
        velocity), ``sticking`` (below it) or ``frictionless``.
    """

    ball: str
    t_start: float
    x: float
    y: float
    v_in: float
    partner: str = PLATE
    index: int = 0
    approach_in: float = float("nan")
    t_end: float = float("nan")
    v_out: float = float("nan")
    approach_out: float = float("nan")
    peak_force: float = 0.0
    t_peak: float = float("nan")
    max_penetration: float = 0.0
    next_apex_height: float = float("nan")
    end: End = End.DURATION
    normal_impulse: float = float("nan")
    tangential_impulse: float = 0.0
    tangential_end: str = "frictionless"

    @property
    def restitution(self) -> float:
        """Coefficient of restitution (dimensionless): approach_out / approach_in (v_out / v_in
        for a plate contact), nan unless the contact ended by separation or rest and
        approach_in > 0 (single-ball solvers: 0.0 for a ball declared at rest in contact,
        where v_out = 0)."""
        if self.end in (End.SEPARATED, End.REST) and self.approach_in > 0.0:
            return self.approach_out / self.approach_in
        return math.nan

    @property
    def ends_at_rest(self) -> bool:
        """True if the ball came to rest on the plate during this contact (end ``rest``)."""
        return self.end == End.REST

    @property
    def duration(self) -> float:
        """t_end - t_start (s)."""
        return self.t_end - self.t_start

    @classmethod
    def single_ball(cls, ball, *, t_start, v_in, v_out, at_rest, **other) -> "Impact":
        """A single-ball solver's contact with the plate (rigid, coupled, FE reference).

        Parameters
        ----------
        ball : Ball or Pair
            The ball: ``name``, initial ``position`` (m) and ``velocity`` (m/s); its lateral
            motion is uniform, so x, y = position[:2] + velocity[:2] t_start.
        t_start, v_in, v_out : float
            As the fields (s, m/s, m/s); the approach speeds are the ball's (v_in, v_out).
        at_rest : bool
            The ball was declared at rest in this contact (``end`` = ``rest``); otherwise
            ``end`` is ``duration`` if v_out is nan (the run ended during it), else
            ``separated``.
        **other
            The remaining fields (index, t_end, peak_force, t_peak, max_penetration,
            next_apex_height).
        """
        x = ball.position[0] + ball.velocity[0] * t_start
        y = ball.position[1] + ball.velocity[1] * t_start
        end = End.REST if at_rest else (End.DURATION if math.isnan(v_out) else End.SEPARATED)
        return cls(ball=ball.name, partner=PLATE, t_start=t_start, x=x, y=y, v_in=v_in,
                   approach_in=v_in, v_out=v_out, approach_out=v_out, end=end, **other)  # fmt: skip

    def as_dict(self) -> dict:
        """Every field, then ``restitution`` and ``ends_at_rest``."""
        out = {f.name: getattr(self, f.name) for f in fields(self)}
        out["restitution"] = self.restitution
        out["ends_at_rest"] = self.ends_at_rest
        return out


@dataclass(frozen=True)
class LeaveEvent:
    """Ball ``ball`` left the plate over ``edge`` (``x+`` downhill, ...) at ``time`` s."""

    ball: str
    time: float
    edge: str
