"""Friction and rolling resistance of a contact: the Adams CONTACT friction law, written once.

The friction coefficient is a function of the slip speed v = |v_slip| (m/s) at the contact
point, built from Adams' cubic STEP (``tailbeam.physics.contact_law.step``, the one the
IMPACT law uses):

    mu(v) = STEP(v, 0, 0, v_s, mu_s)            0 <= v < v_s   (stiction transition)
    mu(v) = STEP(v, v_s, mu_s, v_d, mu_d)       v_s <= v < v_d (friction transition)
    mu(v) = mu_d                                v >= v_d

and the tangential force on body i is F_t = -mu(v) |F_n| v_slip / v (zero at zero slip).
mu is continuous with a continuous derivative (STEP has zero slope at both ends), and
mu(v) ~ 3 mu_s (v / v_s)^2 near v = 0, so F_t is continuously differentiable in v_slip.
Coulomb's law is the limit v_s, v_d -> 0. The regularisation has a price: a tangential
load below mu_s |F_n| is held by a slip speed below v_s, not by zero slip (a "creep"
bounded by v_s). With v_s = v_d = 0 (``FrictionSettings.coulomb``) the law is Coulomb's:
mu = mu_d at any slip; a stuck contact's force is whatever holds it, up to mu_s |F_n|, and
the solver that models it switches stick and slip as events.

Rolling resistance (the constant directional torque of DEM codes): a torque of magnitude
mu_r R |F_n| against the relative rolling angular velocity omega_roll (the part of the
relative angular velocity in the contact plane), R the rolling radius (the ball's radius on
the plate, R1 R2 / (R1 + R2) between two balls). The direction is regularised as the
friction's is: magnitude mu_r R |F_n| STEP(R |omega_roll|, 0, 0, v_s, 1), so a ball held by
it creeps at a rolling speed below v_s (``rolling_torque``; with v_s = 0: mu_r R |F_n| at
any rolling speed, and a held contact's torque is whatever holds it, up to mu_r R |F_n|).
"""

from dataclasses import dataclass, replace

import numpy as np

from tailbeam.errors import InputError, require_nonnegative
from tailbeam.physics.contact_law import step  # Adams' STEP, the IMPACT law's own

# Adams CONTACT defaults (100 mm/s and 1000 mm/s): coarse; the manual says how far to trust them
DEFAULT_STICTION_VELOCITY = 0.1  # m/s
DEFAULT_TRANSITION_VELOCITY = 1.0  # m/s
KEYS = ("static", "dynamic", "stiction_velocity", "transition_velocity", "rolling")


@dataclass(frozen=True)
class FrictionSettings:
    """One pair's friction: static mu_s and dynamic mu_d coefficients, stiction velocity v_s
    and transition velocity v_d (m/s, 0 < v_s < v_d), rolling-resistance coefficient mu_r
    (dimensionless, a lever arm per radius). ``field`` names it in errors
    (``contact.friction``)."""

    static: float
    dynamic: float
    stiction_velocity: float = DEFAULT_STICTION_VELOCITY
    transition_velocity: float = DEFAULT_TRANSITION_VELOCITY
    rolling: float = 0.0
    field: str = "contact.friction"

    def __post_init__(self):
        f = self.field
        for key in ("static", "dynamic", "rolling"):
            object.__setattr__(self, key, require_nonnegative(f"{f}.{key}", getattr(self, key)))
        for key in ("stiction_velocity", "transition_velocity"):
            object.__setattr__(self, key, require_nonnegative(f"{f}.{key}", getattr(self, key)))
        if self.dynamic > self.static:
            raise InputError(
                f"{f}.dynamic", f"must be <= static = {self.static!r} (Adams' rule), "
                f"got {self.dynamic!r}"
            )  # fmt: skip
        if self.coulomb and self.transition_velocity != 0.0:
            raise InputError(
                f"{f}.transition_velocity",
                "must be 0 with stiction_velocity = 0 (Coulomb's law: mu_s holds a stuck "
                f"contact, mu_d acts on any slip), got {self.transition_velocity!r}",
            )
        if not self.coulomb and self.transition_velocity <= self.stiction_velocity:
            raise InputError(
                f"{f}.transition_velocity",
                f"must be > stiction_velocity = {self.stiction_velocity!r} m/s, "
                f"got {self.transition_velocity!r}",
            )

    @property
    def coulomb(self) -> bool:
        """Coulomb's law (v_s = v_d = 0): stick and slip, rolling held and free, switched as
        events (the ``stream-reference`` solver), in place of the regularised law."""
        return self.stiction_velocity == 0.0

    def values(self) -> dict:
        """The five scene-file keys and their values."""
        return {k: getattr(self, k) for k in KEYS}


