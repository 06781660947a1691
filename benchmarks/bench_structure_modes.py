"""Solid structures: the example tail beam's modes to 5 kHz (time, peak memory, mode count),
and the element convergence study on the flat plate.

    python benchmarks/bench_structure_modes.py --out DIR [--study] [--fmax 5000]

Beam: meshes/tail_beam.msh (``--mesh``), pinned at ``hinge``, the jack a spring of
``--jack`` N/m on ``jack``, every mode below ``--fmax`` (cold: assembly, Sylvester count,
shift-invert Lanczos), peak resident memory of the process (getrusage); then the same basis
read back from the disk cache (a fresh temporary folder): its load time, file size and
whether it equals the solved one bit for bit; then ``tailbeam modes`` on a scene of the same
structure and band, run ``--cached-runs`` times (3) in fresh processes with that cache
folder: each run's CPU time (user + system, the operating system's count for the child),
wall time, peak memory (the largest child's so far, the runs being started from a small
process) and whether it read the cache (``DIR/cached_runs.csv``): the cached
path end to end (interpreter start, imports, the scene's checks, the basis read back).
``--cached-only FOLDER`` does only those runs, on ``--scene`` (examples/tail_beam_stream.toml)
and a cache folder its structure's basis to ``--fmax`` was solved into before.

``--refine SIZE``: the example beam against the same beam meshed at SIZE m (meshes/tail_beam.py,
gmsh), every mode below ``--refine-fmax`` (2 kHz): the rib-stiffened box against a finer
solution.

``--impact FMAX``: one sandstone ball on the beam through the coupled solver (the structure's
basis to FMAX Hz, passed unchanged), over a rib and between ribs.

``--load-only``: instead of solving, a file of the 5 kHz basis' shape (81 640 x 477 random
vectors) written under the beam's real cache key, read back three times by
``structure_modes`` (wall and CPU time of each load; the load path alone, in a minute).

``--study``: the flat 0.6 x 0.6 x 0.01 m free steel plate as a volume mesh of serendipity
hexahedra (one and two layers through the thickness), triquadratic hexahedra and quadratic
tetrahedra over in-plane divisions, against the converged Reissner-Mindlin plate (Lagrange P4,
32 divisions) and with the Mindlin-Kirchhoff difference beside it: the first 30 frequencies'
largest relative difference. Needs gmsh only for the beam mesh when it is absent.

Writes DIR/bench_structure_modes.csv (beam), DIR/cached_runs.csv, DIR/cache_load.csv
(--load-only),
DIR/element_study.csv, DIR/refinement.csv, DIR/impacts.csv and DIR/table.md.
Single-threaded BLAS (OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1) for reproducible timings.
"""

import argparse
import csv
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))  # the tests' tensor-grid mesh writer

COUNT = 30


def peak_gb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024**2


def cpu_s() -> float:
    """CPU time of this process (user + system), s: less sensitive than wall time to the
    other jobs of a shared machine."""
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


SCENE = """duration = 0.001

[plate]
model = "modal"
material = "carbon_steel"
mesh = "{mesh}"
impact_face = "top"
fmax = {fmax}

[[plate.supports]]
group = "hinge"
kind = "pinned"

[[plate.supports]]
group = "jack"
kind = "spring"
stiffness = {jack}

[[balls]]
name = "lump"
material = "sandstone"
radius = 0.03
position = [0.45, 0.0, 0.031]
velocity = [0.0, 0.0, -2.0]
"""


