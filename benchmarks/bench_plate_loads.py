"""Sensor signals of a stream from sparse load histories: plate_response against a dense replay.

    python benchmarks/bench_plate_loads.py --out DIR [--quick]

Reproduces the cost figures of docs/streams.md ("Sensor signals"). Scene, at the reference
stream's scale: ``contacts`` ball-plate contacts at uniform random points of the 0.6 m plate
(2 cm from the edges), random start times over ``duration``, each a half-sine pulse of
0.1-0.3 ms and 0.2-3 kN peak given by ``nodes`` force nodes (piecewise linear), plus 100
dead-load pieces (5 balls sliding in 20 pieces of 20 ms, 2-6 N; the baseline's short stream:
one ball, pieces of duration/25); SSSS Kirchhoff closed-form basis to 10 kHz (106 modes), 1 %
damping, 2 sensors at 51.2 kHz. ``--quick``: a 1 s full case, 0.05 s baseline, 5 kHz FE basis.

Rows:
1. baseline, same run: a smaller stream (``duration`` 0.1 s, density as the full case) on
   the sensor's fine grid (102.4 kHz) by the dense exact replay
   (tailbeam.solvers.plate_loads.forced: one force column per contact, every node time) and
   by plate_response; wall time, the
   size of the dense force table, and their largest difference (both are exact, so it is
   rounding);
2. the full case (6 s, 20 000 contacts) at the sensors' fine grid: plate_response wall time
   and peak traced memory (tracemalloc: numpy allocations), for several nodes per contact;
3. the full case with the quasi-static (residual) correction on (25 nodes per contact): its
   extra cost is one static deflection per distinct load point and sensor (this basis: the
   Navier double series, ~1 ms per point), reported separately;
4. the full case through the whole sensor chain (sensor_outputs), wall time and peak memory;
   its records are drawn in DIR/sensor_s1.png, sensor_s2.png (tailbeam.signals.figures).
Rows 1-2 and 4 have the correction off.
5. per-load-point costs with an FE Mindlin basis to 10 kHz (computed or cached by
   compute_modes, ~3 s): mode shapes and quasi-static correction for 2 000 random point
   loads and 1.5 mm discs (the Mindlin load model).
Writes DIR/bench_plate_loads.csv and DIR/table.md. Run single-threaded (OMP_NUM_THREADS=1).
"""

import argparse
import csv
import math
import time
import tracemalloc
from pathlib import Path

import numpy as np

from tailbeam.physics.bodies import Plate
from tailbeam.plate.closed_forms import ssss_kirchhoff_basis
from tailbeam.progress import quiet
from tailbeam.signals.figures import sensor_figures
from tailbeam.signals.sensor import SensorSpec
from tailbeam.solvers.plate_loads.forced import forced_response
from tailbeam.solvers.plate_loads.loads import PlateLoads
from tailbeam.solvers.plate_loads.response import plate_response, sensor_outputs

FMAX = 10000.0
ZETA = 0.01
FINE_RATE = 102400.0  # the sensor chain's fine grid for 51.2 kHz and modes to 10 kHz
SENSORS = (SensorSpec("s1", (0.0, 0.15)), SensorSpec("s2", (-0.2, 0.1)))
POINTS = np.array([s.position for s in SENSORS])
RATE = 20000 / 6.0  # contacts per second of the full case


def stream(duration, n_contacts, nodes, seed=0):
    """(PlateLoads, pieces): the scene of the module docstring; pieces as (x, y, t, F)."""
    rng = np.random.default_rng(seed)
    pieces = []
    for t0 in np.sort(rng.uniform(0.0, duration - 5e-4, n_contacts)):
        x, y = rng.uniform(-0.28, 0.28, 2)
        tau, peak = rng.uniform(1e-4, 3e-4), rng.uniform(200.0, 3000.0)
        u = np.linspace(0.0, 1.0, nodes)
        pieces.append((x, y, t0 + tau * u, peak * np.sin(np.pi * u)))
    n_sliders = 5 if duration >= 2.0 else 1
    piece = min(0.02, duration / 25)  # s per dead-load piece (20 per slider)
    for b in range(n_sliders):
        start, y = rng.uniform(0.0, duration - 20 * piece), rng.uniform(-0.2, 0.2)
        for k in range(20):
            t = start + piece * k
            pieces.append((-0.25 + 0.02 * k, y, np.array([t, t + piece]), np.full(2, 2.0 + b)))
    loads = PlateLoads()
    for x, y, t, f in pieces:
        if len(t) == 2 and f[0] == f[1]:
            loads.add_dead_load(x, y, t[0], t[1], f[0])
        else:
            loads.add_contact(x, y, t, f)
    return loads, pieces


