"""Zener's sphere-on-plate impact: the ball meets an infinite Kirchhoff plate.

An infinite thin plate answers a point force with a velocity F / Z at the load point, with the
real, frequency-independent point impedance Z = 8 sqrt(D rho h) (Cremer & Heckl). During the
contact the plate therefore acts as a dashpot in series with the Hertz spring:

    m dv/dt = -F,    d delta/dt = v - F / Z,    F = k delta^e        (e = 3/2)

(v the ball's approach speed, delta the Hertz penetration). Scaling delta by the Hertz maximum
penetration delta_m and time by delta_m / v0 leaves one parameter, Zener's inelasticity

    lambda = F_m / (Z v0)      with F_m = k delta_m^e the rigid-plate Hertz peak force,

the ratio of the plate's dashpot velocity under the peak force to the impact speed. (Zener
(1941) wrote it, for e = 3/2, as lambda_Z = pi^(3/5)/(2 sqrt 3) (R/h)^2 (v0/c)^(1/5)
(rho_ball/rho_plate)^(3/5) (E-dependent factor); ours is the same group up to a constant.)
Restitution falls from 1 (lambda = 0) towards 0 as lambda grows. This ODE, integrated at tight
tolerance, is the independent truth of the coupled solver's far-from-edges limit.
"""

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from tailbeam.errors import require_positive
from tailbeam.physics.bodies import Plate
from tailbeam.physics.hertz import hertz_max_penetration, hertz_peak_force


def point_impedance(plate: Plate) -> float:
    """Z = 8 sqrt(D rho h) in N s/m: an infinite Kirchhoff plate's drive-point impedance."""
    return 8.0 * math.sqrt(plate.bending_stiffness * plate.mass_per_area)


@dataclass(frozen=True)
class ZenerImpact:
    """Restitution, contact duration (s), peak force (N), inelasticity lambda, plate energy
    fraction (energy radiated into the plate / the ball's initial kinetic energy)."""

    restitution: float
    duration: float
    peak_force: float
    lam: float
    energy_to_plate: float


def zener_lambda(mass: float, speed: float, stiffness: float, impedance: float, exponent=1.5):
    """lambda = F_m / (Z v0), F_m the rigid-plate Hertz peak force."""
    return hertz_peak_force(mass, speed, stiffness, exponent) / (impedance * speed)


def zener_impact(
    mass: float, speed: float, stiffness: float, impedance: float, exponent: float = 1.5
) -> ZenerImpact:
    """Integrate the Zener ODE (rtol 1e-12) for a ball of ``mass`` kg meeting the plate at
    ``speed`` m/s under F = k delta^e; the contact ends when delta returns to 0."""
    require_positive("mass", mass)
    require_positive("speed", speed)
    require_positive("impedance", impedance)
    k, e, Z = stiffness, exponent, impedance
    delta_m = hertz_max_penetration(mass, speed, k, e)
    t_scale = delta_m / speed

    def rhs(_t, y):
        v, d = y
        f = k * max(d, 0.0) ** e
        return [-f / mass, v - f / Z]

    def end(_t, y):
        return y[1]

    end.terminal = True
    end.direction = -1
    # start just inside (delta = 0 is a fixed point of the event); first-order start-up
    t0 = 1e-9 * t_scale
    sol = solve_ivp(
        rhs, (t0, 50 * t_scale), [speed, speed * t0], method="DOP853", rtol=1e-12,
        atol=[1e-14 * speed, 1e-14 * delta_m], events=end, dense_output=True,
    )  # fmt: skip
    t_end = float(sol.t_events[0][0])
    v_end = float(sol.y_events[0][0][0])
    tt = np.linspace(t0, t_end, 4001)
    f = k * np.maximum(sol.sol(tt)[1], 0.0) ** e
    return ZenerImpact(
        restitution=-v_end / speed,
        duration=t_end,
        peak_force=float(np.max(f)),
        lam=zener_lambda(mass, speed, k, Z, e),
        energy_to_plate=1.0 - (v_end / speed) ** 2,
    )