def children_usage() -> tuple:
    """(CPU s, peak resident GB) of this process' finished children so far."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024**2


def cached_runs(scene: Path, fmax: float, folder, runs: int) -> list:
    """``tailbeam modes SCENE --fmax FMAX``, ``runs`` times in fresh processes reading the
    basis from the cache ``folder`` (module docstring)."""
    env = {**os.environ, "TAILBEAM_CACHE_DIR": str(folder), "OMP_NUM_THREADS": "1",
           "OPENBLAS_NUM_THREADS": "1", "PYTHONPATH": str(ROOT)}  # fmt: skip
    rows = []
    with tempfile.TemporaryDirectory(prefix="tailbeam-bench-modes-") as tmp:
        for i in range(runs):
            cpu0, _ = children_usage()
            load, w = os.getloadavg()[0], time.perf_counter()
            done = subprocess.run([sys.executable, "-m", "tailbeam", "modes", str(scene),
                                   "--fmax", str(fmax), "--out", str(Path(tmp) / f"out{i}")],
                                  env=env, capture_output=True, text=True)  # fmt: skip
            wall = time.perf_counter() - w
            cpu1, peak = children_usage()
            first = (done.stdout.splitlines() or [""])[0]
            if done.returncode:
                print(done.stderr, file=sys.stderr, flush=True)
            rows.append({"run": i + 1, "exit": done.returncode,
                         "cache_hit": first.endswith("cache hit"), "cpu_s": cpu1 - cpu0,
                         "wall_s": wall, "peak_gb_largest_so_far": peak,
                         "load_average_1min": (load + os.getloadavg()[0]) / 2})  # fmt: skip
            print(rows[-1], flush=True)
    return rows


def cached_runs_apart(scene: Path, fmax: float, folder, runs: int) -> list:
    """``cached_runs`` from a fresh, small process (this script with ``--cached-only``): a
    child started from this process would count its memory at the start as its own."""
    out = Path(folder) / "cached-runs"
    subprocess.run([sys.executable, __file__, "--out", str(out), "--cached-only", str(folder),
                    "--scene", str(scene), "--fmax", str(fmax), "--cached-runs", str(runs)],
                   check=True)  # fmt: skip
    with open(out / "cached_runs.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    floats = ("cpu_s", "wall_s", "peak_gb_largest_so_far", "load_average_1min")
    return [{k: float(v) if k in floats else v for k, v in row.items()} for row in rows]


def beam_scene(folder, mesh: Path, fmax: float, jack: float) -> Path:
    """A scene file in ``folder`` of the benchmark's structure (``SCENE``)."""
    scene = Path(folder) / "beam.toml"
    scene.write_text(SCENE.format(mesh=Path(mesh).resolve(), fmax=float(fmax), jack=jack))
    return scene


def beam(mesh: Path, fmax: float, jack: float, runs: int = 3) -> tuple:
    from tailbeam.plate.solid import Support, assemble_structure, structure_modes

    t0, c0 = time.perf_counter(), cpu_s()
    supports = [Support("pinned", group="hinge"), Support("spring", group="jack", stiffness=jack)]
    model = assemble_structure(mesh, "top", supports)
    _ = model.stiffness  # assembled here (else on the eigen-solve's first use), timed apart
    t1 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="tailbeam-bench-cache-") as folder:
        basis = structure_modes(model, fmax_hz=fmax, cache_dir=folder)  # cold: solved, saved
        t2 = time.perf_counter()
        cpu_cold = cpu_s() - c0
        again = structure_modes(model, fmax_hz=fmax, cache_dir=folder)  # read back
        t3 = time.perf_counter()
        size = Path(basis.info["cache_file"]).stat().st_size
        cli = cached_runs_apart(beam_scene(folder, mesh, fmax, jack), fmax, folder, runs)
    same = np.array_equal(again.mode_vectors, basis.mode_vectors) and np.array_equal(
        again.frequencies_hz, basis.frequencies_hz
    )
    f = basis.frequencies_hz
    return {"mesh": str(mesh), "dofs": model.n_dofs, "cells": basis.info["n_cells"],
            "element": model.element, "fmax_hz": fmax, "modes": basis.n_modes,
            "first_hz": f[0], "last_hz": f[-1], "assembly_s": t1 - t0,
            "eigensolve_s": t2 - t1, "total_s": t2 - t0, "cpu_s": cpu_cold,
            "cached_load_s": t3 - t2, "cache_file_mb": size / 1e6,
            "cached_equal": bool(same and again.info["cache"] == "hit"),
            "load_average_1min": os.getloadavg()[0], "peak_gb": peak_gb(),
            "first_10_hz": " ".join(f"{v:.1f}" for v in f[:10])}, cli  # fmt: skip


def load_only(mesh: Path, jack: float, n_modes: int = 477) -> list:
    """Load time of a cached basis of the example beam's 5 kHz shape (module docstring)."""
    from tailbeam.plate.solid import Support, assemble_structure, cached, structure_modes

    supports = [Support("pinned", group="hinge"), Support("spring", group="jack", stiffness=jack)]
    model = assemble_structure(mesh, "top", supports)
    rows = []
    with tempfile.TemporaryDirectory(prefix="tailbeam-bench-cache-") as folder:
        key = cached.basis_key(model, 5000.0, None)
        path = cached.basis_path(folder, key)
        rng = np.random.default_rng(0)
        phi = rng.standard_normal((model.n_dofs, n_modes))
        freqs = np.sort(rng.uniform(30.0, 5000.0, n_modes))
        cached.store_basis(path, key, freqs, phi, {"theory": "solid", "impact_face": "top"})
        for i in range(3):
            w, c = time.perf_counter(), cpu_s()
            basis = structure_modes(model, fmax_hz=5000.0, cache_dir=folder)
            rows.append({"load": i + 1, "cache": basis.info["cache"],
                         "wall_s": time.perf_counter() - w, "cpu_s": cpu_s() - c,
                         "file_mb": path.stat().st_size / 1e6,
                         "equal": bool(np.array_equal(basis.mode_vectors, phi)),
                         "load_average_1min": os.getloadavg()[0]})  # fmt: skip
    return rows


