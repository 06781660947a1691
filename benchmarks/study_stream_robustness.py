"""Do caving streams run to their end? Many random streams, each run once, tallied.

    python benchmarks/study_stream_robustness.py --out DIR [--quick] [--seeds N]
        [--plates rigid,modal]

The scene of study 2 of docs/datasets.md (a smaller ``examples/caving_stream.toml``): coal and
sandstone lumps of radius 10-40 mm (uniform), 100 per second (Poisson arrivals) over 3 s,
released 0.3-0.8 m above a 0.4 x 0.4 m area on the upper part of the 30-degree SSSS plate
(~300 particles), contact damping 300 N s/m, 3 s simulated, on the rigid plate and on the
modal plate with modes to 5 kHz (two-way, the default residual flexibility and contact tails,
one sensor at (0.1, 0) m sampled at 12.8 kHz). Seed k (1..N) sets the stream's seed and its
gangue fraction (uniform 0-0.5, drawn from k), so the cases are the kind of streams a sweep
draws.

Each case runs ``tailbeam.simulate`` in this process; a case that raises is recorded as
stopped with the error's type and its one-line message (a ``WorkLimitError`` "no progress"
is the stream solver's stall guard). One JSON line per case goes to DIR/cases.jsonl as soon
as the case ends (a rerun skips the cases already there); DIR/summary.md has the tally per
plate: finished, stopped and why, wall time, and the stream's delivery (particles released in
[start, stop], delivered rate, largest release delay).

``--quick``: seeds 1-4, 1 s of stream (~100 particles). Full: seeds 1-200 (``--seeds`` sets
N), ~20-40 min on 2 shared cores.
"""

import argparse
import json
import time
import traceback
from pathlib import Path

import numpy as np

RATE = 100.0  # particles per second
FULL = {"seeds": 200, "duration": 3.0}
QUICK = {"seeds": 4, "duration": 1.0}
PLATES = ("rigid", "modal")


def scene_table(seed: int, plate: str, duration: float) -> dict:
    """Study 2's stream scene with stream seed ``seed`` and a gangue fraction drawn from it."""
    gangue = float(np.random.default_rng(seed).uniform(0.0, 0.5))
    table = {
        "duration": duration,
        "contact": {"damping": 300.0, "penetration": 1e-4},
        "plate": {"model": "rigid", "inclination": 30.0},
        "streams": [
            {
                "name": "cave",
                "rate": RATE,
                "start": 0.0,
                "stop": duration,
                "gangue_fraction": gangue,
                "radius": [0.01, 0.04],
                "area": [[-0.3, 0.1], [-0.2, 0.2]],
                "height": [0.3, 0.8],
                "seed": seed,
            }
        ],
    }
    if plate == "modal":
        table["plate"] = {"model": "modal", "boundary": "SSSS", "inclination": 30.0,
                          "fmax": 5000.0}  # fmt: skip
        table["sensors"] = [
            {"name": "S1", "position": [0.1, 0.0], "sample_rate": 12800.0, "bandwidth": 5000.0}
        ]
    return table


def run_case(seed: int, plate: str, duration: float) -> dict:
    """Simulate one case; its outcome as a JSON-able row."""
    import tailbeam
    from tailbeam.io.scene_file import parse_scene

    row = {"plate": plate, "seed": seed}
    wall = time.perf_counter()
    try:
        scene = parse_scene(scene_table(seed, plate, duration))
        row["particles"] = len(scene.particles)
        result = tailbeam.simulate(scene, progress=False)
    except Exception as err:  # noqa: BLE001 - a stop of any kind is what this study counts
        row.update(outcome="stopped", error_type=type(err).__name__,
                   error=str(err).splitlines()[0] if str(err) else repr(err),
                   where=traceback.format_exc().strip().splitlines()[-3:])  # fmt: skip
    else:
        stats = result.stats
        row.update(outcome="finished", status=result.status, contacts=len(result.impacts),
                   rtol=stats.get("rtol"), late_starts=stats.get("late_starts"),
                   postponed_releases=stats.get("postponed_releases"),
                   release_delay_max=stats.get("release_delay_max"),
                   **{k: v for k, v in result.info.get("streams", {}).get("cave", {}).items()
                      if k in DELIVERY})  # fmt: skip
    row["wall_s"] = time.perf_counter() - wall
    return row


