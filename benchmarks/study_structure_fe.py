"""The coupled solver on the example tail beam against the full finite-element integration of
the same mesh.

    python benchmarks/study_structure_fe.py --out DIR [--size S | --mesh PATH]
        [--bands HZ ...] [--dt S] [--duration S] [--window S] [--check-duration S]

Reproduces the table of docs/structures.md (Checks and their errors), from three runs:

    --dt 4e-6 --duration 3e-3 --window 2.5e-3 --check-duration 6e-4 --bands 2000
    --dt 4e-6 --duration 3e-3 --window 2.5e-3 --check-duration 6e-4 --bands 6000
    --size 0.1 --dt 2e-6 --duration 4e-3 --window 3e-3 --bands 2000 3000 4500 6000 7500

(the first ~4 min of CPU on the example mesh, 3.2 GB peak; the second ~8 min, the example
mesh's modes to 6 kHz solved cold; the third ~5 min). The beam: the example
mesh (meshes/tail_beam.msh, 81 640 DOFs) or, with ``--size S``, the same beam re-meshed by
meshes/tail_beam.py at in-plane element size S m (written into DIR); hinge pinned about y,
jack 2e8 N/m, as examples/tail_beam_stream.toml. One impact: a 60 mm sandstone ball at 2 m/s
between the ribs at (0.45, 0) m; one sensor on the back, the bottom plate's underside at
(0.6, 0, -0.30) m, read along z. No damping (the FE model has none to match).

Truth, in the same run: tailbeam.solvers.coupled.fe_structure (every DOF of the mesh,
Newmark average acceleration at ``--dt``, the contact law implicit each step), its step
error estimated from a second run at 2 dt over the first ``--check-duration`` s (order 2:
the error of the fine run is a third of their difference). The coupled solver
(simulate_coupled, its default 200 steps per contact) on the beam's modes below each band,
with the residual flexibility (the default) and without. Errors: each contact quantity of the
first impact relative to the reference, their maximum ("contact"), and the relative L2 error
of the sensor acceleration low-passed to half the band and to the band, over the first
``--window`` s.

Cost: the reference factorises K + (4 / dt^2) M once (METIS order, 20-50 s on the example
mesh) and then solves once per step (0.3 s on an idle core there); ``--duration / --dt``
steps. Writes DIR/study.csv and DIR/study.md.
"""

import argparse
import csv
import os
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from tailbeam.io.scene_file import loads_scene
from tailbeam.physics.bodies import Ball
from tailbeam.physics.contact_law import ball_plate_law
from tailbeam.physics.materials import CARBON_STEEL, SANDSTONE
from tailbeam.plate.solid import Support, assemble_structure, structure_modes
from tailbeam.signals.sensor import SensorSpec
from tailbeam.solvers.coupled.fe_compare import result_errors
from tailbeam.solvers.coupled.fe_reference import QUANTITIES, impact_quantities
from tailbeam.solvers.coupled.fe_structure import StructureCase
from tailbeam.solvers.coupled.solver import simulate_coupled
from tailbeam.solvers.modal_setup.band import choose_band

ROOT = Path(__file__).resolve().parents[1]
MESH = ROOT / "meshes" / "tail_beam.msh"
SUPPORTS = (Support("pinned", group="hinge", axis=(0.0, 1.0, 0.0)),
            Support("spring", group="jack", stiffness=2.0e8))  # fmt: skip
R, SPEED, IMPACT = 0.03, 2.0, (0.45, 0.0)
SENSOR = SensorSpec("back", (0.6, 0.0, -0.30), direction=(0.0, 0.0, 1.0))
COLUMNS = ("band_hz", "n_modes", "variant", *QUANTITIES, "contact", "sensor_half_band",
           "sensor_band")  # fmt: skip


def cpu() -> float:
    """CPU seconds of this process and its finished children."""
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


def beam(args, out: Path):
    """(mesh path, StructureModel) of the example beam or its --size variant."""
    mesh = Path(args.mesh) if args.mesh else MESH
    if args.size is not None:
        mesh = out / f"tail_beam_{args.size:g}.msh"
        subprocess.run([sys.executable, str(ROOT / "meshes" / "tail_beam.py"), "--size",
                        str(args.size), "--out", str(mesh)], check=True)  # fmt: skip
    return mesh, assemble_structure(mesh, "top", SUPPORTS, material=CARBON_STEEL)


def case_for(model, band_hz, window):
    ball = Ball("b", SANDSTONE, R, (*IMPACT, R + 1e-5), (0.0, 0.0, -SPEED))
    law = ball_plate_law(SANDSTONE, R, CARBON_STEEL)
    return StructureCase(model, ball, law, SENSOR, gravity=0.0, sensor_band_hz=band_hz,
                         sensor_window_s=window)  # fmt: skip


def step_error(case, ref, dt, duration) -> dict:
    """Relative error estimate of ``ref`` (step dt) per contact quantity: a third of its
    difference from a run at 2 dt over ``duration`` s (Newmark is second order)."""
    coarse = case.reference(2 * dt, duration=duration, max_work=1e16)
    q, q2 = impact_quantities(ref.impacts[0]), impact_quantities(coarse.impacts[0])
    return {k: abs(q2[k] - q[k]) / 3 / abs(q[k]) for k in QUANTITIES}


def below(basis, band):
    """The modes of ``basis`` below ``band`` Hz (a StructureModalBasis still: sensors
    anywhere); the static compliance is the whole structure's either way."""
    keep = int(np.searchsorted(basis.frequencies_hz, band, side="right"))
    return replace(basis, frequencies_hz=basis.frequencies_hz[:keep],
                   mode_vectors=basis.mode_vectors[:, :keep])  # fmt: skip


