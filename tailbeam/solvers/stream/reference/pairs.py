"""The watched pairs of the stream reference: every ball with the plate and with every other
present ball, each with its law, its region flags and its open contact records.
"""

import math
from dataclasses import dataclass, field

import numpy as np

from tailbeam.physics.contact_law import ImpactLaw
from tailbeam.physics.contacts import PLATE


@dataclass
class Pair:
    """A watched pair: ball ``i`` and ball ``j`` (``j = -1``: the plate).

    Parameters
    ----------
    i, j : int
        Indices into the scene's balls, i < j for two balls; j = -1 for the plate.
    law : ImpactLaw
        The pair's contact law.
    radius_sum : float
        r_i + r_j (m); r_i for the plate.
    in_contact, ramp, clamped : bool
        The region: in contact; penetration below d (the STEP ramp of the damping);
        force clamped at zero.
    records : list of Impact
        The open contact's records (one per ball), empty out of contact.
    peak, t_peak, pen : float
        The open contact's largest force (N), its time (s) and largest penetration (m).
    phi0 : ndarray or None
        Mode shapes (1/sqrt(kg)) kept by a frozen plate contact (modal plate), else None.
    grad0 : ndarray or None
        Their gradients (m, 2) 1/(m sqrt(kg)), kept with them (friction's lever), else None.
    friction : FrictionSettings or None
        The pair's friction (``tailbeam.physics.friction``); None: frictionless.
    share : float
        r_i / (r_i + r_j): where the common contact point lies on the line of centres, as a
        fraction of the centres' distance from ball i (1 for the plate: its surface).
    normal_impulse : float
        The open contact's integral of the normal force (N s).
    tangential_impulse : ndarray
        The open contact's integral of the tangential force on ball i (3,) (N s).
    stuck, held : bool
        Coulomb's law (``FrictionSettings.coulomb``): the slip is stuck at zero, the rolling
        held at zero (``tailbeam.solvers.stream.reference.sticking``).
    slide_dir, roll_dir : ndarray
        Coulomb's law: the direction (3,) a contact slides or rolls in while its slip or
        rolling speed is still zero (it broke loose along it).
    slide_ref, roll_ref : ndarray
        Coulomb's law: the sliding and rolling directions at the current step's start,
        which the events watch the slip and rolling velocity cross.
    """

    i: int
    j: int
    law: ImpactLaw
    radius_sum: float
    in_contact: bool = False
    ramp: bool = True
    clamped: bool = False
    records: list = field(default_factory=list)
    peak: float = 0.0
    t_peak: float = math.nan
    pen: float = 0.0
    phi0: np.ndarray | None = None
    grad0: np.ndarray | None = None
    friction: object = None
    share: float = 1.0
    normal_impulse: float = 0.0
    tangential_impulse: np.ndarray = field(default_factory=lambda: np.zeros(3))
    stuck: bool = False
    held: bool = False
    slide_dir: np.ndarray = field(default_factory=lambda: np.zeros(3))
    roll_dir: np.ndarray = field(default_factory=lambda: np.zeros(3))
    slide_ref: np.ndarray = field(default_factory=lambda: np.zeros(3))
    roll_ref: np.ndarray = field(default_factory=lambda: np.zeros(3))

    @property
    def coulomb(self) -> bool:
        """Whether the pair has Coulomb's law (stick and slip as events)."""
        return self.friction is not None and self.friction.coulomb

    @property
    def kinked(self) -> bool:
        """Whether the law has a STEP kink at delta = d (it does only with damping)."""
        return self.law.damping > 0.0

    def start(self, records, penetration, phi0=None, grad0=None) -> None:
        """Open a contact with its ``records`` (``Impact``, one per ball) at ``penetration``
        (m; 0 if negative), in the ramp region, unclamped; ``phi0``: the mode shapes a
        frozen plate contact keeps."""
        self.in_contact, self.ramp, self.clamped = True, True, False
        self.peak, self.t_peak, self.pen = 0.0, math.nan, max(0.0, penetration)
        self.records, self.phi0, self.grad0 = records, phi0, grad0
        self.normal_impulse, self.tangential_impulse = 0.0, np.zeros(3)
        self.stuck = self.held = False

    def stop(self, slip=math.nan) -> None:
        """Close the contact: its peaks go into its records, which it then lets go. ``slip``:
        the slip speed at the end (m/s; ``write_peaks``)."""
        self.write_peaks(slip)
        self.in_contact, self.records, self.phi0, self.grad0 = False, [], None, None

    def write_peaks(self, slip=math.nan) -> None:
        """Copy the peak force, its time, the largest penetration and the impulses into the
        records; with friction, how the contact ended tangentially: ``sticking`` if the slip
        speed ``slip`` (m/s) is below the stiction velocity (Coulomb's law: if it is stuck),
        else ``sliding``."""
        tangential = float(np.linalg.norm(self.tangential_impulse))
        end = "frictionless"
        if self.coulomb:
            end = "sticking" if self.stuck else "sliding"
        elif self.friction is not None:
            end = "sticking" if slip < self.friction.stiction_velocity else "sliding"
        for rec in self.records:
            rec.peak_force, rec.t_peak, rec.max_penetration = self.peak, self.t_peak, self.pen
            rec.normal_impulse, rec.tangential_impulse = self.normal_impulse, tangential
            rec.tangential_end = end


