"""The speed-against-error report of the three core solvers in one command.

    python benchmarks/run_all.py --out DIR [--quick]

Runs ``bench_rigid`` (docs/rigid-solver.md), ``bench_modes`` (docs/plate-modes.md) and
``bench_coupled`` (docs/coupled-and-sensors.md), each ``main(out_dir, quick=...)`` into its
own subfolder of DIR (default ``out/benchmarks``), and gathers their tables into
``DIR/report.md``. ``--quick`` runs each benchmark's quick version (a few minutes in all).
"""

import argparse
import importlib.util
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
BENCHMARKS = ["bench_rigid", "bench_modes", "bench_coupled"]


def _load(name: str):
    spec = importlib.util.spec_from_file_location(name, HERE / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def main(out_dir="out/benchmarks", quick: bool = False) -> Path:
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    sections = ["# tailbeam speed-vs-error report\n"]
    for name in BENCHMARKS:
        sub = out_dir / name
        sub.mkdir(exist_ok=True)
        t0 = time.perf_counter()
        _load(name).main(sub, quick=quick)
        wall = time.perf_counter() - t0
        table = sub / "table.md"
        body = table.read_text() if table.exists() else "(no table written)"
        sections.append(f"## {name}\n\n(run time {wall:.1f} s; files in `{sub}`)\n\n{body}\n")
        print(f"{name}: {wall:.1f} s", file=sys.stderr)
    report = out_dir / "report.md"
    report.write_text("\n".join(sections))
    return report


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/benchmarks", help="output folder")
    parser.add_argument("--quick", action="store_true", help="each benchmark's quick version")
    args = parser.parse_args()
    print(main(args.out, quick=args.quick))
