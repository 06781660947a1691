"""The MSC Adams IMPACT contact force, with Hertz stiffness (paper eqs. 1, 4-6).

In terms of the penetration delta >= 0 (overlap of the two surfaces, m) and its rate
delta_dot (m/s, > 0 while approaching), Adams evaluates

    F = max(0, k delta^e + STEP(delta, 0, 0, d, c) * delta_dot)        for delta > 0
    F = 0                                                               for delta <= 0

k in N/m^e, c in N s/m, d in m. The max(0, .) clamp is Adams' behaviour; the paper's eq. 1
leaves it out (``clamp=False`` reproduces eq. 1 literally, with its adhesive pull at the end of
rebound). ``impact_force_scalar`` and ``step_scalar`` are written so numba can compile them.
"""

import math
from dataclasses import dataclass

import numpy as np

from tailbeam.errors import InputError, require_nonnegative, require_positive
from tailbeam.materials import Material, effective_modulus

HERTZ_EXPONENT = 1.5


@dataclass(frozen=True)
class ImpactLaw:
    """Parameters of one contact pair.

    stiffness k (N/m^e), exponent e, damping c (N s/m, reached at penetration d),
    penetration d (m, the depth over which damping ramps in), clamp (Adams' max(0, .)).
    """

    stiffness: float
    exponent: float = HERTZ_EXPONENT
    damping: float = 0.0
    penetration: float = 1e-4
    clamp: bool = True

    def __post_init__(self):
        object.__setattr__(self, "stiffness", require_positive("contact.stiffness", self.stiffness))
        e = require_positive("contact.exponent", self.exponent)
        if e < 1.0:
            # e < 1 makes dF/ddelta infinite at first touch; Adams requires e >= 1 too.
            raise InputError("contact.exponent", f"must be >= 1, got {e!r}")
        object.__setattr__(self, "exponent", e)
        object.__setattr__(self, "damping", require_nonnegative("contact.damping", self.damping))
        object.__setattr__(
            self, "penetration", require_positive("contact.penetration", self.penetration)
        )
        object.__setattr__(self, "clamp", bool(self.clamp))

    def force(self, delta, delta_dot):
        """Contact force in N (array-friendly); see ``impact_force``."""
        return impact_force(delta, delta_dot, self)

    def static_penetration(self, load: float) -> float:
        """Penetration in m that carries a static ``load`` in N: (load / k)^(1/e)."""
        return (load / self.stiffness) ** (1.0 / self.exponent)


def effective_radius(r1: float, r2: float = math.inf) -> float:
    """Eq. 5: R = R1 R2 / (R1 + R2); r2 = inf (a flat plate) gives R = R1."""
    if math.isinf(r2):
        return r1
    return r1 * r2 / (r1 + r2)


def hertz_stiffness(e_star: float, radius: float) -> float:
    """Eq. 4: k = 4/3 E* sqrt(R), in N/m^1.5."""
    return 4.0 / 3.0 * e_star * math.sqrt(radius)


def ball_plate_law(
    ball_material: Material,
    radius: float,
    plate_material: Material,
    *,
    exponent: float = HERTZ_EXPONENT,
    damping: float = 0.0,
    penetration: float = 1e-4,
    clamp: bool = True,
) -> ImpactLaw:
    """IMPACT law of a ball of ``radius`` (m) on a flat plate (plate radius infinite)."""
    k = hertz_stiffness(effective_modulus(ball_material, plate_material), radius)
    return ImpactLaw(k, exponent, damping, penetration, clamp)


def ball_ball_law(
    material_1: Material,
    radius_1: float,
    material_2: Material,
    radius_2: float,
    *,
    exponent: float = HERTZ_EXPONENT,
    damping: float = 0.0,
    penetration: float = 1e-4,
    clamp: bool = True,
) -> ImpactLaw:
    """IMPACT law of two balls, with R = R1 R2 / (R1 + R2) (eq. 5)."""
    r = effective_radius(radius_1, radius_2)
    k = hertz_stiffness(effective_modulus(material_1, material_2), r)
    return ImpactLaw(k, exponent, damping, penetration, clamp)


def step_scalar(x: float, x0: float, h0: float, x1: float, h1: float) -> float:
    """Adams STEP: h0 for x <= x0, h1 for x >= x1, cubic h0 + (h1-h0) s^2 (3 - 2 s) between.

    The cubic has zero slope at both ends, so STEP is C1 (its second derivative jumps).
    """
    if x <= x0:
        return h0
    if x >= x1:
        return h1
    s = (x - x0) / (x1 - x0)
    return h0 + (h1 - h0) * s * s * (3.0 - 2.0 * s)


