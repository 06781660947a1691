"""The stream solver's compiled active set: cost per contact against error, and per step
against the number of balls.

    python benchmarks/bench_active_set.py --out DIR [--quick]

Reproduces the active-set rows of docs/streams.md ("The parts, measured").

1. Per contact: an isolated coal ball (30 mm) striking the plate at 2 m/s, c = 0, g = 0, so
   the Hertz closed form (tailbeam.physics.hertz) is the truth. For rtol 1e-8, 1e-10, 1e-12:
   wall time per contact (best of 5 x 50 contacts) and the worst relative error of peak
   force, duration, max penetration and v_out of ``ActiveSet.advance`` from contact start to
   end (one Python call), and, the baseline in the same run, of the rigid solver's contact
   integrator (``tailbeam.solvers.rigid.solver._KernelIntegrator``: its compiled 1-D DOP853
   kernel on the penetration ODE with its thin Python wrapper). Steps and right-hand-side
   evaluations per contact too. The active set integrates the ball's 3-D state (6
   components) and watches 1 pair and 4 edges, the rigid kernel a 2-component ODE: its cost
   per step is the floor.
2. Per step against n: n balls resting on a 15 deg plate (``resting_set``), all n plate
   pairs touching, plus either the n - 1 neighbour ball-ball pairs (P = 2n - 1: the stream
   driver's case) or all n (n - 1) / 2 ball-ball pairs (the O(P) term). Time per accepted
   step (best of 3 runs of 2 ms of simulated time) and the fitted exponent of time against n.

``--quick``: 2 repeats, n up to 32. Writes DIR/bench_active_set.csv,
DIR/bench_active_set_steps.csv and DIR/table.md. Run single-threaded (OMP_NUM_THREADS=1). The
first run compiles the kernels (not timed).
"""

import argparse
import csv
import math
import time
from pathlib import Path

import numpy as np

from tailbeam import CARBON_STEEL, COAL, Ball, ImpactLaw, Plate, ball_plate_law
from tailbeam.physics.hertz import hertz_contact_duration, hertz_max_penetration, hertz_peak_force
from tailbeam.physics.incline import InclinedPlate
from tailbeam.results.records import EventCode
from tailbeam.solvers.rigid.model import make_pairs
from tailbeam.solvers.rigid.solver import _KernelIntegrator
from tailbeam.solvers.stream.active.integrator.set import ActiveSet

RADIUS, SPEED = 0.03, 2.0


def _truth(ball, k):
    return {
        "peak": hertz_peak_force(ball.mass, SPEED, k),
        "duration": hertz_contact_duration(ball.mass, SPEED, k),
        "pen": hertz_max_penetration(ball.mass, SPEED, k),
        "v_out": SPEED,
    }


def _error(values, truth):
    return max(abs(values[name] / truth[name] - 1.0) for name in truth)


def active_contact(ball, law, rtol, repeat):
    """Seconds per contact (START -> END only), error values, steps and nfev per contact."""
    best, values, stats = math.inf, None, None
    for _ in range(repeat):
        sets = []
        for _ in range(50):
            s = ActiveSet([ball.position], [ball.velocity], [ball.mass], [RADIUS], [(0, -1)],
                          [law], (0.0, 0.0, 0.0), (0.3, 0.3), rtol=rtol)  # fmt: skip
            start = s.advance(0.0, 1.0)
            s.io.reset_stats()  # count the contact's work only
            sets.append((s, start))
        t0 = time.perf_counter()
        ends = [s.advance(start.t, 1.0) for s, start in sets]
        best = min(best, (time.perf_counter() - t0) / len(sets))
        s, start = sets[0]
        values = {"peak": s.contacts.peak[0], "duration": ends[0].t - start.t,
                  "pen": s.contacts.pen[0], "v_out": s.v[0, 2]}  # fmt: skip
        stats = s.stats
    return best, values, stats


def rigid_contact(ball, law, rtol, repeat):
    (pair,) = make_pairs([ball], Plate(), [law], 1.0, gravity=0.0, rest_speed=0.0,
                         max_contacts=10, max_steps=100_000)  # fmt: skip
    best, out = math.inf, None
    for _ in range(repeat):
        integrator = _KernelIntegrator(rtol)
        t0 = time.perf_counter()
        for _ in range(50):
            out = integrator(pair, SPEED, 1.0, 100_000)
        best = min(best, (time.perf_counter() - t0) / 50)
    values = {"peak": out.peak_force, "duration": out.tau_end, "pen": out.max_penetration,
              "v_out": out.v_out}  # fmt: skip
    return best, values, {"steps": out.n_steps, "nfev": out.nfev}


