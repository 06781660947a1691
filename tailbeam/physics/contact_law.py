"""The MSC Adams IMPACT contact force, with Hertz stiffness (paper eqs. 1, 4-6).

In terms of the penetration delta >= 0 (overlap of the two surfaces, m) and its rate
delta_dot (m/s, > 0 while approaching), Adams evaluates

    F = max(0, k delta^e + STEP(delta, 0, 0, d, c) * delta_dot)        for delta > 0
    F = 0                                                               for delta <= 0

k in N/m^e, c in N s/m, d in m. The max(0, .) clamp is Adams' behaviour; the paper's eq. 1
leaves it out (``clamp=False`` reproduces eq. 1 literally, with its adhesive pull at the end of
rebound). The law's formula is written once, in ``tailbeam.physics.impact`` (numba); this
module holds the parameters (``ImpactLaw``, Hertz stiffness) and array wrappers of that core
(``tailbeam.physics.impact_ufuncs``). numba loads when a force is first evaluated, not when a
law is built (a scene read builds laws and evaluates none).
"""

import math
from dataclasses import dataclass

import numpy as np

from tailbeam.errors import InputError, require_nonnegative, require_positive
from tailbeam.physics.materials import Material, effective_modulus

HERTZ_EXPONENT = 1.5
# The law's parameters as the compiled kernels take them: one row [k, e, c, d, clamp] per law
# (``law_table``); a solver keeps its own per-law values in the columns after LAW_COLUMNS.
LAW_K, LAW_E, LAW_C, LAW_D, LAW_CLAMP = range(5)
LAW_COLUMNS = 5


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


# --- Array wrappers of the law's one definition (tailbeam.physics.impact) ------------------
# They call the numba ufuncs of ``impact_ufuncs`` (imported on first use), so the formula is
# written once.


def __getattr__(name: str):
    """The compiled names, imported on first use (PEP 562): ``step_scalar`` (Adams STEP of
    floats, ``impact.step``), ``impact_force_scalar`` (the force in N of floats: delta m,
    delta_dot m/s, stiffness, exponent, damping, penetration, clamp; ``impact.force``) and
    ``impact_force_array`` (the same as a ufunc)."""
    if name in ("step_scalar", "impact_force_scalar"):
        from tailbeam.physics import impact

        return impact.step if name == "step_scalar" else impact.force
    if name == "impact_force_array":
        return _ufuncs().impact_force_array
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def _ufuncs():
    from tailbeam.physics import impact_ufuncs

    return impact_ufuncs


def step(x, x0: float, h0: float, x1: float, h1: float):
    """Array version of ``step_scalar``."""
    return _ufuncs().step(np.asarray(x, dtype=float), x0, h0, x1, h1)


def impact_force(delta, delta_dot, law: ImpactLaw):
    """IMPACT force in N (arrays) of penetrations ``delta`` (m) and rates ``delta_dot`` (m/s)
    under ``law``."""
    force = _ufuncs().impact_force_array
    return force(_floats(delta), _floats(delta_dot), *_parameters(law), law.clamp)


def damping_in_region(delta, law: ImpactLaw, ramp):
    """Damping coefficient in N s/m: the STEP cubic (extended past [0, d]) where ``ramp``,
    else c."""
    return _ufuncs().region_damping(_floats(delta), law.damping, law.penetration, ramp)


def impact_force_in_region(delta, delta_dot, law: ImpactLaw, ramp, clamped):
    """Force in N of one region's smooth formula; delta <= 0 gives the elastic term 0; 0 where
    ``clamped``."""
    force = _ufuncs().region_force
    return force(_floats(delta), _floats(delta_dot), *_parameters(law), ramp, clamped)


def clamp_indicator(delta: float, delta_dot: float, law: ImpactLaw, ramp: bool) -> float:
    """Unclamped force / (k delta^e): the sign of the unclamped force, not 0 at delta = 0
    (``tailbeam.physics.impact.clamp_indicator``)."""
    from tailbeam.physics import impact

    return impact.clamp_indicator(float(delta), float(delta_dot), *_parameters(law), bool(ramp))


def elastic_energy(delta, law: ImpactLaw):
    """Energy in J stored by the elastic term: k delta^(e+1) / (e+1) for delta > 0, else 0."""
    return _ufuncs().elastic_energy(_floats(delta), law.stiffness, law.exponent)


def law_table(laws) -> np.ndarray:
    """(P, LAW_COLUMNS) array of the ``ImpactLaw``s ``laws``: k, e, c, d, clamp (0 or 1)."""
    return np.array(
        [[w.stiffness, w.exponent, w.damping, w.penetration, float(w.clamp)] for w in laws],
        dtype=float,
    ).reshape(-1, LAW_COLUMNS)


def _parameters(law):
    return law.stiffness, law.exponent, law.damping, law.penetration


def _floats(x):
    return np.asarray(x, dtype=float)