def automatic_band(mesh) -> float:
    """The band (Hz) a scene of this impact on this beam gets without plate.fmax."""
    text = SCENE.format(mesh=Path(mesh).resolve().as_posix(), r=R, z=R + 1e-5, v=-SPEED,
                        x=IMPACT[0], y=IMPACT[1])  # fmt: skip
    return float(choose_band(loads_scene(text))["fmax_hz"])


SCENE = """duration = 0.004
[plate]
model = "modal"
material = "carbon_steel"
mesh = "{mesh}"
impact_face = "top"
[[plate.supports]]
group = "hinge"
kind = "pinned"
axis = [0.0, 1.0, 0.0]
[[plate.supports]]
group = "jack"
kind = "spring"
stiffness = 2.0e8
[[balls]]
name = "b"
material = "sandstone"
radius = {r}
position = [{x}, {y}, {z}]
velocity = [0.0, 0.0, {v}]
"""


def band_rows(model, case_half, case_full, ref, basis, band):
    """Rows (as COLUMNS) of the coupled solver on the beam's modes below ``band`` Hz."""
    basis = below(basis, band)
    rows = []
    for variant, rf in (("residual flexibility (default)", True), ("kept modes only", False)):
        res = simulate_coupled([case_half.ball], basis, [case_half.law], float(ref.t[-1]),
                               damping_ratio=0.0, gravity=0.0,
                               residual_flexibility=rf)  # fmt: skip
        half, full = result_errors(case_half, res, ref), result_errors(case_full, res, ref)
        rows.append((band, basis.n_modes, variant, *(half[k] for k in QUANTITIES),
                     half["contact"], half["sensor"], full["sensor"]))  # fmt: skip
        print(f"  {band:6.0f} Hz, {basis.n_modes} modes, {variant}: contact "
              f"{half['contact']:.2e}, sensor {half['sensor']:.2e} / {full['sensor']:.2e}",
              flush=True)  # fmt: skip
    return rows


def write(rows, meta, out: Path, auto: float) -> str:
    with open(out / "study.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(COLUMNS)
        w.writerows(rows)
    lines = ["| band (kHz) | modes | variant | restitution | peak force | contact time | "
             "max penetration | sensor 0-band/2 | sensor 0-band |",
             "|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for r in rows:
        errs = " | ".join(f"{v:.1e}" for v in (*r[3:7], r[8], r[9]))
        mark = " (automatic)" if r[0] == auto else ""
        lines.append(f"| {r[0] / 1000:g}{mark} | {r[1]} | {r[2]} | {errs} |")
    text = "\n".join([*lines, "", *meta]) + "\n"
    (out / "study.md").write_text(text)
    return text


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--mesh", default=None, help="a beam mesh (default meshes/tail_beam.msh)")
    ap.add_argument("--size", type=float, default=None, help="re-mesh the beam at this size, m")
    ap.add_argument("--bands", type=float, nargs="+", default=None,
                    help="modal bands, Hz (default 2 kHz to 1.5 x the automatic band)")  # fmt: skip
    ap.add_argument("--dt", type=float, default=2e-6, help="reference step, s")
    ap.add_argument("--duration", type=float, default=4e-3, help="simulated, s")
    ap.add_argument("--window", type=float, default=3e-3, help="sensor compared over, s")
    ap.add_argument("--check-duration", type=float, default=None,
                    help="the 2 dt run's length, s (default --duration)")  # fmt: skip
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    t0, c0 = time.perf_counter(), cpu()
    mesh, model = beam(args, out)
    steps = round(args.duration / args.dt)
    print(f"{mesh}: {model.n_dofs} DOFs, K {model.stiffness.nnz} nonzeros; reference "
          f"{steps} steps of {args.dt:g} s (one factorisation, then one solve a step)",
          flush=True)  # fmt: skip
    auto = automatic_band(mesh)
    bands = sorted(args.bands or {2000.0, 0.5 * auto, 0.75 * auto, auto, 1.5 * auto})
    print(f"  automatic band of this impact: {auto:g} Hz; bands {bands}", flush=True)
    cases = [case_for(model, auto, args.window)]
    ref = cases[0].reference(args.dt, duration=args.duration, max_work=1e16)
    ref_cpu = cpu() - c0
    q = impact_quantities(ref.impacts[0])
    print(f"  reference: {ref_cpu:.0f} s CPU; " + ", ".join(f"{k} {v:.6g}" for k, v in q.items()),
          flush=True)  # fmt: skip
    est = step_error(cases[0], ref, args.dt, args.check_duration or args.duration)
    print("  reference step error estimate:", {k: f"{v:.1e}" for k, v in est.items()}, flush=True)
    rows = []
    widest = structure_modes(model, fmax_hz=max(bands))
    for band in bands:
        half, full = case_for(model, 0.5 * band, args.window), case_for(model, band, args.window)
        rows += band_rows(model, half, full, ref, widest, band)
    load = os.getloadavg()[0]
    meta = [f"{mesh.name}: {model.n_dofs} DOFs. Reference: dt {args.dt:g} s, {steps} steps, "
            f"{ref_cpu:.0f} s CPU; restitution {q['restitution']:.5f}, peak force "
            f"{q['peak_force']:.1f} N, contact {1e3 * q['duration']:.4f} ms; its step error "
            f"(from 2 dt) <= {max(est.values()):.0e}. Sensor over the first "
            f"{1e3 * args.window:g} ms. Total {cpu() - c0:.0f} s CPU, "
            f"{time.perf_counter() - t0:.0f} s wall, 1-min load {load:.1f}. Automatic band "
            f"{auto:g} Hz."]  # fmt: skip
    print(write(rows, meta, out, auto))
    return rows


if __name__ == "__main__":
    sys.exit(0 if main() else 1)
