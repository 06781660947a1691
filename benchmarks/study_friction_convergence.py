"""Convergence of the regularised Adams friction law to Coulomb's as v_s -> 0, in the stream
reference (rigid plate), against closed forms of rigid-body mechanics with Coulomb friction.

Cases (a coal ball, r = 30 mm, on the carbon-steel plate; v_d = 2 v_s, mu_s = mu_d):

* ``stick``: an oblique impact, v_n = 1 m/s, v_t = 0.5 m/s, mu = 0.4, no gravity: v_t is
  below 7/2 mu (1 + e) v_n, so with Coulomb friction the contact point's slip reaches zero
  during the contact and the ball leaves rolling, v_t' = 5/7 v_t: tangential impulse
  J_t = 2/7 m v_t. The regularised law never quite stops the slip, so J_t falls short.
* ``onset``: a ball set down sliding at v0 = 1 m/s on the horizontal plate, mu = 0.4: it
  starts rolling at t = 2 v0 / (7 mu g); the regularised onset (slip down to v_s) is early by
  at most v_d / (7/2 mu g).
* ``stick_stiff``: ``stick`` with the coal's Young's modulus x 100 (penetration / 6.3): the
  shortfall left as v_s -> 0 is the lever arm r - delta of the penetrated ball (the contact
  point lies on the plate's surface), which the rigid-body closed form does not have.
* ``creep``: a ball at rest on a 20 degree incline, mu = 0.4: it rolls, held by friction at
  a steady slip speed below v_s (Coulomb: zero); the slip speed after 50 ms.
* ``hold``: a ball at rest on a 4 degree incline with mu_r = 0.1 (tan theta < mu_r): Coulomb
  holds it; the regularised torque holds it at a creep speed below v_s; the speed after 50 ms.

Writes ``table.md`` and ``convergence.csv`` into --out: error, its observed order between
successive v_s, DOP853 steps and wall time per case.

    python benchmarks/study_friction_convergence.py --out DIR [--quick]
"""

import argparse
import csv
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tailbeam.physics.bodies import STANDARD_GRAVITY, Ball, Plate  # noqa: E402
from tailbeam.physics.contact_law import ball_plate_law  # noqa: E402
from tailbeam.physics.friction import FrictionModel, FrictionSettings  # noqa: E402
from tailbeam.physics.incline import InclinedPlate  # noqa: E402
from tailbeam.physics.materials import CARBON_STEEL, Material, get_material  # noqa: E402
from tailbeam.solvers.stream.reference.solver import simulate_stream_reference  # noqa: E402

G = STANDARD_GRAVITY
R, MU = 0.03, 0.4
COAL = get_material("coal")


def resting(theta, velocity=(0.0, 0.0, 0.0)):
    """The ball on the plate at its static penetration."""
    law = ball_plate_law(COAL, R, CARBON_STEEL, damping=300.0)
    m = Ball("m", COAL, R, (0.0, 0.0, R)).mass
    delta = (m * G * math.cos(math.radians(theta)) / law.stiffness) ** (1.0 / law.exponent)
    return Ball("a", COAL, R, (-0.25, 0.0, R - delta), velocity)


def run(ball, theta, v_s, duration, gravity=G, rolling=0.0):
    model = FrictionModel(FrictionSettings(MU, MU, v_s, 2.0 * v_s, rolling))
    start = time.perf_counter()
    res = simulate_stream_reference(
        [ball], InclinedPlate(Plate(), theta, gravity), duration, friction=model, rtol=1e-11,
        damping=300.0, max_steps=10**6,
    )  # fmt: skip
    return res, time.perf_counter() - start


def stick(v_s, material=COAL):
    """Relative shortfall of J_t against 2/7 m v_t."""
    ball = Ball("a", material, R, (-0.2, 0.0, R + 1e-5), (0.5, 0.0, -1.0))
    res, wall = run(ball, 0.0, v_s, 1e-3, gravity=0.0)
    exact = 2.0 / 7.0 * ball.mass * 0.5
    return abs(res.contacts[0].tangential_impulse - exact) / exact, res.steps, wall


def stick_stiff(v_s):
    """``stick`` with a 100 x stiffer coal."""
    stiff = Material("stiff_coal", COAL.density, 100.0 * COAL.youngs_modulus, COAL.poisson_ratio)
    return stick(v_s, stiff)


def hold(v_s):
    """Centre speed (m/s) after 50 ms of a ball held by rolling resistance (Coulomb: 0)."""
    res, wall = run(resting(4.0), 4.0, v_s, 0.05, rolling=0.1)
    return float(np.linalg.norm(res.states[-1][2][0])), res.steps, wall


def onset(v_s):
    """Onset time error (s) against 2 v0 / (7 mu g), relative."""
    res, wall = run(resting(0.0, (1.0, 0.0, 0.0)), 0.0, v_s, 0.08)
    v = np.array([s[2][0, 0] for s in res.states])
    w = np.array([s[0, 1] for s in res.spins])
    k = int(np.argmax(v - w * R <= v_s))
    exact = 2.0 / (7.0 * MU * G)
    return abs(res.times[k] - exact) / exact, res.steps, wall


def creep(v_s):
    """Slip speed (m/s) of the rolling ball after 50 ms (Coulomb: 0)."""
    res, wall = run(resting(20.0), 20.0, v_s, 0.05)
    v, w = res.states[-1][2][0], res.spins[-1][0]
    return abs(v[0] - w[1] * R), res.steps, wall


CASES = {"stick": stick, "stick_stiff": stick_stiff, "onset": onset, "creep": creep, "hold": hold}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, type=Path)
    parser.add_argument("--quick", action="store_true", help="v_s = 1e-2, 1e-3 only")
    parser.add_argument("--cases", nargs="+", choices=list(CASES), default=list(CASES))
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    ladder = [1e-2, 1e-3] if args.quick else [1e-2, 3e-3, 1e-3, 3e-4, 1e-4]
    rows = []
    for name in args.cases:
        case = CASES[name]
        previous = None
        for v_s in ladder:
            error, steps, wall = case(v_s)
            order = (
                math.log(previous[1] / error) / math.log(previous[0] / v_s)
                if previous and error > 0
                else math.nan
            )
            rows.append((name, v_s, error, order, steps, wall))
            print(f"{name} v_s={v_s:g}: error {error:.3e} order {order:.2f} steps {steps} "
                  f"{wall:.1f} s", flush=True)  # fmt: skip
            previous = (v_s, error)
    with (args.out / "convergence.csv").open("w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["case", "stiction_velocity", "error", "order", "steps", "wall_s"])
        w.writerows(rows)
    lines = ["| case | v_s (m/s) | error | order | steps | wall (s) |", "|---|---|---|---|---|---|"]
    for name, v_s, error, order, steps, wall in rows:
        lines.append(f"| {name} | {v_s:g} | {error:.2e} | {order:.2f} | {steps} | {wall:.1f} |")
    (args.out / "table.md").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
