"""The run cost model (tailbeam.solvers.cost, run_cost) against measured CPU and wall times.

    OMP_NUM_THREADS=1 python benchmarks/bench_cost_model.py --out DIR [--only NAME ...]
    OMP_NUM_THREADS=1 python benchmarks/bench_cost_model.py --out DIR --solid [--beam]
    python benchmarks/bench_cost_model.py --out DIR --again DIR/cost_model.json

For each scene of a spread (single balls and grids, streams, rigid and modal plates, bands
2-40 kHz, light and heavy sensors) the estimate is taken first (``estimate_run``, as
``tailbeam simulate`` prints it), then every part is timed on its own, in process CPU
seconds (what the model estimates: one core's time) and wall seconds, with the load average
at the start and end: the plate set-up (the eigen-solves of the band and the contact tails;
a basis in the user's cache counts as cached, as it does for a user), the solver's run, the
sensor replay and writing the outputs. The compiled kernels are warmed up first (their
one-time compilation is not in the model; the package's sources key numba's cache, so an
edit of tailbeam recompiles). Peak memory is the process's maximum resident size after the
scene (ru_maxrss; each scene in its own process), against the estimate's largest part.

``--solid``: the eigen-solves on their own, each in its own process: structures from small
volume meshes (tests/solid_meshes.py) and the default flat plate to 20 kHz, estimated modes,
factor entries, solves, CPU time and memory against SuperLU's factor, ARPACK's solves and the
process's peak (``--beam``: the example tail beam to 2 kHz too, ~3 GB). ``--again``: no
runs, an earlier run's measurements against the current model's estimates.

Writes DIR/cost_model.csv (per scene and part: estimated, CPU and wall seconds, their ratio,
the load) or DIR/solid_cost.json, and prints the tables of docs/band-and-cost.md. 3-5 CPU
minutes with the bases cached (an uncached 40 kHz solve adds 1-2 CPU minutes).
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
    load0 = os.getloadavg()[0]
    clock = time.perf_counter
    cpu = time.process_time
    with quiet():
        t0, c0 = clock(), cpu()
        setup = plate_setup(scene, method)
        t1, c1 = clock(), cpu()
        result = method.run(scene, setup, Options())
        t2, c2 = clock(), cpu()
        _ = result.sensor_outputs
        t3, c3 = clock(), cpu()
        with tempfile.TemporaryDirectory() as tmp:
            write_results(Path(tmp), scene, result)
        t4, c4 = clock(), cpu()
    cpu_s = {"bases": c1 - c0, "simulation": c2 - c1, "sensor replay": c3 - c2,
             "writing": c4 - c3}  # fmt: skip
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
        "cpu": {k: v for k, v in cpu_s.items() if k in measured}, "total_cpu": c4 - c0,
        "load": [load0, os.getloadavg()[0]],
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


# -- a structure's eigen-solve (tailbeam.plate.solid.cost) -------------------------------------

SOLID_CASES = {
    # name: (mesh kind, its parameters, fmax Hz)
    "solid plate 12x12x1, 3 kHz": ("plate", {"divisions": 12}, 3000.0),
    "solid plate 24x24x1, 3 kHz": ("plate", {"divisions": 24}, 3000.0),
    "solid plate 24x24x1, 8 kHz": ("plate", {"divisions": 24}, 8000.0),
    "solid plate 16x16x2, 6 kHz": ("plate", {"divisions": 16, "layers": 2}, 6000.0),
    "solid tet plate 16x16, 3 kHz": ("tetplate", {"divisions": 16}, 3000.0),
    "solid box beam 20 cells, 2 kHz": ("box", {"cells_x": 20}, 2000.0),
    "solid box beam 40 cells, 4 kHz": ("box", {"cells_x": 40}, 4000.0),
}
BEAM_CASE = ("example tail beam, 2 kHz", ("beam", {}, 2000.0))
PLATE_CASES = {f"flat plate, {f / 1e3:g} kHz": f for f in (5000.0, 10000.0, 20000.0)}


def _structure(kind, params, path):
    sys.path.insert(0, str(HERE.parent / "tests"))
    from solid_meshes import box_beam_mesh, plate_mesh, tet_plate_mesh

    from tailbeam.plate.solid import Support, assemble_structure

    if kind == "beam":
        return assemble_structure(HERE.parent / "meshes" / "tail_beam.msh", "top", (
            Support(kind="pinned", group="hinge", axis=(0.0, 1.0, 0.0)),
            Support(kind="spring", group="jack", stiffness=2.0e8)))  # fmt: skip
    if kind == "box":
        box_beam_mesh(path, 2.0, 0.15, 0.1, 0.01, params["cells_x"])
        return assemble_structure(path, "top", (Support(kind="clamped", group="root"),))
    (tet_plate_mesh if kind == "tetplate" else plate_mesh)(path, **params)
    return assemble_structure(path, "top", (Support(kind="clamped", group="sides"),))


def measure_solid(name: str) -> dict:
    """Estimate, then solve one structure's modes, counting the work (factor entries,
    solves) and timing its stages in CPU seconds (in this process)."""
    from tailbeam.plate.solid import factor
    from tailbeam.plate.solid.cost import structure_cost
    from tailbeam.plate.solid.modes import solve_band

    kind, params, fmax = dict([BEAM_CASE, *SOLID_CASES.items()])[name]
    with tempfile.TemporaryDirectory() as tmp:
        model = _structure(kind, params, str(Path(tmp) / "mesh.msh"))
    est = structure_cost(model, fmax)
    seen = {"factor_s": 0.0, "entries": 0, "solve_s": 0.0, "solves": 0}
    init, solve, nd = (
        factor.OrderedSolver.__init__,
        factor.OrderedSolver.solve,
        factor.nested_dissection,
    )

    def timed_init(self, matrix, perm):
        c = time.process_time()
        init(self, matrix, perm)
        seen["factor_s"] += time.process_time() - c
        seen["entries"] = int(self._lu.L.nnz + self._lu.U.nnz)

    def timed_order(matrix):
        c = time.process_time()
        perm = nd(matrix)
        seen["factor_s"] += time.process_time() - c
        return perm

    def timed_solve(self, rhs):
        c = time.process_time()
        out = solve(self, rhs)
        seen["solve_s"] += time.process_time() - c
        seen["solves"] += 1
        return out

    factor.OrderedSolver.__init__, factor.OrderedSolver.solve = timed_init, timed_solve
    factor.nested_dissection = timed_order
    load0, c0, t0 = os.getloadavg()[0], time.process_time(), time.perf_counter()
    freqs, _ = solve_band(model, fmax)
    cpu, wall = time.process_time() - c0, time.perf_counter() - t0
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024.0
    return {"name": name, "n_dofs": model.n_dofs, "nnz": int(model.stiffness.nnz),
            "modes_estimated": est.n_modes, "modes": len(freqs),
            "entries_estimated": est.factor_entries, "entries": seen["entries"],
            "solves_estimated": est.solves, "solves": seen["solves"],
            "time_estimated": est.time_s, "cpu": cpu, "wall": wall,
            "factor_cpu": seen["factor_s"], "solve_cpu": seen["solve_s"],
            "memory_estimated": est.memory_bytes, "memory_measured": rss,
            "load": [load0, os.getloadavg()[0]]}  # fmt: skip


def measure_plate(name: str) -> dict:
    """Estimate, then solve the default flat plate's band (modal_plate.toml's plate, Mindlin,
    no cache), in CPU seconds (in this process)."""
    from tailbeam.io.scene_file import loads_scene
    from tailbeam.plate.fe.modes import compute_modes

    plate = loads_scene((EXAMPLES / "modal_plate.toml").read_text()).plate
    load0, c0, t0 = os.getloadavg()[0], time.process_time(), time.perf_counter()
    basis = compute_modes(plate, "SSSS", theory="mindlin", fmax_hz=PLATE_CASES[name],
                          use_cache=False, blas_threads=1)  # fmt: skip
    cpu, wall = time.process_time() - c0, time.perf_counter() - t0
    est = basis.info["cost_estimate"]
    return {"name": name, "n_dofs": basis.info["n_dofs"], "modes_estimated": est["n_modes"],
            "modes": basis.n_modes, "time_estimated": est["time_s"], "cpu": cpu, "wall": wall,
            "memory_estimated": est["memory_bytes"],
            "memory_measured": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024.0,
            "load": [load0, os.getloadavg()[0]]}  # fmt: skip


def _plate_line(r):
    return (f"| {r['name']} | {r['n_dofs']} | {r['modes_estimated']} / {r['modes']} | "
            f"{r['time_estimated']:.3g} / {r['cpu']:.3g} ({r['cpu'] / r['time_estimated']:.2f})"
            f" | {r['wall']:.3g} | {r['memory_estimated'] / 1e6:.0f} / "
            f"{r['memory_measured'] / 1e6:.0f} | {r['load'][0]:.1f}-{r['load'][1]:.1f} |"
    )  # fmt: skip


def _solid_line(r):
    return (f"| {r['name']} | {r['n_dofs']} | {r['modes_estimated']} / {r['modes']} | "
            f"{r['entries_estimated'] / 1e6:.2f} / {r['entries'] / 1e6:.2f} | "
            f"{r['solves_estimated']} / {r['solves']} | {r['time_estimated']:.3g} / "
            f"{r['cpu']:.3g} ({r['cpu'] / r['time_estimated']:.2f}) | {r['wall']:.3g} | "
            f"{r['memory_estimated'] / 1e6:.0f} / {r['memory_measured'] / 1e6:.0f} "
            f"({r['memory_measured'] / r['memory_estimated']:.2f}) | "
            f"{r['load'][0]:.1f}-{r['load'][1]:.1f} |")  # fmt: skip


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="output directory")
    parser.add_argument("--only", nargs="*", help="scene names (default: all)")
    parser.add_argument(
        "--solid",
        action="store_true",
        help="the structures' eigen-solves on small meshes instead (~2 min)",
    )
    parser.add_argument("--beam", action="store_true",
                        help="with --solid: also the example tail beam to 2 kHz (~3 GB, "
                        "~3 CPU min)")  # fmt: skip
    parser.add_argument("--again", metavar="JSON",
                        help="no runs: tabulate DIR/cost_model.json's measurements of an "
                        "earlier run against the current model's estimates")  # fmt: skip
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child == "warm-up":
        warm_up()
        return 0
    if args.child:
        kind, _, name = args.child.partition(":")
        run = {"solid": measure_solid, "plate": measure_plate}.get(kind)
        row = run(name) if run else measure(args.child)
        print(json.dumps(row))
        return 0
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.again:
        rows = [_estimate_again(row) for row in json.loads(Path(args.again).read_text())]
        for row in rows:
            print(_line(row))
        _write_csv(out, rows)
        return 0
    if args.solid:
        names = [*SOLID_CASES, *([BEAM_CASE[0]] if args.beam else [])]
        rows = _children(out, [f"solid:{n}" for n in args.only or names], _solid_line)
        rows += _children(out, [f"plate:{n}" for n in PLATE_CASES], _plate_line)
        (out / "solid_cost.json").write_text(json.dumps(rows, indent=1))
        print(f"wrote {out / 'solid_cost.json'}")
        return 0
    subprocess.run([sys.executable, __file__, "--out", str(out), "--child", "warm-up"], check=True)
    rows = _children(out, args.only or list(SCENES), _line)
    _write_csv(out, rows)
    (out / "cost_model.json").write_text(json.dumps(rows, indent=1))
    print(f"load average at the end: {os.getloadavg()[0]:.1f}; wrote {out / 'cost_model.csv'}")
    return 0


def _estimate_again(row: dict) -> dict:
    """``row`` (a scene's measurement) with the current model's estimates."""
    from tailbeam.io.scene_file import loads_scene
    from tailbeam.progress import quiet
    from tailbeam.simulation import choose_solver
    from tailbeam.solvers.run_cost import estimate_run

    text, solver = SCENES[row["name"]]
    scene = loads_scene(text)
    with quiet():
        cost = estimate_run(scene, choose_solver(scene, solver))
    estimated = {p: cost.part(p).time_s for p in ("simulation", "writing")}
    bases = [p for p in cost.parts if p.name in ("eigen-solve", "contact tails", "set-up")]
    if "bases" in row["estimated"]:
        estimated["bases"] = sum(p.time_s for p in bases)
    if cost.part("sensor replay"):
        estimated["sensor replay"] = cost.part("sensor replay").time_s
    return {**row, "estimated": estimated, "total_estimated": cost.time_s,
            "memory_estimated": cost.memory_bytes, "line": cost.describe()}  # fmt: skip


def _children(out, names, line):
    """Run each named measurement in its own process (its own peak memory)."""
    rows = []
    for name in names:
        proc = subprocess.run([sys.executable, __file__, "--out", str(out), "--child", name],
                              capture_output=True, text=True, env={**os.environ})  # fmt: skip
        if proc.returncode != 0:
            print(f"{name}: failed\n{proc.stderr[-2000:]}", file=sys.stderr)
            continue
        row = json.loads(proc.stdout.strip().splitlines()[-1])
        rows.append(row)
        print(line(row), flush=True)
    return rows


def _write_csv(out, rows):
    with open(out / "cost_model.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["scene", "part", "estimated_s", "measured_cpu_s", "measured_wall_s",
                    "cpu_over_estimated", "load_start", "load_end"])  # fmt: skip
        for row in rows:
            cpu = {**row["cpu"], "total": row["total_cpu"]}
            wall = {**row["measured"], "total": row["total_measured"]}
            for part, est in {**row["estimated"], "total": row["total_estimated"]}.items():
                ratio = f"{cpu[part] / est:.2f}" if est > 0 else ""
                w.writerow([row["name"], part, f"{est:.3g}", f"{cpu[part]:.3g}",
                            f"{wall[part]:.3g}", ratio, *row["load"]])  # fmt: skip
            w.writerow([row["name"], "memory_bytes", f"{row['memory_estimated']:.3g}",
                        f"{row['memory_measured']:.3g}", "",
                        f"{row['memory_measured'] / row['memory_estimated']:.2f}",
                        *row["load"]])  # fmt: skip


def _line(row):
    """A row of docs/band-and-cost.md's table: estimated / measured CPU seconds per part."""
    cpu = row["total_cpu"]
    cells = [row["name"], f"{row['total_estimated']:.1f}", f"{cpu:.1f}",
             f"{cpu / row['total_estimated']:.2f}", f"{row['total_measured']:.1f}"]  # fmt: skip
    for part in ("bases", "simulation", "sensor replay", "writing"):
        if part in row["cpu"]:
            cells.append(f"{row['estimated'][part]:.2g} / {row['cpu'][part]:.2g}")
        else:
            cells.append("-")
    mem = row["memory_measured"] / row["memory_estimated"]
    est, meas = row["memory_estimated"] / 1e6, row["memory_measured"] / 1e6
    cells.append(f"{est:.0f} / {meas:.0f} ({mem:.2f})")
    cells.append(f"{row['load'][0]:.1f}-{row['load'][1]:.1f}")
    return "| " + " | ".join(cells) + " |"


if __name__ == "__main__":
    sys.exit(main())
