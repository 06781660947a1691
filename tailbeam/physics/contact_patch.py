"""Where the contact force acts on the plate: a point, or 1 N spread over the Hertz disc.

The load model of a ball on the plate depends on the plate theory:
- Kirchhoff (thin plate): a point load. The thin-plate deflection under a point load is
  finite, and spreading the load over the Hertz disc (radius ~1-2 mm here) changes the local
  compliance by ~2e-4 only.
- Mindlin (shear-deformable plate): the deflection under a point load diverges
  (logarithmically, through shear), so on an FE mesh it depends on the mesh. The load is spread
  uniformly over a disc of the Hertz contact radius a = sqrt(R delta_m) at the ball's hardest
  impact (the speed after falling from its start), fixed per ball so the plate deflection the
  ball sees never jumps between flight and contact.

The same load model is used everywhere a ball meets the plate: the modal force and the plate
deflection under the ball (disc-averaged mode shapes), the static compliance and the kept-mode
compliance of the residual flexibility, and the FE reference (its load vector).
"""

import math

import numpy as np

from tailbeam.physics.hertz import hertz_max_penetration

DISC_RINGS, DISC_SPOKES = 4, 12  # 48-point polar rule for a load spread over a disc
RADIUS_GRID = 0.05  # load radii are rounded to a 5 % logarithmic grid (caching)


def disc_rule(plate, center, radius: float):
    """Points (q, 2) and weights (q,) summing to 1 for a uniform load over a disc.

    Gauss-Legendre in r^2 (area-uniform rings) x equally spaced angles; points that fall off
    the plate are dropped and the weights renormalised (the load stays 1 N in total).
    radius 0 gives the point itself.
    """
    center = np.asarray(center, dtype=float).reshape(2)
    if radius == 0.0:
        return center[None, :], np.ones(1)
    g, gw = np.polynomial.legendre.leggauss(DISC_RINGS)
    rings = radius * np.sqrt(0.5 * (g + 1.0))
    angles = 2.0 * np.pi * (np.arange(DISC_SPOKES) + 0.5) / DISC_SPOKES
    r, th = np.meshgrid(rings, angles, indexing="ij")
    pts = center + np.column_stack([(r * np.cos(th)).ravel(), (r * np.sin(th)).ravel()])
    w = np.repeat(gw, DISC_SPOKES)
    inside = (np.abs(pts[:, 0]) <= 0.5 * plate.size_x) & (np.abs(pts[:, 1]) <= 0.5 * plate.size_y)
    return pts[inside], w[inside] / w[inside].sum()


def uses_disc(theory: str) -> bool:
    """True if the plate theory spreads the contact force over the Hertz disc (Mindlin)."""
    return not str(theory).startswith("kirchhoff")


def load_radius(theory: str, ball, law, gravity: float) -> float:
    """Radius (m) of the disc a ball's contact force is spread over: 0 (point) for Kirchhoff,
    the Hertz radius at the ball's hardest impact for Mindlin (see the module docstring),
    rounded to the 5 % logarithmic grid."""
    if not uses_disc(theory):
        return 0.0
    gap = max(ball.position[2] - ball.radius, 0.0)
    speed = max(math.sqrt(ball.velocity[2] ** 2 + 2.0 * gravity * gap), 1e-3)
    delta_m = hertz_max_penetration(ball.mass, speed, law.stiffness, law.exponent)
    return round_radius(math.sqrt(ball.radius * delta_m))


def round_radius(radius: float) -> float:
    """radius (m) rounded to the 5 % logarithmic grid (0 stays 0)."""
    if radius <= 0.0:
        return 0.0
    return math.exp(RADIUS_GRID * round(math.log(radius) / RADIUS_GRID))
