"""The paper's built-in scenes (sections 4.1-4.3): two balls dropped side by side on a rigid plate.

Every scenario uses Table 1 materials, radius R = 0.03 m and the rigid 0.6 x 0.6 x 0.01 m
carbon-steel plate. The balls sit at x = -0.15 m and x = +0.15 m (0.3 m apart, so they never
touch), start with their lowest point ``DROP_GAP`` above the plate and move straight down at the
paper's speed. Where the paper is silent (drop gap, duration, c, d) the values come from the
calibration against every qualitative claim (tailbeam.paper.claims, benchmarks/claim_map.py;
docs/reproduction.md, "Defaults").
"""

import math
from dataclasses import dataclass

from tailbeam.physics.bodies import Ball, Plate
from tailbeam.physics.materials import COAL, SANDSTONE, Material
from tailbeam.scene import ContactSettings, Scene

BALL_RADIUS = 0.03  # m, Table 1
BALL_X = (-0.15, 0.15)  # m, centres of the two balls (plate spans x in [-0.3, 0.3])

# Gap between each ball's lowest point and the plate at t = 0, m. The paper gives the speed as the
# balls' "initial speed" and says they "collide with the rigid plate at the initial speed", so the
# drop must be short: 5 mm raises a 1 m/s impact to 1.048 m/s (< 5 %) and keeps the balls visibly
# clear of the plate at t = 0. The gap must stay small anyway for claim 4.1 "B reaches its
# highest rebound later than A" (after a long drop both balls hit at nearly the same speed and A,
# starting slower, arrives last); benchmarks/claim_map.py maps the claims over gaps 0-200 mm.
DROP_GAP = 0.005

# Simulated time, s, per scenario. 4.1 and 4.2: 1 s shows 4-9 collisions per ball (the claims
# compare the balls collision by collision); over 5-20 s the near-rest hops and the balls coming
# to rest overturn the "collides more often" and "short contact" claims
# (docs/reproduction.md, "Defaults").
# 4.3: 10 s, because the claim "coal comes to rest first" needs coal declared at rest
# (tailbeam.solvers.rigid's definition: a rebound slower than its rest_speed, 0.01 m/s); with the
# STEP ramp the damping vanishes at small penetration, so the last bounces are nearly elastic and
# coal only comes to rest after ~7 s.
DURATIONS = {"velocity": 1.0, "material": 1.0, "energy": 10.0}

# Output sample rate of the built-in scenes, Hz (time series and figures). time_grid adds every
# impact's peak time, so peaks are exact at any rate; 20 kHz puts ~7 samples in a 0.35 ms contact.
# 4.3 runs 10 s and uses 5 kHz to keep its time series small (50 001 rows).
SAMPLE_RATES = {"velocity": 20000.0, "material": 20000.0, "energy": 5000.0}


def equal_energy_speed(speed_ref: float, material_ref: Material, material: Material) -> float:
    """Speed (m/s) that gives a ball of ``material`` the kinetic energy of an equal-radius ball of
    ``material_ref`` moving at ``speed_ref``: m v^2 = m_ref v_ref^2 with m proportional to the
    density, so v = v_ref sqrt(rho_ref / rho)."""
    return speed_ref * math.sqrt(material_ref.density / material.density)


@dataclass(frozen=True)
class BallSpec:
    """One ball of a scenario: name, material and downward speed at t = 0 (m/s)."""

    name: str
    material: Material
    speed: float


@dataclass(frozen=True)
class Scenario:
    """A built-in scene of the paper: key, section, title, two balls, duration (s)."""

    key: str
    section: str
    title: str
    balls: tuple[BallSpec, BallSpec]
    duration: float
    sample_rate: float

    def scene(
        self,
        contact: ContactSettings | None = None,
        *,
        drop_gap: float = DROP_GAP,
        duration: float | None = None,
    ) -> Scene:
        """The Scene: balls side by side, lowest points ``drop_gap`` (m) above the plate."""
        balls = tuple(
            Ball(
                spec.name,
                spec.material,
                BALL_RADIUS,
                (x, 0.0, BALL_RADIUS + drop_gap),
                (0.0, 0.0, -spec.speed),
            )
            for spec, x in zip(self.balls, BALL_X, strict=True)
        )
        return Scene(
            balls,
            Plate(),
            contact if contact is not None else ContactSettings(),
            self.duration if duration is None else duration,
            self.sample_rate,
        )


VELOCITY = Scenario(
    "velocity",
    "4.1",
    "Effect of velocity: coal A at 1 m/s, coal B at 2 m/s",
    (BallSpec("A", COAL, 1.0), BallSpec("B", COAL, 2.0)),
    DURATIONS["velocity"],
    SAMPLE_RATES["velocity"],
)
MATERIAL = Scenario(
    "material",
    "4.2",
    "Effect of material: coal and sandstone at 1 m/s",
    (BallSpec("coal", COAL, 1.0), BallSpec("sandstone", SANDSTONE, 1.0)),
    DURATIONS["material"],
    SAMPLE_RATES["material"],
)
_V_COAL = equal_energy_speed(1.0, SANDSTONE, COAL)  # m/s, 1.3425 (paper)
ENERGY = Scenario(
    "energy",
    "4.3",
    f"Equal kinetic energy: sandstone 1 m/s, coal {_V_COAL:.4f} m/s",
    (
        BallSpec("coal", COAL, _V_COAL),
        BallSpec("sandstone", SANDSTONE, 1.0),
    ),
    DURATIONS["energy"],
    SAMPLE_RATES["energy"],
)
SCENARIOS = {s.key: s for s in (VELOCITY, MATERIAL, ENERGY)}


def run_scenario(
    key: str,
    contact: ContactSettings | None = None,
    *,
    drop_gap: float = DROP_GAP,
    duration: float | None = None,
    solver=None,
    **solver_options,
):
    """Simulate built-in scenario ``key`` on the rigid plate; returns its ``tailbeam.Result``.

    ``solver``: a function with the signature of ``tailbeam.solvers.rigid.simulate_rigid``
    (default), e.g. ``tailbeam.solvers.rigid.reference.simulate_rigid_reference``.
    """
    if solver is None:
        from tailbeam.solvers.rigid import simulate_rigid as solver  # imported when first needed

    scene = SCENARIOS[key].scene(contact, drop_gap=drop_gap, duration=duration)
    return solver(scene.balls, scene.plate, scene.contacts(), scene.duration, **solver_options)


def run_all(contact: ContactSettings | None = None, *, drop_gap: float = DROP_GAP, **options):
    """Run the three built-in scenarios; returns {scenario key: Result}."""
    return {key: run_scenario(key, contact, drop_gap=drop_gap, **options) for key in SCENARIOS}
