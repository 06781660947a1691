"""The contacts of a scene as one table of pairs: rows (body, body, law).

A body is a ball, named by its index in the table's body order or by its name, or the plate
(``PLATE``). The table holds one ball-plate row per ball (Hertz stiffness of the ball on the
flat plate, paper eqs. 4-6) and creates a ball-ball row (eq. 5: R = R1 R2 / (R1 + R2), E*
from both materials) the first time that pair is asked for, then keeps it: a stream of N
balls never materialises its N (N - 1) / 2 pairs, only those that come close. Every solver
asks the table (the rigid and coupled solvers for plate rows, the stream solver and its slow
reference for both kinds), so each pair's law is built in one place.

A row's law is one object per pair (today an ``ImpactLaw``: normal force only). The table
never looks inside it, so Coulomb friction or rotation can later enter as fields of a richer
per-pair law without changing the table or its callers' lookups.
"""

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from tailbeam.errors import InputError
from tailbeam.physics.contact_law import ImpactLaw, ball_ball_law, ball_plate_law

PLATE = "plate"  # the plate as a body of a pair, and the partner name of a ball-plate contact


@dataclass(frozen=True)
class LawOptions:
    """IMPACT parameters shared by every pair: exponent e, damping c (N s/m) reached at
    penetration d (m), clamp (Adams' max(0, .)); the stiffness comes from Hertz per pair."""

    exponent: float
    damping: float
    penetration: float
    clamp: bool

    @classmethod
    def of(cls, settings) -> "LawOptions":
        """The four parameters of any object that has them (``tailbeam.scene.ContactSettings``)."""
        return cls(settings.exponent, settings.damping, settings.penetration, settings.clamp)

    def kwargs(self) -> dict:
        """The parameters as keyword arguments of ``ball_plate_law`` / ``ball_ball_law``."""
        return {
            "exponent": self.exponent,
            "damping": self.damping,
            "penetration": self.penetration,
            "clamp": self.clamp,
        }


class ContactRow(NamedTuple):
    """One contact pair: two bodies (ball names, or ``PLATE`` as the second) and its law."""

    body: str
    other: str
    law: ImpactLaw


class PlateLawArrays(NamedTuple):
    """The ball-plate laws as per-ball arrays (body order) for the compiled kernels:
    stiffness k (N/m^e), exponent e, damping c (N s/m), penetration d (m), clamp (bool)."""

    stiffness: np.ndarray
    exponent: np.ndarray
    damping: np.ndarray
    penetration: np.ndarray
    clamp: np.ndarray