def coefficient(speed, static, dynamic, v_s, v_d):
    """mu(v) of the module docstring at slip speeds ``speed`` (m/s, >= 0); the parameters
    may be arrays broadcasting with ``speed``."""
    speed = np.asarray(speed, dtype=float)
    coulomb = np.asarray(v_s) == 0.0
    v_s, v_d = np.where(coulomb, 1.0, v_s), np.where(coulomb, 2.0, v_d)  # (unused there)
    rise = step(speed, 0.0, 0.0, v_s, static)
    fall = step(speed, v_s, static, v_d, dynamic)
    regularised = np.where(speed < v_s, rise, fall)
    return np.where(coulomb, np.where(speed > 0.0, dynamic, 0.0), regularised)


def tangential_force(slip, normal_force, static, dynamic, v_s, v_d):
    """F_t = -mu(|slip|) |F_n| slip / |slip| (N), zero where slip = 0.

    slip: (..., 3) slip velocity at the contact point (m/s, tangential); normal_force: (...)
    F_n (N); the coefficients as ``coefficient``'s, broadcasting with (...).
    """
    slip = np.asarray(slip, dtype=float)
    speed = np.sqrt(np.einsum("...k,...k->...", slip, slip))
    mu = coefficient(speed, static, dynamic, v_s, v_d)
    scale = np.divide(mu * np.abs(normal_force), speed, out=np.zeros_like(speed), where=speed > 0)
    return -scale[..., None] * slip


def rolling_torque(omega_roll, normal_force, rolling, radius, v_s):
    """Rolling-resistance torque (N m) on body i: -mu_r R |F_n| STEP(R |w|, 0, 0, v_s, 1)
    w / |w|, w = ``omega_roll`` (..., 3) the relative angular velocity in the contact plane
    (rad/s); zero where w = 0. ``radius``: the rolling radius R (m)."""
    omega_roll = np.asarray(omega_roll, dtype=float)
    rate = np.sqrt(np.einsum("...k,...k->...", omega_roll, omega_roll))
    coulomb = np.asarray(v_s) == 0.0
    ramp = step(radius * rate, 0.0, 0.0, np.where(coulomb, 1.0, v_s), 1.0)
    size = rolling * radius * np.abs(normal_force) * np.where(coulomb, 1.0, ramp)
    scale = np.divide(size, rate, out=np.zeros_like(rate), where=rate > 0)
    return -scale[..., None] * omega_roll


@dataclass(frozen=True)
class FrictionModel:
    """The friction of a scene: ``default`` for every pair, and ``pairs``, a tuple of
    ((material, material), FrictionSettings) overriding it for those two materials (in
    either order; a material with itself for two balls of it; the plate's material for a
    ball on the plate)."""

    default: FrictionSettings
    pairs: tuple = ()

    def __post_init__(self):
        seen = set()
        for k, (names, _settings) in enumerate(self.pairs, start=1):
            key = frozenset(names)
            if key in seen:
                raise InputError(
                    f"contact.friction.pairs[{k}].materials",
                    f"{list(names)} is given by an earlier pair",
                )
            seen.add(key)

    def between(self, a: str, b: str) -> FrictionSettings:
        """The settings of a contact between materials named ``a`` and ``b``."""
        for names, settings in self.pairs:
            if frozenset(names) == frozenset((a, b)):
                return settings
        return self.default

    def pair_settings(self, index: int, materials, values: dict) -> tuple:
        """((a, b), settings) of pair number ``index`` (1-based): ``values`` override the
        default's (InputError naming ``contact.friction.pairs[index].KEY``)."""
        field = f"contact.friction.pairs[{index}]"
        return tuple(materials), replace(self.default, field=field, **values)

    @property
    def coulomb(self) -> bool:
        """Whether any pair has Coulomb's law (``FrictionSettings.coulomb``)."""
        return self.default.coulomb or any(s.coulomb for _names, s in self.pairs)

    def values(self) -> dict:
        """The scene-file table: the five keys, then ``pairs`` if any."""
        out = self.default.values()
        if self.pairs:
            out["pairs"] = [
                {"materials": list(names), **s.values()} for names, s in self.pairs
            ]  # fmt: skip
        return out
