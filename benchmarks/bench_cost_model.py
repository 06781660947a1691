"""The run cost model (tailbeam.solvers.cost, run_cost) against measured wall times.

    OMP_NUM_THREADS=1 python benchmarks/bench_cost_model.py --out DIR [--only NAME ...]

For each scene of a spread (single balls and grids, streams, rigid and modal plates, bands
2-40 kHz, light and heavy sensors) the estimate is taken first (``estimate_run``, as
``tailbeam simulate`` prints it), then every part is timed on its own: the plate set-up (the
eigen-solves of the band and the contact tails; a basis in the user's cache counts as cached,
as it does for a user), the solver's run, the sensor replay and writing the outputs. The
compiled kernels are warmed up first (their one-time compilation is not in the model).
Peak memory is the process's maximum resident size after the scene (ru_maxrss; each scene in
its own process), against the estimate's largest part.

Writes DIR/cost_model.csv (per scene and part: estimated and measured seconds, their ratio)
and prints the table of docs/band-and-cost.md. ~10-15 min on the 2-core machine when the
bases to 40 kHz are cached (an uncached 40 kHz solve adds 3-10 min).
"""

import argparse
import csv
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE.parent / "examples"


def _grid(n_side_x, n_side_y, duration, fmax=None, rigid=False, sensors=(), pitch=0.1):
    """A grid of coal and sandstone balls, radii 10-40 mm, 3 m/s, none touching."""
    lines = [f"duration = {duration}", "sample_rate = 10000.0", "", "[plate]"]
    lines.append('model = "rigid"' if rigid else 'model = "modal"')
    if fmax:
        lines.append(f"fmax = {fmax}")
    k = 0
    for i in range(n_side_x):
        for j in range(n_side_y):
            k += 1
            mat = "coal" if k % 2 else "sandstone"
            r = 0.01 + 0.005 * (k % 7)
            x = (i - (n_side_x - 1) / 2) * pitch
            y = (j - (n_side_y - 1) / 2) * pitch
            z = r + 0.002 + 0.004 * (k % 5)
            lines += ["", "[[balls]]", f'name = "{mat}_{k:02d}"', f'material = "{mat}"',
                      f"radius = {r}", f"position = [{x:.3f}, {y:.3f}, {z:.4f}]",
                      "velocity = [0.0, 0.0, -3.0]"]  # fmt: skip
    for name, pos, rate, bw in sensors:
        lines += ["", "[[sensors]]", f'name = "{name}"', f"position = [{pos[0]}, {pos[1]}]",
                  f"sample_rate = {rate}"] + ([f"bandwidth = {bw}"] if bw else [])  # fmt: skip
    return "\n".join(lines) + "\n"


def _with(path, old, new):
    text = (EXAMPLES / path).read_text()
    for a, b in zip(old, new, strict=True):
        assert a in text, (path, a)
        text = text.replace(a, b, 1)
    return text


SENSOR = ("acc", (0.05, 0.1), 51200.0, None)
SCENES = {
    # name: (scene text, solver)
    "rigid 2 balls": ((EXAMPLES / "two_balls_rigid.toml").read_text(), "auto"),
    "rigid grid 30, 0.6 s": (_grid(6, 5, 0.6, rigid=True), "auto"),
    "modal 1 ball, 20 kHz": ((EXAMPLES / "modal_plate.toml").read_text(), "auto"),
    "modal 1 ball, 2 kHz": (
        _grid(1, 1, 0.05, fmax=2000.0, sensors=[("acc", (0.05, 0.1), 5120.0, None)]),
        "auto",
    ),
    "modal grid 30, 22.5 kHz": ((EXAMPLES / "thirty_balls_modal.toml").read_text(), "auto"),
    "modal grid 12, 5 kHz, 0.3 s": (_grid(4, 3, 0.3, fmax=5000.0, sensors=[SENSOR]), "auto"),
    "modal grid 30, 10 kHz, 0.2 s": (_grid(6, 5, 0.2, fmax=10000.0, sensors=[SENSOR]), "auto"),
    "modal 1 ball, 1 MHz sensor": (
        _grid(1, 1, 0.05, fmax=10000.0, sensors=[("acc", (0.05, 0.1), 1e6, 20000.0)]),
        "auto",
    ),
    "stream rigid, small": ((EXAMPLES / "small_stream.toml").read_text(), "auto"),
    "stream reference, small": ((EXAMPLES / "small_stream.toml").read_text(), "stream-reference"),
    "stream modal, caving 10 kHz, 1.5 s": (
        _with(
            "caving_stream.toml", ["duration = 6.0", "stop = 5.0"], ["duration = 1.5", "stop = 1.0"]
        ),
        "auto",
    ),
    "stream modal 400 particles, 20 deg, sensors' band": (  # the sensors' default bandwidth
        _with(
            "caving_stream.toml",
            [
                "duration = 6.0",
                "stop = 5.0",
                "inclination = 30.0",
                "fmax = 10000.0",
                "bandwidth = 10000.0\n",
                "bandwidth = 10000.0\n",
            ],
            ["duration = 2.5", "stop = 2.0", "inclination = 20.0", "", "", ""],
        ),  # fmt: skip
        "auto",
    ),
    "stream modal 15 kHz one-way": (
        _with(
            "caving_stream.toml",
            ["duration = 6.0", "stop = 5.0", "fmax = 10000.0"],
            ["duration = 0.8", "stop = 0.4", 'fmax = 15000.0\ncoupling = "one-way"'],
        ),
        "auto",
    ),
}