def step(x, x0: float, h0: float, x1: float, h1: float):
    """Array version of ``step_scalar``."""
    x = np.asarray(x, dtype=float)
    s = np.clip((x - x0) / (x1 - x0), 0.0, 1.0)
    return h0 + (h1 - h0) * s * s * (3.0 - 2.0 * s)


def impact_force_scalar(
    delta: float,
    delta_dot: float,
    stiffness: float,
    exponent: float,
    damping: float,
    penetration: float,
    clamp: bool,
) -> float:
    """IMPACT force in N for penetration ``delta`` (m) and rate ``delta_dot`` (m/s)."""
    if delta <= 0.0:
        return 0.0
    force = stiffness * delta**exponent + step_scalar(delta, 0.0, 0.0, penetration, damping) * (
        delta_dot
    )
    if clamp and force < 0.0:
        return 0.0
    return force


def impact_force(delta, delta_dot, law: ImpactLaw):
    """Array version of ``impact_force_scalar`` for an ``ImpactLaw``."""
    delta = np.asarray(delta, dtype=float)
    delta_dot = np.asarray(delta_dot, dtype=float)
    inside = delta > 0.0
    pos = np.where(inside, delta, 0.0)
    force = law.stiffness * pos**law.exponent + step(
        pos, 0.0, 0.0, law.penetration, law.damping
    ) * (delta_dot)
    if law.clamp:
        force = np.maximum(force, 0.0)
    return np.where(inside, force, 0.0)


# --- The law region by region (for integrators that stop at every kink) -------------------
# A kink-respecting integrator (the slow references) integrates each region of the law with
# that region's smooth formula, extended past the region's borders, and stops at the border.
# Regions: ``ramp`` (delta < d: damping c STEP(delta, 0, 0, d, c)) or full damping (delta >= d:
# damping c), and ``clamped`` (Adams' max(0, .) active: force 0). These helpers are the same
# law as ``impact_force`` (tests/test_contact_law_regions.py checks they agree in each region).


def damping_in_region(delta, law: ImpactLaw, ramp):
    """Damping coefficient in N s/m: the STEP cubic (extended past [0, d]) where ``ramp``,
    else c. Array-friendly: ``law`` may hold arrays of parameters (one per pair) and
    ``ramp`` an array of flags."""
    s = np.asarray(delta, dtype=float) / law.penetration
    return np.where(ramp, law.damping * s * s * (3.0 - 2.0 * s), law.damping)


def impact_force_in_region(delta, delta_dot, law: ImpactLaw, ramp, clamped):
    """Force in N of one region's smooth formula; delta <= 0 gives the elastic term 0.

    Array-friendly like ``damping_in_region`` (``clamped``: flags, force 0 where set)."""
    pos = np.maximum(np.asarray(delta, dtype=float), 0.0)
    raw = law.stiffness * pos**law.exponent + damping_in_region(pos, law, ramp) * delta_dot
    return np.where(clamped, 0.0, raw)


def clamp_indicator(delta: float, delta_dot: float, law: ImpactLaw, ramp: bool) -> float:
    """raw force / (k delta^e): the sign of the unclamped force, not 0 at delta = 0.

    Its zero is the clamp kink (clamp on/off); unlike the force it does not vanish at
    separation, so the clamp events never coincide with contact end. At delta <= 0: the limit
    at delta -> 0+.
    """
    k, e, c, d = law.stiffness, law.exponent, law.damping, law.penetration
    if delta > 0.0:
        return 1.0 + float(damping_in_region(delta, law, ramp)) * delta_dot / (k * delta**e)
    if ramp and e < 2.0:
        return 1.0
    if ramp and e == 2.0:
        return 1.0 + 3.0 * c * delta_dot / (k * d * d)
    return -1.0 if delta_dot < 0.0 else 1.0


def elastic_energy(delta, law: ImpactLaw):
    """Energy in J stored by the elastic term: k delta^(e+1) / (e+1) for delta > 0, else 0."""
    pos = np.maximum(np.asarray(delta, dtype=float), 0.0)
    return law.stiffness * pos ** (law.exponent + 1.0) / (law.exponent + 1.0)