class ContactTable:
    """The contact pairs of a set of bodies; see the module docstring.

    Parameters
    ----------
    bodies : sequence
        The balls (anything with ``name``, ``material`` and ``radius`` in m: ``Ball``,
        stream ``Particle``), in the order their indices refer to.
    plate_laws : sequence of ImpactLaw
        The ball-plate law of each body, in body order.
    options : LawOptions, optional
        The IMPACT parameters of the ball-ball rows; None: the table answers plate rows only
        (built from a user's list of laws, ``from_laws``).
    """

    def __init__(self, bodies, plate_laws, options: LawOptions | None = None):
        self.bodies = tuple(bodies)
        self.names = tuple(b.name for b in self.bodies)
        self._index = {name: i for i, name in enumerate(self.names)}
        self._plate = tuple(plate_laws)
        if len(self._plate) != len(self.bodies):
            raise InputError(
                "laws", f"need one ball-plate law per ball: {len(self.bodies)} balls, "
                f"{len(self._plate)} laws"
            )  # fmt: skip
        self.options = options
        self._pairs = {}  # (i, j), i < j -> the ball-ball law, created when first asked for

    @classmethod
    def from_settings(cls, bodies, plate_material, settings) -> "ContactTable":
        """The table of ``bodies`` on a plate of ``plate_material`` with the shared IMPACT
        ``settings`` (``ContactSettings`` or ``LawOptions``): Hertz stiffness per pair."""
        options = LawOptions.of(settings)
        kw = options.kwargs()
        plate = [ball_plate_law(b.material, b.radius, plate_material, **kw) for b in bodies]
        return cls(bodies, plate, options)

    @classmethod
    def from_laws(cls, balls, laws) -> "ContactTable":
        """The table of a user's list of ball-plate ``laws`` (one ``ImpactLaw`` per ball, the
        solvers' ``laws`` argument); it has no ball-ball rows."""
        try:
            laws = tuple(laws)
        except TypeError:
            raise InputError("laws", "must be a sequence of ImpactLaw, one per ball") from None
        if len(laws) != len(balls):
            raise InputError(
                "laws", f"need one ImpactLaw per ball: {len(balls)} balls, {len(laws)}"
            )
        for i, law in enumerate(laws):
            if not isinstance(law, ImpactLaw):
                raise InputError(f"laws[{i}]", "must be an ImpactLaw")
        return cls(balls, laws)

    # --- lookups ---------------------------------------------------------------------------
    def index(self, body) -> int:
        """The index (body order) of a ball given by index or name."""
        if isinstance(body, (int, np.integer)) and not isinstance(body, bool):
            if 0 <= body < len(self.bodies):
                return int(body)
        elif body in self._index:
            return self._index[body]
        raise InputError("contacts", f"no ball {body!r} in this contact table")

    def law(self, body, other):
        """The law of the pair (``body``, ``other``): each a ball (index or name) or
        ``PLATE``; symmetric, law(a, b) is law(b, a). Ball-ball rows are created here on
        first use and cached."""
        if isinstance(body, str) and body == PLATE:
            body, other = other, body
        i = self.index(body)
        if isinstance(other, str) and other == PLATE:
            return self._plate[i]
        j = self.index(other)
        if i == j:
            raise InputError("contacts", f"ball {self.names[i]!r} cannot touch itself")
        key = (i, j) if i < j else (j, i)
        law = self._pairs.get(key)
        if law is None:
            law = self._pairs[key] = self._pair_law(*key)
        return law

    def _pair_law(self, i: int, j: int) -> ImpactLaw:
        """Eq. 5 for balls i < j: R = R1 R2 / (R1 + R2), E* of both materials."""
        if self.options is None:
            raise InputError(
                "laws", "a list of ball-plate laws has no ball-ball contact; build the table "
                "from contact settings (ContactTable.from_settings, Scene.contacts())"
            )  # fmt: skip
        a, b = self.bodies[i], self.bodies[j]
        return ball_ball_law(a.material, a.radius, b.material, b.radius, **self.options.kwargs())

    # --- views -----------------------------------------------------------------------------
    def plate_laws(self) -> tuple:
        """The ball-plate law of every ball, in body order (``Scene.laws()``)."""
        return self._plate

    def plate_arrays(self) -> PlateLawArrays:
        """The ball-plate laws as per-ball arrays, in body order (for the compiled kernels)."""
        laws = self._plate
        return PlateLawArrays(
            np.array([lw.stiffness for lw in laws]),
            np.array([lw.exponent for lw in laws]),
            np.array([lw.damping for lw in laws]),
            np.array([lw.penetration for lw in laws]),
            np.array([lw.clamp for lw in laws], dtype=np.bool_),
        )

    def rows(self):
        """The rows held, as ``ContactRow`` (body, other, law): every ball's plate row, then
        the ball-ball rows asked for so far (lower index first)."""
        for name, law in zip(self.names, self._plate, strict=True):
            yield ContactRow(name, PLATE, law)
        for (i, j), law in self._pairs.items():
            yield ContactRow(self.names[i], self.names[j], law)

    def __len__(self) -> int:
        """Number of rows held (plate rows plus the ball-ball rows created so far)."""
        return len(self._plate) + len(self._pairs)

    def check_covers(self, bodies) -> None:
        """InputError (naming ``laws``) unless the table was built for ``bodies``: the same
        names, radii and materials in the same order."""
        bodies = tuple(bodies)
        same = len(bodies) == len(self.bodies) and all(
            (a.name, a.radius, a.material) == (b.name, b.radius, b.material)
            for a, b in zip(bodies, self.bodies, strict=True)
        )
        if not same:
            raise InputError("laws", "the contact table was built for other balls")


def contact_table(bodies, laws, plate_material=None) -> ContactTable:
    """What a solver's ``laws`` argument means, as a table over ``bodies``: a
    ``ContactTable`` (checked to cover them), a sequence of ball-plate ``ImpactLaw`` (one per
    body, ``from_laws``) or shared IMPACT settings (``ContactSettings``, ``LawOptions``) with
    the ``plate_material``."""
    bodies = tuple(bodies)
    if isinstance(laws, ContactTable):
        laws.check_covers(bodies)
        return laws
    if isinstance(laws, (LawOptions,)) or _is_settings(laws):
        if plate_material is None:
            raise InputError("laws", "contact settings need the plate's material")
        return ContactTable.from_settings(bodies, plate_material, laws)
    return ContactTable.from_laws(bodies, laws)


def _is_settings(laws) -> bool:
    """Shared IMPACT settings (not one law, not a sequence of laws)."""
    names = ("exponent", "damping", "penetration", "clamp")
    return not isinstance(laws, ImpactLaw) and all(hasattr(laws, n) for n in names)
