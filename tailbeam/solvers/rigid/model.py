"""The ball-plate pair: constants, ballistic flight, rest definition and input checks.

Shared by the fast solver and the reference (these are closed forms; the two differ in how they
integrate a contact). In a contact the state is the penetration delta = R - z (m) and its rate
u = -vz (m/s); the equation of motion is  m du/dt = m g - F(delta, u).

Rest. With the STEP ramp the damping vanishes at small penetration, so the restitution tends to
1 at low speed and an undisturbed ball would bounce ever lower for a very long time. A ball is
declared at rest when either
  (A) it leaves a contact with a rebound speed below ``rest_speed``, or
  (B) during a contact its mechanical energy above the static rest state,
      E_ex = m u^2 / 2 + k delta^(e+1) / (e+1) - m g delta - V_static,
      drops to E_rest = min(m rest_speed^2 / 2, E_trap), where E_trap = m g delta_s e / (e+1)
      is the least energy with which it could still leave the plate. Since the IMPACT force
      never adds energy (dE/dt = -STEP u^2 <= 0, and <= 0 when clamped), a ball with
      E_ex <= E_trap stays in persistent contact and oscillates about delta_s = (m g / k)^(1/e).
From then on it sits at z = R - delta_s, vz = 0, force = m g.

DEFAULT_REST_SPEED = 0.01 m/s: a rebound at that speed rises v^2 / (2 g) = 5.1 um, comparable
to the surface roughness of a hot-rolled steel plate (Ra ~ 1-10 um) and to the static Hertz
penetration of a 30 mm coal ball (~1 um): below it the bounce height is not resolved by the
model's own idealisations (smooth surfaces, rigid plate).
"""

import math
from dataclasses import dataclass
from functools import cached_property

from tailbeam.errors import InputError, require_nonnegative, require_positive, require_real
from tailbeam.physics import impact
from tailbeam.physics.bodies import Ball, Plate, check_ball_above_plate
from tailbeam.physics.contacts import PLATE, contact_table
from tailbeam.physics.hertz import static_penetration

DEFAULT_REST_SPEED = 0.01  # m/s, see the module docstring
DEFAULT_MAX_CONTACTS = 20_000  # per ball
DEFAULT_MAX_STEPS = 2_000_000  # integrator steps per ball


@dataclass(frozen=True)
class Pair:
    """One ball against the plate: everything the contact integrators need (SI units)."""

    name: str
    radius: float
    mass: float
    k: float
    e: float
    c: float
    d: float
    clamp: bool
    gravity: float
    rest_speed: float
    position: tuple
    velocity: tuple

    @cached_property
    def delta_static(self) -> float:
        """Static penetration (m g / k)^(1/e) in m."""
        return static_penetration(self.mass * self.gravity, self.k, self.e)

    @cached_property
    def e_trap(self) -> float:
        """Energy above the rest state (J) below which the ball cannot leave the plate."""
        return self.mass * self.gravity * self.delta_static * self.e / (self.e + 1.0)

    @cached_property
    def e_rest(self) -> float:
        """Rule (B) threshold in J (0 disables it)."""
        return min(0.5 * self.mass * self.rest_speed**2, self.e_trap)

    def excess_energy(self, delta: float, u: float) -> float:
        """Mechanical energy in J above the static rest state (see the module docstring)."""
        elastic = impact.elastic_energy(delta, self.k, self.e)
        return 0.5 * self.mass * u * u + elastic - self.mass * self.gravity * delta + self.e_trap

    def contains(self, plate: Plate, t: float) -> bool:
        """Whether the centre is over the plate at time t (lateral motion is uniform)."""
        x = self.position[0] + self.velocity[0] * t
        y = self.position[1] + self.velocity[1] * t
        return plate.contains(x, y)

    def scales(self, v_in: float) -> tuple:
        """(penetration m, speed m/s, time s) scales of a contact at impact speed v_in."""
        delta_h = 0.0
        if v_in > 0.0:
            p = self.e + 1.0
            delta_h = (p * self.mass * v_in**2 / (2.0 * self.k)) ** (1.0 / p)
        delta = max(delta_h, self.delta_static)
        speed = math.sqrt(v_in**2 + 2.0 * self.gravity * delta)
        return delta, speed, delta / speed


def time_to_contact(gap: float, vz: float, gravity: float) -> tuple:
    """First time tau >= 0 (s) at which a ball with its lowest point ``gap`` m above the plate,
    moving at ``vz`` (m/s, up positive) under ``gravity``, touches it; and its speed then.

    Solves gap + vz tau - g tau^2 / 2 = 0 without cancellation: with s = sqrt(vz^2 + 2 g gap),
    tau = 2 gap / (s - vz) if vz < 0 else (vz + s) / g. Returns (inf, nan) if it never does.
    """
    if gravity == 0.0:
        if vz < 0.0:
            return gap / -vz, -vz
        return math.inf, math.nan
    s = math.sqrt(vz * vz + 2.0 * gravity * gap)
    if vz < 0.0:
        return 2.0 * gap / (s - vz), s
    return (vz + s) / gravity, s


def make_pairs(balls, plate, laws, duration, *, gravity, rest_speed, max_contacts, max_steps):
    """Validate the inputs of a rigid simulation and return the Pair of each ball; ``laws``:
    the balls' ``ContactTable`` or one ball-plate ImpactLaw per ball (``contact_table``)."""
    if not isinstance(plate, Plate):
        raise InputError("plate", "must be a Plate")
    try:
        balls = tuple(balls)
    except TypeError:
        raise InputError("balls", "must be a sequence of Ball") from None
    if not balls:
        raise InputError("balls", "must contain at least one Ball")
    names = set()
    for i, ball in enumerate(balls):
        if not isinstance(ball, Ball):
            raise InputError(f"balls[{i}]", "must be a Ball")
        if ball.name in names:
            raise InputError(f"balls[{i}].name", f"duplicate ball name {ball.name!r}")
        names.add(ball.name)
        check_ball_above_plate(ball, plate)
    contacts = contact_table(balls, laws)
    require_positive("duration", duration)
    g = require_nonnegative("gravity", gravity)
    rs = require_nonnegative("rest_speed", rest_speed)
    for fname, value in (("max_contacts", max_contacts), ("max_steps", max_steps)):
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise InputError(fname, f"must be a positive integer, got {value!r}")
    return [_pair(ball, contacts.law(i, PLATE), g, rs) for i, ball in enumerate(balls)]


def _pair(ball, law, gravity: float, rest_speed: float) -> Pair:
    """The Pair of ``ball`` with its ball-plate ``law`` (gravity m/s^2, rest_speed m/s)."""
    return Pair(
        ball.name,
        ball.radius,
        ball.mass,
        law.stiffness,
        law.exponent,
        law.damping,
        law.penetration,
        law.clamp,
        gravity,
        rest_speed,
        ball.position,
        ball.velocity,
    )


def check_rtol(rtol: float) -> float:
    """Relative tolerance within [1e-14, 1e-2]."""
    rtol = require_real("rtol", rtol)
    if not 1e-14 <= rtol <= 1e-2:
        raise InputError("rtol", f"must lie in [1e-14, 1e-2], got {rtol!r}")
    return rtol