def dense_table(pieces):
    """Node times (K,) and forces (K, pieces) for forced_response: every piece's nodes, jumps
    as two nodes at the same time, each column interpolated (zero outside its piece)."""
    t_all = np.unique(np.concatenate([[0.0]] + [p[2] for p in pieces]))
    jumps = np.concatenate([p[2][[0, -1]] for p in pieces if p[3][0] != 0.0])
    tn = np.sort(np.concatenate([t_all, jumps]))
    forces = np.zeros((tn.size, len(pieces)))
    for j, (_x, _y, t, f) in enumerate(pieces):
        inside = (tn >= t[0]) & (tn <= t[-1])
        forces[inside, j] = np.interp(tn[inside], t, f)
        if f[0] != 0.0:  # the piece's own jumps: zero at the first copy of each end
            forces[np.searchsorted(tn, t[0]), j] = 0.0
            forces[np.searchsorted(tn, t[-1], side="right") - 1, j] = 0.0
    return tn, forces


def traced(fun):
    """(wall s, peak traced MB, result) of fun()."""
    tracemalloc.start()
    start = time.perf_counter()
    out = fun()
    wall = time.perf_counter() - start
    peak = tracemalloc.get_traced_memory()[1] / 1e6
    tracemalloc.stop()
    return wall, peak, out


def baseline_row(basis, nodes, quick):
    duration = 0.05 if quick else 0.1
    loads, pieces = stream(duration, int(round(RATE * duration)), nodes, seed=1)
    times = np.arange(int(duration * FINE_RATE) + 1) / FINE_RATE
    tn, forces = dense_table(pieces)
    xy = [(p[0], p[1]) for p in pieces]
    wall_d, peak_d, ref = traced(
        lambda: forced_response(basis, xy, tn, forces, times, POINTS, damping_ratio=ZETA)
    )
    wall_s, peak_s, ours = traced(
        lambda: plate_response(basis, ZETA, loads, POINTS, times, quasi_static=False)
    )
    err = max(
        float(np.max(np.abs(ours[k] - ref[k])) / np.max(np.abs(ref[k]))) for k in ("w", "v", "a")
    )
    common = {"duration_s": duration, "pieces": len(pieces), "load_nodes": loads.n_nodes,
              "samples": times.size, "max_rel_diff_vs_dense": err}  # fmt: skip
    return [
        {"case": "baseline", "method": "dense replay", "nodes_per_contact": nodes,
         "wall_s": wall_d, "peak_MB": peak_d, "dense_table_MB": forces.nbytes / 1e6, **common},
        {"case": "baseline", "method": "plate_response", "nodes_per_contact": nodes,
         "wall_s": wall_s, "peak_MB": peak_s, "dense_table_MB": math.nan, **common},
    ]  # fmt: skip


def full_rows(basis, nodes_list, quick):
    duration = 1.0 if quick else 6.0
    n_contacts = int(round(RATE * duration))
    times = np.arange(int(duration * FINE_RATE) + 1) / FINE_RATE
    rows = []
    for nodes in nodes_list:
        loads, pieces = stream(duration, n_contacts, nodes)
        wall, peak, _ = traced(
            lambda loads=loads: plate_response(
                basis, ZETA, loads, POINTS, times, quasi_static=False
            )
        )
        rows.append({"case": "full", "method": "plate_response", "nodes_per_contact": nodes,
                     "duration_s": duration, "pieces": len(pieces), "load_nodes": loads.n_nodes,
                     "samples": times.size, "wall_s": wall, "peak_MB": peak})  # fmt: skip
        print(_line(rows[-1]), flush=True)
    loads, pieces = stream(duration, n_contacts, 25)
    wall, peak, _ = traced(lambda: plate_response(basis, ZETA, loads, POINTS, times))
    rows.append({"case": "full", "method": "plate_response + quasi-static",
                 "nodes_per_contact": 25, "duration_s": duration, "pieces": len(pieces),
                 "load_nodes": loads.n_nodes, "samples": times.size, "wall_s": wall,
                 "peak_MB": peak})  # fmt: skip
    print(_line(rows[-1]), flush=True)
    loads, pieces = stream(duration, n_contacts, nodes_list[-1])
    wall, peak, outputs = traced(
        lambda: sensor_outputs(basis, ZETA, loads, SENSORS, duration, quasi_static=False)
    )
    rows.append({"case": "full", "method": "sensor_outputs (whole chain)",
                 "nodes_per_contact": nodes_list[-1], "duration_s": duration,
                 "pieces": len(pieces), "load_nodes": loads.n_nodes,
                 "samples": times.size, "wall_s": wall, "peak_MB": peak})  # fmt: skip
    print(_line(rows[-1]), flush=True)
    return rows, outputs