def measure(name: str) -> dict:
    """Estimate, then time every part of one scene (in this process)."""
    from tailbeam.cli.simulate import write_results
    from tailbeam.io.scene_file import loads_scene
    from tailbeam.progress import quiet
    from tailbeam.simulation import choose_solver, plate_setup
    from tailbeam.solvers.base import Options
    from tailbeam.solvers.run_cost import estimate_run

    text, solver = SCENES[name]
    scene = loads_scene(text)
    method = choose_solver(scene, solver)
    cost = estimate_run(scene, method)
    measured = {}
    with quiet():
        t0 = time.perf_counter()
        setup = plate_setup(scene, method)
        t1 = time.perf_counter()
        result = method.run(scene, setup, Options())
        t2 = time.perf_counter()
        _ = result.sensor_outputs
        t3 = time.perf_counter()
        with tempfile.TemporaryDirectory() as tmp:
            write_results(Path(tmp), scene, result)
        t4 = time.perf_counter()
    bases = [p for p in cost.parts if p.name in ("eigen-solve", "contact tails")]  # + set-up
    if bases:
        measured["bases"] = t1 - t0
    measured["simulation"] = t2 - t1
    if cost.part("sensor replay"):
        measured["sensor replay"] = t3 - t2
    measured["writing"] = t4 - t3
    estimated = {p: cost.part(p).time_s for p in ("simulation", "writing")}
    if bases:
        estimated["bases"] = sum(p.time_s for p in bases)
        if cost.part("set-up"):
            estimated["bases"] += cost.part("set-up").time_s
    if cost.part("sensor replay"):
        estimated["sensor replay"] = cost.part("sensor replay").time_s
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024.0
    return {
        "name": name, "estimated": estimated, "measured": measured,
        "total_estimated": cost.time_s, "total_measured": t4 - t0,
        "memory_estimated": cost.memory_bytes, "memory_measured": rss,
        "cached": all(p.cached for p in bases) if bases else None,
        "line": cost.describe(), "impacts": len(result.impacts),
    }  # fmt: skip


def warm_up():
    """Compile (and cache on disk) every kernel the scenes use, on short scenes with contacts
    of every kind: the one-time compilation is not in the model, as on a user's second run."""
    from tailbeam.io.scene_file import loads_scene
    from tailbeam.progress import quiet
    from tailbeam.simulation import simulate

    rigid = SCENES["rigid 2 balls"][0].replace("duration = 1.0", "duration = 0.1")
    modal = _grid(1, 1, 0.02, fmax=2000.0, sensors=[("acc", (0.05, 0.1), 5120.0, None)])
    small = SCENES["stream rigid, small"][0]
    caving = _with("caving_stream.toml", ["duration = 6.0", "stop = 5.0", "height = [0.3, 0.8]"],
                   ["duration = 0.1", "stop = 0.05", "height = [0.001, 0.01]"])  # fmt: skip
    for text in (rigid, modal, small, caving):
        with quiet():
            simulate(loads_scene(text))
    with quiet():
        simulate(loads_scene(small), solver="stream-reference")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="output directory")
    parser.add_argument("--only", nargs="*", help="scene names (default: all)")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child == "warm-up":
        warm_up()
        return 0
    if args.child:
        print(json.dumps(measure(args.child)))
        return 0
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    subprocess.run([sys.executable, __file__, "--out", str(out), "--child", "warm-up"], check=True)
    for name in args.only or SCENES:
        proc = subprocess.run([sys.executable, __file__, "--out", str(out), "--child", name],
                              capture_output=True, text=True, env={**os.environ})  # fmt: skip
        if proc.returncode != 0:
            print(f"{name}: failed\n{proc.stderr[-2000:]}", file=sys.stderr)
            continue
        row = json.loads(proc.stdout.strip().splitlines()[-1])
        rows.append(row)
        print(_line(row), flush=True)
    with open(out / "cost_model.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["scene", "part", "estimated_s", "measured_s", "measured_over_estimated"])
        for row in rows:
            for part, est in {**row["estimated"], "total": row["total_estimated"]}.items():
                meas = row["measured"].get(part, row["total_measured"])
                ratio = f"{meas / est:.2f}" if est > 0 else ""
                w.writerow([row["name"], part, f"{est:.3g}", f"{meas:.3g}", ratio])
            w.writerow([row["name"], "memory_bytes", f"{row['memory_estimated']:.3g}",
                        f"{row['memory_measured']:.3g}",
                        f"{row['memory_measured'] / row['memory_estimated']:.2f}"])  # fmt: skip
    (out / "cost_model.json").write_text(json.dumps(rows, indent=1))
    print(f"load average at the end: {os.getloadavg()[0]:.1f}; wrote {out / 'cost_model.csv'}")
    return 0


def _line(row):
    cells = [row["name"], f"{row['total_estimated']:.1f}", f"{row['total_measured']:.1f}",
             f"{row['total_measured'] / row['total_estimated']:.2f}"]  # fmt: skip
    for part in ("bases", "simulation", "sensor replay", "writing"):
        if part in row["measured"]:
            e, m = row["estimated"][part], row["measured"][part]
            cells.append(f"{part} {e:.2g}/{m:.2g}")
        else:
            cells.append("-")
    mem = row["memory_measured"] / row["memory_estimated"]
    est, meas = row["memory_estimated"] / 1e6, row["memory_measured"] / 1e6
    cells.append(f"{est:.0f}/{meas:.0f} MB ({mem:.2f})")
    return "| " + " | ".join(cells) + " |"


if __name__ == "__main__":
    sys.exit(main())
