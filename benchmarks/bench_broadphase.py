"""The stream solver's broad phase against particle count: the cell grid against brute force.

    python benchmarks/bench_broadphase.py --out DIR [--quick]

Reproduces the broad-phase row of docs/streams.md ("The parts, measured"). Scene: N balls with
radii uniform in 10-40 mm (the reference stream's), uniform in a cube whose side grows as
N^(1/3) so that the solids fraction stays at ~8 % (a dilute release zone), speed bounds
uniform in 0-6 m/s, horizon 1 ms. For each N: the wall time of ``candidate_pairs`` (best of 3)
and, the baseline in the same run, of ``candidate_pairs_brute_force`` (the O(N^2) search, up
to N = 16000), the number of candidate pairs, and whether both sets are identical (they must
be: the grid's error is 0 by construction, checked here). Fitted exponent: the slope of
log(time) against log(N). ``--quick``: N up to 8000.

Writes DIR/bench_broadphase.csv and DIR/table.md. Run single-threaded (OMP_NUM_THREADS=1).
"""

import argparse
import csv
import math
import time
from pathlib import Path

import numpy as np

from tailbeam.solvers.stream.driver.broadphase import candidate_pairs, candidate_pairs_brute_force

SOLIDS_FRACTION = 0.08
HORIZON = 1e-3
BRUTE_MAX = 16000


def scene(n, seed=0):
    rng = np.random.default_rng(seed)
    r = rng.uniform(0.01, 0.04, n)
    side = (np.sum(4.0 / 3.0 * math.pi * r**3) / SOLIDS_FRACTION) ** (1.0 / 3.0)
    return rng.uniform(0.0, side, (n, 3)), r, rng.uniform(0.0, 6.0, n)


def best_time(fun, repeat=3):
    best, out = math.inf, None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fun()
        best = min(best, time.perf_counter() - t)
    return best, out


def main(out_dir, quick=False):
    sizes = [1000, 2000, 4000, 8000] if quick else [1000, 2000, 4000, 8000, 16000, 32000, 64000]
    rows = []
    for n in sizes:
        x, r, s = scene(n)
        t_grid, grid = best_time(lambda x=x, r=r, s=s: candidate_pairs(x, r, s, HORIZON))
        t_brute, same = math.nan, ""
        if n <= BRUTE_MAX:
            t_brute, brute = best_time(
                lambda x=x, r=r, s=s: candidate_pairs_brute_force(x, r, s, HORIZON), repeat=1
            )
            same = bool(np.array_equal(grid, brute))
            if not same:
                raise SystemExit(f"N = {n}: grid and brute force differ (a bug)")
        rows.append({"N": n, "pairs": len(grid), "grid_s": t_grid, "brute_s": t_brute,
                     "identical": same})  # fmt: skip
        print(f"N={n:6d} pairs={len(grid):7d} grid {t_grid * 1e3:8.2f} ms "
              f"brute {t_brute * 1e3:9.1f} ms identical={same}", flush=True)  # fmt: skip
    logn = np.log([row["N"] for row in rows])
    slope = float(np.polyfit(logn, np.log([row["grid_s"] for row in rows]), 1)[0])
    brute_rows = [row for row in rows if not math.isnan(row["brute_s"])]
    slope_b = float(np.polyfit(np.log([row["N"] for row in brute_rows]),
                               np.log([row["brute_s"] for row in brute_rows]), 1)[0])  # fmt: skip
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "bench_broadphase.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    lines = ["| N | candidate pairs | grid (ms) | brute force (ms) | identical |",
             "|---|---|---|---|---|"]  # fmt: skip
    for row in rows:
        lines.append(f"| {row['N']} | {row['pairs']} | {row['grid_s'] * 1e3:.2f} | "
                     f"{row['brute_s'] * 1e3:.1f} | {row['identical']} |")  # fmt: skip
    lines.append(f"\nFitted exponent (time ~ N^p): grid p = {slope:.2f}, brute force p = "
                 f"{slope_b:.2f}.")  # fmt: skip
    (out / "table.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--quick", action="store_true", help="N up to 8000 only")
    args = parser.parse_args()
    main(args.out, args.quick)