def refinement(mesh: Path, fine_size: float, fmax: float, jack: float) -> list:
    """The example beam against the same beam meshed finer (meshes/tail_beam.py --size;
    needs gmsh): every mode below ``fmax`` of both, relative differences (the fine mesh as
    the converged reference)."""
    import importlib.util

    from tailbeam.plate.solid import Support, assemble_structure, structure_modes

    spec = importlib.util.spec_from_file_location("tail_beam", ROOT / "meshes" / "tail_beam.py")
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    supports = [Support("pinned", group="hinge"), Support("spring", group="jack", stiffness=jack)]
    rows, freqs = [], {}
    with tempfile.TemporaryDirectory() as tmp:
        fine = Path(tmp) / "fine.msh"
        script.main(["--size", str(fine_size), "--out", str(fine)])
        for name, path in (("example", mesh), ("fine", fine)):
            model = assemble_structure(path, "top", supports)
            freqs[name] = structure_modes(model, fmax_hz=fmax).frequencies_hz
            rows.append({"mesh": name, "dofs": model.n_dofs, "modes_below_hz": fmax,
                         "modes": len(freqs[name])})  # fmt: skip
    n = min(len(freqs["example"]), len(freqs["fine"]))
    diff = freqs["example"][:n] / freqs["fine"][:n] - 1
    for row in rows:
        row["max_rel_diff"] = float(np.abs(diff).max())
        row["rel_diff_first_10"] = " ".join(f"{100 * d:.2f}%" for d in diff[:10])
        row["rel_diff_last"] = float(diff[-1])
    return rows


def impacts(mesh: Path, fmax: float, jack: float) -> list:
    """One sandstone ball (60 mm, 2 m/s) on the example beam through the coupled solver with
    the structure's basis to ``fmax`` unchanged: over an inner longitudinal rib and between
    ribs, restitution, peak force and the top's acceleration beside the impact."""
    from tailbeam.physics.bodies import Ball
    from tailbeam.physics.materials import CARBON_STEEL, SANDSTONE
    from tailbeam.plate.solid import Support, assemble_structure, structure_modes
    from tailbeam.scene import ContactSettings
    from tailbeam.signals.sensor import SensorSpec
    from tailbeam.solvers.coupled import simulate_coupled

    supports = [Support("pinned", group="hinge"), Support("spring", group="jack", stiffness=jack)]
    basis = structure_modes(assemble_structure(mesh, "top", supports), fmax_hz=fmax)
    rows, radius = [], 0.03
    for where, xy in (("over the rib y = 0.25", (0.45, 0.25)), ("between ribs", (0.45, 0.0))):
        ball = Ball("s", SANDSTONE, radius, (*xy, radius + 1e-4), (0.0, 0.0, -2.0))
        law = ContactSettings().law_for(ball, CARBON_STEEL)
        sensor = SensorSpec("top", (xy[0] + 0.1, xy[1]), sample_rate=51200.0)
        res = simulate_coupled([ball], basis, [law], 0.02, sensors=(sensor,), gravity=0.0)
        _, acc = res.sensor_signals["top"]
        imp = res.impacts[0]
        rows.append({"impact": where, "band_hz": fmax, "modes": basis.n_modes,
                     "restitution": imp.restitution, "peak_force_n": imp.peak_force,
                     "contact_ms": 1e3 * (imp.t_end - imp.t_start),
                     "sensor_peak_m_s2": float(np.max(np.abs(acc)))})  # fmt: skip
    return rows