DELIVERY = ("drawn_in_window", "released_in_window", "delivered_rate", "delayed_releases",
            "moved_releases")  # fmt: skip


def _plain(value):
    """numpy scalars as Python numbers for JSON."""
    return value.item() if isinstance(value, np.generic) else str(value)


def done_cases(path: Path) -> set:
    """(plate, seed) of the cases already in ``path``."""
    if not path.exists():
        return set()
    rows = [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
    return {(r["plate"], r["seed"]) for r in rows}


def summary(rows: list, plates) -> str:
    """The tally per plate as a markdown table, and every stop."""
    head = ("plate", "cases", "finished", "stopped", "stops by reason",
            "wall time per case (median, max) s", "particles (median)",
            "delivered rate (median, min) /s", "largest release delay s")  # fmt: skip
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for plate in plates:
        mine = [r for r in rows if r["plate"] == plate]
        if not mine:
            continue
        fin = [r for r in mine if r["outcome"] == "finished"]
        stops = [r for r in mine if r["outcome"] != "finished"]
        reasons = {}
        for r in stops:
            key = f"{r['error_type']}: {r['error'][:60]}"
            reasons[key] = reasons.get(key, 0) + 1
        why = "; ".join(f"{n} x {k}" for k, n in sorted(reasons.items())) or "-"
        wall = [r["wall_s"] for r in mine]
        rate = [r["delivered_rate"] for r in fin if "delivered_rate" in r]
        delay = [r["release_delay_max"] for r in fin if "release_delay_max" in r]
        lines.append(
            f"| {plate} | {len(mine)} | {len(fin)} | {len(stops)} | {why} | "
            f"{np.median(wall):.2f}, {max(wall):.2f} | "
            f"{np.median([r.get('particles', 0) for r in mine]):.0f} | "
            + (f"{np.median(rate):.1f}, {min(rate):.1f}" if rate else "-")
            + " | "
            + (f"{max(delay):.3g}" if delay else "-")
            + " |"
        )
    stops = [r for r in rows if r["outcome"] != "finished"]
    lines += ["", "Stops:"] + [f"- {r['plate']} seed {r['seed']}: {r['error']}" for r in stops]
    return "\n".join(lines) + "\n"


def main(argv=None) -> list:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="folder for cases.jsonl and summary.md")
    parser.add_argument("--quick", action="store_true", help="seeds 1-4, 1 s of stream")
    parser.add_argument("--seeds", type=int, default=None, help="run seeds 1..N")
    parser.add_argument("--plates", default=",".join(PLATES), help="rigid,modal (default)")
    args = parser.parse_args(argv)
    mode = QUICK if args.quick else FULL
    n_seeds = args.seeds or mode["seeds"]
    plates = [p for p in args.plates.split(",") if p]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    path = out / "cases.jsonl"
    done = done_cases(path)
    for plate in plates:
        for seed in range(1, n_seeds + 1):
            if (plate, seed) in done:
                continue
            row = run_case(seed, plate, mode["duration"])
            with path.open("a") as fh:
                fh.write(json.dumps(row, default=_plain) + "\n")
            why = f": {row['error']}" if row["outcome"] != "finished" else ""
            print(f"{plate} seed {seed}: {row['outcome']} ({row['wall_s']:.1f} s){why}", flush=True)
    rows = [json.loads(line) for line in path.read_text().splitlines() if line.strip()]
    rows = [r for r in rows if r["plate"] in plates and r["seed"] <= n_seeds]
    text = summary(rows, plates)
    (out / "summary.md").write_text(text)
    print(text)
    return rows


if __name__ == "__main__":
    main()
