"""Convergence and cost of the slow stream reference against its tolerance.

    python benchmarks/bench_stream_reference.py --out DIR [--quick]

Reproduces the convergence figures of docs/streams.md ("The slow reference"). Scene: the
ten-ball scene of the tests (tests/stream_scenes.py: a 3-ball cluster, a ball resting on the
15 degree plate hit by another, two mid-air collisions, one free fall), c = 2000 N s/m,
d = 2e-5 m, 0.1 s (``--quick``: 0.06 s). Truth: the same reference at rtol 1e-13, in the same
run. For rtol 1e-7 ... 1e-12: wall time, steps, and the largest relative error over every
contact's peak force, v_out (relative to max(|v_out|, approach speed): a ball left at rest has
v_out ~ 0) and duration, with the contacts matched by (ball, partner, n-th contact of that
pair). The measured order is the slope of log(error) against log(rtol).

Writes DIR/bench_stream_reference.csv and DIR/table.md.
"""

import argparse
import csv
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from stream_scenes import ten_ball_scene  # noqa: E402

from tailbeam.physics.incline import InclinedPlate  # noqa: E402
from tailbeam.solvers.stream.reference.solver import simulate_stream_reference  # noqa: E402

INCLINE = InclinedPlate(inclination=15.0)


def run(rtol, duration):
    t = time.perf_counter()
    res = simulate_stream_reference(ten_ball_scene(INCLINE), INCLINE, duration, rtol=rtol,
                                    damping=2000.0, penetration=2e-5)  # fmt: skip
    return res, time.perf_counter() - t


def _by_key(res):
    """Contacts keyed by (ball, partner, n-th contact of that pair)."""
    seen, out = {}, {}
    for c in res.contacts:
        n = seen[(c.ball, c.partner)] = seen.get((c.ball, c.partner), 0) + 1
        out[(c.ball, c.partner, n)] = c
    return out


def error(res, truth):
    ours, ref = _by_key(res), _by_key(truth)
    if set(ours) != set(ref):
        return float("inf")  # a different set of contacts
    worst = 0.0
    for key, b in ref.items():
        a = ours[key]
        for x, y, scale in ((a.peak_force, b.peak_force, 0.0),
                            (a.v_out, b.v_out, b.approach_in),
                            (a.t_end - a.t_start, b.t_end - b.t_start, 0.0)):  # fmt: skip
            if np.isfinite(y) and max(abs(y), scale) > 0.0:
                worst = max(worst, abs(x - y) / max(abs(y), scale))
    return worst


def main(out_dir, quick=False):
    duration = 0.06 if quick else 0.1
    truth, t_truth = run(1e-13, duration)
    print(f"truth rtol 1e-13: {t_truth:.1f} s, {truth.steps} steps, "
          f"{len(truth.contacts)} contact records", flush=True)  # fmt: skip
    rows = []
    for rtol in (1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12):
        res, wall = run(rtol, duration)
        rows.append({"rtol": rtol, "wall_s": wall, "steps": res.steps,
                     "max_rel_error": error(res, truth)})  # fmt: skip
        print(rows[-1], flush=True)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "bench_stream_reference.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    lines = [f"Ten-ball scene, {duration:g} s; truth: rtol 1e-13 ({truth.steps} steps, "
             f"{t_truth:.1f} s, {len(truth.contacts)} contact records).", "",
             "| rtol | wall (s) | steps | max rel. error |", "|---|---|---|---|"]  # fmt: skip
    for r in rows:
        lines.append(f"| {r['rtol']:g} | {r['wall_s']:.2f} | {r['steps']} | "
                     f"{r['max_rel_error']:.2e} |")  # fmt: skip
    ok = [(r["rtol"], r["max_rel_error"]) for r in rows
          if np.isfinite(r["max_rel_error"]) and r["max_rel_error"] > 0]  # fmt: skip
    if len(ok) >= 2:
        slope = np.polyfit(np.log([r for r, _ in ok]), np.log([e for _, e in ok]), 1)[0]
        lines.append(f"\nMeasured order: error ~ rtol^{slope:.2f}")
    (out / "table.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--quick", action="store_true", help="0.06 s instead of 0.1 s")
    args = parser.parse_args()
    main(args.out, args.quick)
