"""The reference caving stream on the example tail beam against the same stream on the flat
plate at the same band: process CPU time and peak memory of each run, and their ratio.

    python benchmarks/bench_beam_stream.py --out DIR [--duration 6] [--stop 5] [--skip-flat]
        [--vtk-rate HZ]

Beam: examples/tail_beam_stream.toml (the ribbed beam of meshes/tail_beam.msh, its modes to
2 kHz, the lumps released over its upper half). Flat plate: examples/caving_stream.toml (the
0.6 x 0.6 x 0.01 m SSSS plate, its own release area) at the beam's band: plate.fmax and the
sensors' bandwidth 2 kHz, plate.tail "quasi-static" (what "auto" chooses on the beam). Both
keep the stream itself (1000 lumps at 200 per second, radii, heights, seed). ``--duration``
and ``--stop`` shorten both (a prefix of the same stream). Each run is ``tailbeam simulate``
in a fresh process; its CPU time (user + system) and peak resident memory come from the
operating system (``os.wait4``), so a shared machine's load changes the wall time, not
these. The beam's basis, face compliance and its sensors' static influences are read from the
cache when warmed before (the first run solves them: run this twice to time the stream).

Writes DIR/beam.toml, DIR/flat.toml, each run's output folder, DIR/bench_beam_stream.csv and
DIR/table.md.
"""

import argparse
import csv
import os
import re
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
BEAM = ROOT / "examples" / "tail_beam_stream.toml"
FLAT = ROOT / "examples" / "caving_stream.toml"
BAND = 2000.0  # Hz: the beam's plate.fmax


def beam_scene(duration: float, stop: float) -> str:
    text = BEAM.read_text()
    text = text.replace('"../meshes/tail_beam.msh"', repr(str(ROOT / "meshes" / "tail_beam.msh")))
    return _shorten(text, duration, stop)


def flat_scene(duration: float, stop: float) -> str:
    text = FLAT.read_text()
    text = re.sub(r"(?m)^fmax = .*$", f'fmax = {BAND}\ntail = "quasi-static"', text)
    text = re.sub(r"(?m)^bandwidth = .*$", f"bandwidth = {BAND}", text)
    return _shorten(text, duration, stop)


def _shorten(text: str, duration: float, stop: float) -> str:
    text = re.sub(r"(?m)^duration = .*$", f"duration = {duration}", text)
    return re.sub(r"(?m)^stop = .*$", f"stop = {stop}", text)


def run(scene: Path, out: Path, extra=()) -> dict:
    """``tailbeam simulate scene --out out`` in a child process: its CPU s, peak GB, wall s."""
    cmd = [sys.executable, "-m", "tailbeam", "simulate", str(scene), "--out", str(out), *extra]
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    start = time.perf_counter()
    with open(out.with_suffix(".log"), "w") as log:
        child = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, env=env)
        _, status, usage = os.wait4(child.pid, 0)
    wall = time.perf_counter() - start
    if os.waitstatus_to_exitcode(status):
        raise RuntimeError(f"{' '.join(cmd)} failed; see {out.with_suffix('.log')}")
    return {
        "cpu_s": round(usage.ru_utime + usage.ru_stime, 1),
        "peak_gb": round(usage.ru_maxrss / 1024**2, 2),
        "wall_s": round(wall, 1),
        "impacts": _count_rows(out / "impacts.csv"),
    }


def _count_rows(path: Path) -> int | None:
    if not path.is_file():
        return None
    with open(path) as fh:
        return max(sum(1 for _ in fh) - 1, 0)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--duration", type=float, default=6.0, help="s simulated")
    parser.add_argument("--stop", type=float, default=5.0, help="s: the stream's last release")
    parser.add_argument("--skip-flat", action="store_true")
    parser.add_argument("--vtk-rate", type=float, default=None,
                        help="also write the beam's ParaView series at this rate (Hz)")  # fmt: skip
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    rows = []
    cases = [("beam", beam_scene)] + ([] if args.skip_flat else [("flat", flat_scene)])
    for name, make in cases:
        scene = args.out / f"{name}.toml"
        scene.write_text(make(args.duration, args.stop))
        extra = (
            ("--vtk", "--vtk-rate", str(args.vtk_rate)) if args.vtk_rate and name == "beam" else ()
        )
        row = {"case": name, "duration_s": args.duration, "stop_s": args.stop,
               **run(scene, args.out / name, extra)}  # fmt: skip
        print(row, flush=True)
        rows.append(row)
    with open(args.out / "bench_beam_stream.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    lines = [
        "| case | simulated s | impacts | CPU s | peak GB | wall s |",
        "|---|---|---|---|---|---|",
    ]
    lines += [f"| {r['case']} | {r['duration_s']} | {r['impacts']} | {r['cpu_s']} | "
              f"{r['peak_gb']} | {r['wall_s']} |" for r in rows]  # fmt: skip
    if len(rows) == 2:
        lines.append(f"\nbeam / flat CPU: {rows[0]['cpu_s'] / rows[1]['cpu_s']:.2f}")
    (args.out / "table.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
