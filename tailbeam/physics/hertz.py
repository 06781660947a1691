"""Closed forms of an undamped elastic (Hertz-type) impact without gravity.

A ball of mass m (kg) meets a rigid flat at speed v (m/s) under the force F = k delta^e
(k in N/m^e, delta the penetration in m). Energy conservation, m v^2 / 2 = k delta^(e+1) / (e+1),
gives the maximum penetration and peak force; integrating dt = d delta / delta_dot gives the
contact duration (Johnson, Contact Mechanics, section 11.4, for e = 3/2):

    delta_m = ((e + 1) m v^2 / (2 k))^(1 / (e + 1))
    F_m     = k delta_m^e
    t_c     = 2 (delta_m / v) * I(e),    I(e) = int_0^1 dx / sqrt(1 - x^(e+1))
                                              = B(1 / (e + 1), 1 / 2) / (e + 1)

For e = 3/2, 2 I(e) = 2.9432... (Johnson's constant). The motion is symmetric: the peak is at
t_c / 2 and the ball leaves at speed v (restitution 1). These are the independent truths the
rigid-plate solver is tested against.
"""

import math

from tailbeam.errors import require_positive


def _check(mass, speed, stiffness, exponent):
    require_positive("mass", mass)
    require_positive("speed", speed)
    require_positive("stiffness", stiffness)
    require_positive("exponent", exponent)


def hertz_max_penetration(mass: float, speed: float, stiffness: float, exponent: float = 1.5):
    """Maximum penetration delta_m in m of an undamped impact at ``speed`` (m/s)."""
    _check(mass, speed, stiffness, exponent)
    return ((exponent + 1.0) * mass * speed**2 / (2.0 * stiffness)) ** (1.0 / (exponent + 1.0))


def hertz_peak_force(mass: float, speed: float, stiffness: float, exponent: float = 1.5):
    """Peak force F_m = k delta_m^e in N."""
    return stiffness * hertz_max_penetration(mass, speed, stiffness, exponent) ** exponent


def hertz_duration_factor(exponent: float = 1.5) -> float:
    """The dimensionless 2 I(e) of t_c = 2 I(e) delta_m / v; 2.9432 for e = 3/2."""
    from scipy.special import beta  # here: importing scipy.special costs more than a scene read

    require_positive("exponent", exponent)
    p = exponent + 1.0
    return 2.0 * beta(1.0 / p, 0.5) / p


def hertz_contact_duration(mass: float, speed: float, stiffness: float, exponent: float = 1.5):
    """Contact duration t_c in s of an undamped impact at ``speed`` (m/s)."""
    delta_m = hertz_max_penetration(mass, speed, stiffness, exponent)
    return hertz_duration_factor(exponent) * delta_m / speed


def static_penetration(weight: float, stiffness: float, exponent: float = 1.5) -> float:
    """Penetration in m that carries a static load ``weight`` (N): (W / k)^(1/e)."""
    if weight == 0.0:
        return 0.0
    return (weight / stiffness) ** (1.0 / exponent)


def free_fall_apex(speed: float, gravity: float) -> float:
    """Height in m reached by a ball leaving upwards at ``speed`` (m/s): v^2 / (2 g)."""
    if gravity <= 0.0:
        return math.inf
    return speed**2 / (2.0 * gravity)