def fe_rows(quick):
    """Per-load-point costs with an FE Mindlin basis (10 kHz; quick: 5 kHz): mode shapes and
    the quasi-static correction for 2 000 random point loads and 1.5 mm Hertz discs."""
    from tailbeam.plate import compute_modes
    from tailbeam.solvers.plate_loads.response import _residual, load_shapes

    basis = compute_modes(Plate(), "SSSS", theory="mindlin", fmax_hz=5000.0 if quick else FMAX)
    rng = np.random.default_rng(2)
    rows = []
    seen = np.ones(2000, dtype=bool)
    for radius in (0.0, 0.0015):
        xyr = np.column_stack([rng.uniform(-0.28, 0.28, (2000, 2)), np.full(2000, radius)])
        wall_shapes, _, phi = traced(lambda xyr=xyr: load_shapes(basis, xyr))
        g = phi @ (basis.deflection(POINTS) / basis.omega**2).T
        wall_res, _, _ = traced(lambda xyr=xyr, g=g: _residual(basis, xyr, POINTS, seen, g))
        rows.append({"case": f"FE Mindlin {basis.n_modes} modes", "load radius (mm)": radius * 1e3,
                     "load points": len(xyr), "shapes ms/point": wall_shapes / len(xyr) * 1e3,
                     "quasi-static ms/point (2 sensors)": wall_res / len(xyr) * 1e3})  # fmt: skip
        print(rows[-1], flush=True)
    return rows


def _line(row):
    return (f"{row['case']:8s} {row['method']:28s} nodes/contact {row['nodes_per_contact']:4d} "
            f"{row['duration_s']:5.2f} s {row['pieces']:6d} pieces {row['load_nodes']:8d} nodes "
            f"{row['wall_s']:7.2f} s peak {row['peak_MB']:7.1f} MB")  # fmt: skip


def main(out_dir, quick=False):
    basis = ssss_kirchhoff_basis(Plate(), FMAX)
    with quiet():
        tiny, _ = stream(0.01, 3, 5)
        plate_response(basis, ZETA, tiny, POINTS, np.arange(50) / FINE_RATE, quasi_static=False)
        forced_response(basis, POINTS, [0.0, 1e-4], np.ones((2, 2)), [0.0, 1e-5], POINTS)
        rows = baseline_row(basis, 25, quick)
        for row in rows:
            print(_line(row), f"dense table {row['dense_table_MB']:.1f} MB", flush=True)
        more, outputs = full_rows(basis, [10, 25] if quick else [10, 25, 50, 100, 200], quick)
        rows += more
        fe = fe_rows(quick)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    keys = list(dict.fromkeys(k for row in rows for k in row))
    with open(out / "bench_plate_loads.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=keys, restval="")
        writer.writeheader()
        writer.writerows(rows)
    fe_lines = ["", "| " + " | ".join(fe[0]) + " |", "|---" * len(fe[0]) + "|"]
    fe_lines += ["| " + " | ".join(f"{v:.3g}" if isinstance(v, float) else str(v)
                                   for v in row.values()) + " |" for row in fe]  # fmt: skip
    (out / "table.md").write_text(_table(rows, basis) + "\n".join(fe_lines) + "\n")
    positions = {s.name: s.position for s in SENSORS}
    sensor_figures(outputs, out, positions)  # sensor_<name>.png: the stream's records
    print((out / "table.md").read_text())


def _table(rows, basis):
    lines = [
        f"Basis: SSSS Kirchhoff closed form to {FMAX:g} Hz ({basis.n_modes} modes), 2 points, "
        f"{FINE_RATE:g} Hz grid (the 51.2 kHz sensors' fine grid); single thread.",
        "",
        "| case | method | nodes/contact | duration (s) | pieces | load nodes | samples | "
        "wall (s) | peak traced (MB) | dense table (MB) | max rel. diff vs dense |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        dense = r.get("dense_table_MB", math.nan)
        diff = r.get("max_rel_diff_vs_dense", math.nan)
        lines.append(
            f"| {r['case']} | {r['method']} | {r['nodes_per_contact']} | {r['duration_s']:g} | "
            f"{r['pieces']} | {r['load_nodes']} | {r['samples']} | {r['wall_s']:.2f} | "
            f"{r['peak_MB']:.1f} | {'' if math.isnan(dense) else f'{dense:.1f}'} | "
            f"{'' if math.isnan(diff) else f'{diff:.1e}'} |"
        )
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--quick", action="store_true", help="1 s full case, 0.05 s baseline")
    args = parser.parse_args()
    main(args.out, args.quick)
