"""The command line's start: what importing tailbeam and starting a command cost, in fresh
processes, for this tree and (``--tree PATH``) others side by side.

    python benchmarks/bench_startup.py --out DIR [--tree PATH ...] [--runs 5] [--cache FOLDER]

For each tree (this one first, then each ``--tree``, a folder holding a ``tailbeam`` package,
for example ``git archive REV tailbeam | tar -x -C PATH``), ``--runs`` rounds, the trees
taking turns within a round so that both see the same load:

- ``import tailbeam``: the process' CPU time (user + system, the operating system's count for
  the child) and the modules it holds afterwards;
- the same import under ``python -X importtime``: Python's own count of the import's time
  (microseconds of wall time, the package and what it pulls in);
- ``tailbeam --help``: CPU time and the modules held once the parser is built (that count in
  a separate ``-c`` run that builds the parser);
- ``tailbeam modes SCENE --fmax FMAX`` (``--scene``, the example tail beam's scene, 5 kHz) with
  the basis read from ``--cache`` (``TAILBEAM_CACHE_DIR``; default the user's cache, which
  must already hold that basis: the run reports whether it read the cache, and a cold solve
  would take minutes): CPU and wall time.

Each row carries the 1-minute load average (mean of its start and end). Writes DIR/runs.csv
(every run) and DIR/table.md (per tree and measure: median, min and max). Single-threaded BLAS
(OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1), as the other benchmarks.
"""

import argparse
import csv
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

COUNT_MODULES = "import sys; {code}; print('MODULES', len(sys.modules))"
PARSER = "from tailbeam.cli.main import build_parser; build_parser()"


def child_cpu() -> float:
    """CPU time (user + system, s) of this process' finished children so far."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def run(tree: Path, args: list, cache) -> dict:
    """One fresh ``python ARGS`` with ``tree`` first on the path: CPU, wall, stdout, stderr."""
    env = {**os.environ, "PYTHONPATH": str(tree), "OMP_NUM_THREADS": "1",
           "OPENBLAS_NUM_THREADS": "1"}  # fmt: skip
    if cache is not None:
        env["TAILBEAM_CACHE_DIR"] = str(cache)
    load, cpu0, w = os.getloadavg()[0], child_cpu(), time.perf_counter()
    done = subprocess.run([sys.executable, *args], env=env, capture_output=True, text=True,
                          cwd=tree)  # fmt: skip
    wall, cpu = time.perf_counter() - w, child_cpu() - cpu0
    if done.returncode:
        raise SystemExit(f"{tree}: python {' '.join(args)} failed:\n{done.stderr}")
    return {"cpu_s": cpu, "wall_s": wall, "load_average_1min": (load + os.getloadavg()[0]) / 2,
            "stdout": done.stdout, "stderr": done.stderr}  # fmt: skip


def modules(out: str) -> int:
    return int(re.search(r"^MODULES (\d+)$", out, re.M).group(1))


def importtime_s(stderr: str, module: str = "tailbeam") -> float:
    """The cumulative import time of ``module`` (s) in ``python -X importtime``'s report."""
    pattern = rf"^import time:\s+\d+ \|\s+(\d+) \|\s*{re.escape(module)}$"
    return int(re.search(pattern, stderr, re.M).group(1)) / 1e6


def one_round(tree: Path, scene: Path, fmax: float, cache, tmp: Path) -> list:
    """The four measures on ``tree`` (module docstring), one row each."""
    rows = []
    r = run(tree, ["-c", COUNT_MODULES.format(code="import tailbeam")], cache)
    rows.append(("import tailbeam", r, {"modules": modules(r["stdout"])}))
    r = run(tree, ["-X", "importtime", "-c", "import tailbeam"], cache)
    rows.append(("import tailbeam, -X importtime", r, {"importtime_s": importtime_s(r["stderr"])}))
    count = modules(run(tree, ["-c", COUNT_MODULES.format(code=PARSER)], cache)["stdout"])
    r = run(tree, ["-m", "tailbeam", "--help"], cache)
    rows.append(("tailbeam --help", r, {"modules": count}))
    out = tmp / f"modes-{len(list(tmp.iterdir()))}"
    r = run(tree, ["-m", "tailbeam", "modes", str(scene), "--fmax", str(fmax), "--out", str(out)],
            cache)  # fmt: skip
    first = (r["stdout"].splitlines() or [""])[0]
    rows.append((f"tailbeam modes --fmax {fmax:g}", r, {"cache_hit": first.endswith("cache hit")}))
    return [{"tree": str(tree), "measure": name, "cpu_s": r["cpu_s"], "wall_s": r["wall_s"],
             "load_average_1min": r["load_average_1min"], **extra}
            for name, r, extra in rows]  # fmt: skip


def summary(rows: list) -> list:
    """Per tree and measure: median (min-max) of the CPU and wall times, the import time and
    the module count, and the load's range."""
    out = []
    keys = dict.fromkeys((r["tree"], r["measure"]) for r in rows)
    for tree, measure in keys:
        mine = [r for r in rows if r["tree"] == tree and r["measure"] == measure]
        row = {"tree": tree, "measure": measure, "runs": len(mine)}
        for key in ("cpu_s", "wall_s", "importtime_s", "modules"):
            values = [r[key] for r in mine if r.get(key) not in (None, "")]
            if values:
                f = "d" if key == "modules" else ".3g"
                mid = (
                    statistics.median_low(values) if key == "modules" else statistics.median(values)
                )
                row[key] = f"{mid:{f}} ({min(values):{f}}-{max(values):{f}})"
        loads = [r["load_average_1min"] for r in mine]
        row["load_average_1min"] = f"{min(loads):.1f}-{max(loads):.1f}"
        if any("cache_hit" in r for r in mine):
            row["cache_hit"] = all(r.get("cache_hit") for r in mine)
        out.append(row)
    return out


def table(rows: list) -> str:
    keys = list(dict.fromkeys(k for r in rows for k in r))
    lines = ["| " + " | ".join(keys) + " |", "|" + "---|" * len(keys)]
    lines += ["| " + " | ".join(str(r.get(k, "")) for k in keys) + " |" for r in rows]
    return "\n".join(lines)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, required=True, help="output folder")
    parser.add_argument("--tree", type=Path, action="append", default=[],
                        help="another tree to measure beside this one (repeatable)")  # fmt: skip
    parser.add_argument("--runs", type=int, default=5, help="rounds over the trees")
    parser.add_argument("--scene", type=Path, default=ROOT / "examples" / "tail_beam_stream.toml")
    parser.add_argument("--fmax", type=float, default=5000.0, help="the modes' band, Hz")
    parser.add_argument(
        "--cache",
        type=Path,
        default=None,
        help="TAILBEAM_CACHE_DIR holding the basis (default: the user's cache)",
    )
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    trees = [ROOT, *(t.resolve() for t in args.tree)]
    rows = []
    with tempfile.TemporaryDirectory(prefix="tailbeam-bench-startup-") as tmp:
        for _ in range(args.runs):
            for tree in trees:
                rows += one_round(tree, args.scene.resolve(), args.fmax, args.cache, Path(tmp))
                print(*(f"{r['measure']}: {r['cpu_s']:.2f} s CPU" for r in rows[-4:]),
                      sep="; ", flush=True)  # fmt: skip
    keys = list(dict.fromkeys(k for r in rows for k in r))
    with open(args.out / "runs.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=keys)
        writer.writeheader()
        writer.writerows(rows)
    text = table(summary(rows))
    (args.out / "table.md").write_text("## Start-up, fresh processes\n\n" + text + "\n")
    print(text)


if __name__ == "__main__":
    main()
