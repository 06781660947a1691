"""Which of the paper's claims hold over a grid of the contact settings it does not give.

    python benchmarks/claim_map.py --out DIR [--quick]

Reproduces the figure of docs/reproduction.md ("How fragile the claims are"). The paper gives
no damping c, penetration depth d or drop height. This study runs the three scenarios
(sections 4.1-4.3) at every point of a grid of (c, d, drop gap) and records which claims hold
(tailbeam.paper.claims); the defaults (tailbeam.scene) are grid points, the baseline the
others are read against. ``--quick``: a coarse grid (seconds). Writes to DIR:

- claim_map.csv: one row per grid point: c, d, gap, number of claims holding, 0/1 per claim;
- table.csv: per claim, the fraction of the grid where it holds, and of the defaults'
  neighbourhood (c within x/÷1.5, d within x/÷2, gap <= 10 mm);
- table.md: the same as a markdown table;
- claim_map.png: one panel per drop gap, the number of claims holding over (c, d).
"""

import argparse
import csv
import math
import time
from pathlib import Path

import numpy as np

from tailbeam.errors import WorkLimitError
from tailbeam.paper import claims as claims_mod
from tailbeam.paper.figures import claim_map_figure
from tailbeam.paper.scenarios import DROP_GAP, run_all
from tailbeam.scene import DEFAULT_DAMPING, DEFAULT_PENETRATION, ContactSettings

# Dense near the band where every claim holds, coarser far from it; the defaults are grid points.
DAMPINGS = (100, 125, 150, 175, 200, 225, 250, 275, 300, 325, 350, 375, 400, 450, 500, 600, 700)
DAMPINGS += (850, 1000, 1250, 1500, 2000, 2500, 3000, 4000, 5000)  # N s/m
PENETRATIONS = (1e-5, 1.5e-5, 2e-5, 3e-5, 5e-5, 7e-5, 1e-4, 1.5e-4, 2e-4, 3e-4, 5e-4, 7e-4, 1e-3)
GAPS = (0.0, 0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2)  # m
QUICK = (
    (100, 200, 250, 300, 350, 400, 600, 1500, 5000),
    (1e-5, 3e-5, 1e-4, 3e-4, 1e-3),
    (0.0, 0.005, 0.05),
)


def in_neighbourhood(c: float, d: float, gap: float) -> bool:
    """c within a factor 1.5 and d within a factor 2 of the defaults, drop gap 0-10 mm."""
    return (
        abs(math.log(c / DEFAULT_DAMPING)) <= math.log(1.5) + 1e-9
        and abs(math.log(d / DEFAULT_PENETRATION)) <= math.log(2.0) + 1e-9
        and gap <= 0.01 + 1e-12
    )


def evaluate_point(c, d, gap) -> dict:
    """claim id -> passed at (c, d, gap); a solver limit counts as failing every claim."""
    try:
        results = run_all(ContactSettings(damping=c, penetration=d), drop_gap=gap)
    except WorkLimitError:
        return {cid: False for cid in claims_mod.claim_ids()}
    return {cl.id: cl.passed for cl in claims_mod.evaluate(results)}


def main(out_dir, quick=False):
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    dampings, penetrations, gaps = QUICK if quick else (DAMPINGS, PENETRATIONS, GAPS)
    ids = claims_mod.claim_ids()
    count = np.zeros((len(gaps), len(dampings), len(penetrations)), dtype=int)
    rows = []
    start = time.perf_counter()
    for g, gap in enumerate(gaps):
        for i, c in enumerate(dampings):
            for j, d in enumerate(penetrations):
                passed = evaluate_point(c, d, gap)
                count[g, i, j] = sum(passed.values())
                rows.append((c, d, gap, count[g, i, j], *(int(passed[k]) for k in ids)))
    elapsed = time.perf_counter() - start

    with open(out / "claim_map.csv", "w", newline="") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(["damping", "penetration", "drop_gap", "n_pass", *ids])
        w.writerows(rows)

    near = [r for r in rows if in_neighbourhood(r[0], r[1], r[2])]
    table = []
    for k, cid in enumerate(ids):
        col = 4 + k
        frac_all = sum(r[col] for r in rows) / len(rows)
        frac_near = sum(r[col] for r in near) / len(near) if near else math.nan
        table.append((cid, frac_all, frac_near))
    all_hold = sum(r[3] == len(ids) for r in rows) / len(rows)
    all_near = sum(r[3] == len(ids) for r in near) / len(near) if near else math.nan
    table.append(("ALL claims at once", all_hold, all_near))

    with open(out / "table.csv", "w", newline="") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(["claim", "fraction_of_grid", "fraction_near_defaults"])
        w.writerows((cid, repr(a), repr(b)) for cid, a, b in table)
    md = [
        f"Claims over {len(rows)} grid points (c in {min(dampings)}-{max(dampings)} N s/m, "
        f"d in {min(penetrations):g}-{max(penetrations):g} m, drop gap "
        f"{min(gaps) * 1000:g}-{max(gaps) * 1000:g} mm); neighbourhood of the defaults "
        f"(c = {DEFAULT_DAMPING:g} N s/m x/÷ 1.5, d = {DEFAULT_PENETRATION:g} m x/÷ 2, "
        "gap <= 10 mm): "
        f"{len(near)} points. Run time {elapsed:.0f} s.",
        "",
        "| claim | holds on fraction of grid | near the defaults |",
        "|---|---|---|",
    ]
    md += [f"| {cid} | {a:.2f} | {b:.2f} |" for cid, a, b in table]
    (out / "table.md").write_text("\n".join(md) + "\n")
    claim_map_figure(
        out / "claim_map.png",
        gaps,
        dampings,
        penetrations,
        count,
        len(ids),
        defaults=(DEFAULT_DAMPING, DEFAULT_PENETRATION, DROP_GAP),
    )
    print("\n".join(md))
    return table


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--quick", action="store_true", help="a coarse grid, seconds")
    args = parser.parse_args()
    main(args.out, quick=args.quick)