def per_contact(quick):
    k = ball_plate_law(COAL, RADIUS, CARBON_STEEL).stiffness
    law = ImpactLaw(k, 1.5, damping=0.0)
    ball = Ball("A", COAL, RADIUS, (0.0, 0.0, RADIUS + 1e-4), (0.0, 0.0, -SPEED))
    truth = _truth(ball, k)
    active_contact(ball, law, 1e-10, 1)  # compile
    rigid_contact(ball, law, 1e-10, 1)
    rows = []
    for rtol in (1e-8, 1e-10, 1e-12):
        for name, fun in (("active set", active_contact), ("rigid kernel", rigid_contact)):
            sec, values, stats = fun(ball, law, rtol, 2 if quick else 5)
            rows.append({"solver": name, "rtol": rtol, "us_per_contact": sec * 1e6,
                         "max_rel_error": _error(values, truth), "steps": stats["steps"],
                         "nfev": stats["nfev"]})  # fmt: skip
            error = rows[-1]["max_rel_error"]
            print(f"{name:12s} rtol {rtol:.0e}: {sec * 1e6:8.1f} us/contact, error "
                  f"{error:.1e}, {stats['steps']} steps", flush=True)  # fmt: skip
    return rows


def resting_set(n, all_pairs):
    """n coal balls at rest on a 15 deg plate (static penetration, vz = -0.1 mm/s so that
    the contacts work), on an 8 x 8 grid 70 mm apart (no two touch); pairs: the plate pairs
    and the neighbours in grid order, or all ball-ball pairs."""
    incline = InclinedPlate(inclination=15.0)
    law = ball_plate_law(COAL, RADIUS, CARBON_STEEL)
    gn = incline.gravity * math.cos(math.radians(15.0))
    z = RADIUS - law.static_penetration(Ball("p", COAL, RADIUS, (0, 0, 1.0)).mass * gn)
    balls, pairs = [], []
    for b in range(n):
        x, y = -0.245 + 0.07 * (b % 8), -0.245 + 0.07 * (b // 8)
        balls.append(Ball(f"b{b}", COAL, RADIUS, (x, y, z), (0.0, 0.0, -1e-4)))
        pairs.append((b, -1))
    for i in range(n):
        for j in range(i + 1, n if all_pairs else min(i + 2, n)):
            pairs.append((i, j))
    return ActiveSet.from_balls(balls, pairs, incline, rtol=1e-10), len(pairs)


def per_step(quick):
    sizes = [1, 2, 4, 8, 16, 32] if quick else [1, 2, 4, 8, 16, 32, 64]
    rows = []
    resting_set(2, True)[0].advance(0.0, 1e-4)  # compile
    for all_pairs in (False, True):
        for n in sizes:
            best, steps = math.inf, 0
            for _ in range(3):
                s, p = resting_set(n, all_pairs)
                t0 = time.perf_counter()
                out = s.advance(0.0, 2e-3)
                best = min(best, time.perf_counter() - t0)
                steps = s.stats["steps"]
                assert out.code == EventCode.NONE, out
            rows.append({"n": n, "pairs": p, "all_pairs": all_pairs, "steps": steps,
                         "us_per_step": best / steps * 1e6})  # fmt: skip
            print(f"n={n:3d} P={p:5d} steps={steps:4d} {best / steps * 1e6:8.1f} us/step",
                  flush=True)  # fmt: skip
    return rows


def _slope(rows):
    return float(np.polyfit(np.log([r["n"] for r in rows]),
                            np.log([r["us_per_step"] for r in rows]), 1)[0])  # fmt: skip


def main(out_dir, quick=False):
    contact_rows = per_contact(quick)
    step_rows = per_step(quick)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    for name, rows in (("bench_active_set.csv", contact_rows),
                       ("bench_active_set_steps.csv", step_rows)):  # fmt: skip
        with open(out / name, "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)
    lines = ["| solver | rtol | us / contact | max rel. error vs Hertz | steps | nfev |",
             "|---|---|---|---|---|---|"]  # fmt: skip
    for r in contact_rows:
        lines.append(f"| {r['solver']} | {r['rtol']:.0e} | {r['us_per_contact']:.1f} | "
                     f"{r['max_rel_error']:.1e} | {r['steps']} | {r['nfev']} |")  # fmt: skip
    lines += ["", "| n | pairs | steps | us / step |", "|---|---|---|---|"]
    for r in step_rows:
        lines.append(f"| {r['n']} | {r['pairs']} | {r['steps']} | {r['us_per_step']:.1f} |")
    near = [r for r in step_rows if not r["all_pairs"]]
    full = [r for r in step_rows if r["all_pairs"]]
    lines.append(f"\nFitted exponent (time per step ~ n^p): neighbour pairs p = "
                 f"{_slope(near):.2f}, all pairs p = {_slope(full):.2f}.")  # fmt: skip
    (out / "table.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--quick", action="store_true", help="fewer repeats, n up to 32")
    args = parser.parse_args()
    main(args.out, args.quick)