def element_study(rungs) -> list:
    from skfem import ElementHex2, ElementHexS2
    from solid_meshes import plate_mesh, tet_plate_mesh

    import tailbeam.plate.solid.elasticity as elasticity
    from tailbeam.physics.bodies import Plate
    from tailbeam.plate import compute_modes
    from tailbeam.plate.solid import assemble_structure, structure_modes

    plate = Plate()
    mindlin = compute_modes(plate, "FFFF", theory="mindlin", count=COUNT, divisions=32,
                            use_cache=False).frequencies_hz  # fmt: skip
    kirchhoff = compute_modes(plate, "FFFF", theory="kirchhoff", count=COUNT, divisions=32,
                              use_cache=False).frequencies_hz  # fmt: skip
    theories = np.abs(mindlin / kirchhoff - 1)
    rows = []
    cases = [("hexS2", ElementHexS2, 1), ("hexS2", ElementHexS2, 2), ("hex2", ElementHex2, 1),
             ("tetP2", None, 1)]  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "plate.msh"
        for name, element, layers in cases:
            for n in rungs:
                if element is None:
                    tet_plate_mesh(path, divisions=n, layers=layers)
                else:
                    elasticity.ELEMENTS["hexahedron"] = element
                    plate_mesh(path, divisions=n, layers=layers)
                t0 = time.perf_counter()
                model = assemble_structure(path, "top", [], free=True)
                f = structure_modes(model, count=COUNT).frequencies_hz
                err = np.abs(f / mindlin - 1)
                rows.append({"element": name, "layers": layers, "divisions": n,
                             "dofs": model.n_dofs, "max_rel_diff_vs_mindlin": err.max(),
                             "mode_of_max": int(np.argmax(err)) + 1,
                             "within_theories_all_30": bool(np.all(err <= theories)),
                             "max_mindlin_vs_kirchhoff": theories.max(),
                             "time_s": time.perf_counter() - t0})  # fmt: skip
                print(rows[-1], flush=True)
    elasticity.ELEMENTS["hexahedron"] = ElementHexS2
    return rows


def write_csv(path: Path, rows: list) -> None:
    with open(path, "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)


def table(rows: list) -> str:
    keys = list(rows[0])
    out = ["| " + " | ".join(keys) + " |", "|" + "---|" * len(keys)]
    for r in rows:
        out.append("| " + " | ".join(f"{v:.4g}" if isinstance(v, float) else str(v)
                                     for v in r.values()) + " |")  # fmt: skip
    return "\n".join(out)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--mesh", type=Path, default=ROOT / "meshes" / "tail_beam.msh")
    parser.add_argument("--fmax", type=float, default=5000.0)
    parser.add_argument("--jack", type=float, default=2.0e8, help="jack stiffness, N/m")
    parser.add_argument("--study", action="store_true", help="also the element study")
    parser.add_argument("--skip-beam", action="store_true")
    parser.add_argument("--load-only", action="store_true", help="only the cache's load time")
    parser.add_argument("--cached-runs", type=int, default=3, help="cached tailbeam modes runs")
    parser.add_argument(
        "--cached-only",
        type=Path,
        metavar="FOLDER",
        help="only the cached runs, on a cache folder filled before",
    )
    parser.add_argument(
        "--scene",
        type=Path,
        default=ROOT / "examples" / "tail_beam_stream.toml",
        help="the scene of --cached-only",
    )
    parser.add_argument("--rungs", type=int, nargs="+", default=[12, 16, 24, 32])
    parser.add_argument(
        "--refine",
        type=float,
        metavar="SIZE",
        help="also compare with the beam meshed at SIZE m (gmsh)",
    )
    parser.add_argument("--refine-fmax", type=float, default=2000.0)
    parser.add_argument(
        "--impact",
        type=float,
        metavar="FMAX",
        help="also one ball on the beam through the coupled solver, band FMAX Hz",
    )
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    parts = []
    if args.load_only:
        rows = load_only(args.mesh, args.jack)
        print(rows, flush=True)
        write_csv(args.out / "cache_load.csv", rows)
        parts.append("## Cached basis load\n\n" + table(rows))
    elif args.cached_only:
        rows = cached_runs(args.scene, args.fmax, args.cached_only, args.cached_runs)
        write_csv(args.out / "cached_runs.csv", rows)
        parts.append("## Cached `tailbeam modes`\n\n" + table(rows))
    elif not args.skip_beam:
        row, rows = beam(args.mesh, args.fmax, args.jack, args.cached_runs)
        print(row, flush=True)
        write_csv(args.out / "bench_structure_modes.csv", [row])
        write_csv(args.out / "cached_runs.csv", rows)
        parts.append("## Tail beam modes\n\n" + table([row]))
        parts.append("## Cached `tailbeam modes`\n\n" + table(rows))
    if args.study:
        rows = element_study(args.rungs)
        write_csv(args.out / "element_study.csv", rows)
        parts.append("## Element study (free flat plate, first 30 modes)\n\n" + table(rows))
    if args.impact:
        rows = impacts(args.mesh, args.impact, args.jack)
        print(rows, flush=True)
        write_csv(args.out / "impacts.csv", rows)
        parts.append("## One ball on the example beam\n\n" + table(rows))
    if args.refine:
        rows = refinement(args.mesh, args.refine, args.refine_fmax, args.jack)
        print(rows, flush=True)
        write_csv(args.out / "refinement.csv", rows)
        parts.append("## Example beam against a finer mesh\n\n" + table(rows))
    (args.out / "table.md").write_text("\n\n".join(parts) + "\n")


if __name__ == "__main__":
    main()