class PairSet:
    """The watched pairs by key (i, j), in the order they were created.

    Parameters
    ----------
    balls : list of Ball
        The scene's balls (their radii, m).
    table : ContactTable
        The laws of every pair of the scene.
    friction : FrictionModel or None
        The scene's friction (None: frictionless).
    plate_material : str
        The plate's material name (the friction of ball-plate pairs).
    """

    def __init__(self, balls, table, friction=None, plate_material=""):
        self.balls = balls
        self.table = table
        self.friction = friction
        self.plate_material = plate_material
        self.pairs = {}

    def __getitem__(self, key) -> Pair:
        return self.pairs[key]

    def items(self):
        return self.pairs.items()

    def values(self):
        return self.pairs.values()

    def in_contact(self) -> list:
        """The pairs in contact, in creation order."""
        return [p for p in self.pairs.values() if p.in_contact]

    def add_ball(self, i: int, present) -> list:
        """Create the pairs of ball i with the plate and with every other ball of ``present``
        (indices) that has none yet; returns the pairs of ball i with those."""
        a, made = self.balls[i], []
        law = self.table.law(i, PLATE)
        plate = Pair(i, -1, law, a.radius, friction=self._friction(a, self.plate_material))
        made.append(self.pairs.setdefault((i, -1), plate))
        for j in present:
            if j != i:
                lo, hi = min(i, j), max(i, j)
                b, c = self.balls[lo], self.balls[hi]
                rsum = b.radius + c.radius
                pair = Pair(
                    lo,
                    hi,
                    self.table.law(lo, hi),
                    rsum,
                    friction=self._friction(b, c.material.name),
                    share=b.radius / rsum,
                )
                made.append(self.pairs.setdefault((lo, hi), pair))  # fmt: skip
        return made

    def _friction(self, ball, other: str):
        """The friction of ``ball`` against material ``other`` (None: frictionless)."""
        if self.friction is None:
            return None
        return self.friction.between(ball.material.name, other)

    def drop_ball(self, ball: int) -> list:
        """Remove and return the pairs of ``ball``, in creation order."""
        return [self.pairs.pop(key) for key in [key for key in self.pairs if ball in key]]


@dataclass
class Laws:
    """ImpactLaw parameters as arrays over pairs (duck-types ImpactLaw for the law helpers):
    stiffness (N/m^e), exponent, damping (N s/m) and penetration d (m)."""

    stiffness: np.ndarray
    exponent: np.ndarray
    damping: np.ndarray
    penetration: np.ndarray


def law_table(pairs) -> Laws:
    """The laws of ``pairs`` (a list of ``Pair``) as arrays."""
    return Laws(*(np.array([getattr(p.law, a) for p in pairs], dtype=float)
                  for a in ("stiffness", "exponent", "damping", "penetration")))  # fmt: skip
