"""Convergence of the modal coupled solver to the full finite-element plate as the band grows.

    python benchmarks/study_coupled_fe.py --out DIR [--full | --divisions N]
        [--theory kirchhoff|mindlin|both] [--bands HZ ...] [--dt S] [--steps N] [--replot]

Reproduces the tables and figure of docs/fe-convergence.md (the test meshes by default; with
``--full`` its default-mesh table). One impact (sandstone, 30 mm, 1 m/s at (0.05, 0.03) m on
the 0.6 m SSSS steel plate), the sensor 7 cm away at (0.05, 0.10) m. Truth, in the same run:
tailbeam.solvers.coupled.fe_reference on the same mesh and element (every DOF, Newmark
average acceleration at ``--dt`` = 1e-7 s, the contact law implicit each step; its own step
study is printed). The modal solver runs at bands 10-40 kHz, plate damping 0, with each
correction on and off:

- "no correction": the kept modes only;
- "static compliance": the truncated modes' static compliance at the contact, one load model
  for both parts (a point for Kirchhoff, the Hertz disc for Mindlin);
- "static compliance + sensor correction": also the truncated modes' quasi-static response at
  the sensor;
- "quasi-static tail, 200 steps/contact": the same at the shipped 200 steps per contact;
- "Ritz tail (auto k)": ``plate.tail = "ritz"`` with ``tail_modes = "auto"`` (Ritz
  pseudo-modes of the truncated modes at the contact point, then the quasi-static residual of
  the augmented basis), also at 200 steps per contact;
- "default settings": the scene path (simulate_scene_modal) with the default solver settings
  (``plate.tail = "auto"``: the Ritz tail with tail_modes 32; 200 steps per contact).

The first three at ``--steps`` (800) steps per contact, so that the time step's error stays
below the truncation's. Errors: the largest relative error of restitution, peak force,
duration and maximum penetration ("contact"), and the relative L2 error of the 0-10 kHz sensor
acceleration over the first 3 ms ("sensor"). Default meshes: Argyris 8x8 and Mindlin P4 6x6
(minutes); ``--full`` uses the default meshes of a 20 kHz band (Argyris 23x23: ~15 min for
the reference; Mindlin 25x25, 30k DOFs: over an hour). A short check: ``--theory kirchhoff
--bands 10000 20000``. ``--replot`` redraws study.png from DIR/study.csv.

Writes DIR/study.csv, DIR/study.md and DIR/study.png.
"""

import argparse
import csv
import sys
import time
from pathlib import Path

from tailbeam.physics.bodies import Ball, Plate
from tailbeam.physics.contact_law import ball_plate_law
from tailbeam.physics.materials import CARBON_STEEL, SANDSTONE
from tailbeam.plate import assemble_plate, compute_modes
from tailbeam.plate.fe.resolution import resolve
from tailbeam.progress import quiet
from tailbeam.scene import ContactSettings, ModalPlateSettings, Scene
from tailbeam.solvers.coupled.fe_compare import (
    RECORD_S,
    Case,
    modal_errors,
    observed_order,
    result_errors,
)
from tailbeam.solvers.coupled.fe_reference import fe_time_step_study
from tailbeam.solvers.modal_setup.ritz_prepass import ritz_tail_basis
from tailbeam.solvers.single_ball import simulate_scene_modal

R = 0.03
IMPACT, SENSOR = (0.05, 0.03), (0.05, 0.10)
BANDS = (10000.0, 14000.0, 20000.0, 28000.0, 40000.0)
TEST_MESHES = {"kirchhoff": 8, "mindlin": 6}
VARIANTS = ("no correction", "static compliance", "static compliance + sensor correction")
QS200 = "quasi-static tail, 200 steps/contact"
RITZ = "Ritz tail (auto k)"  # plate.tail = "ritz" (tailbeam.solvers.modal_setup.ritz_prepass)
DEFAULTS = "default settings"


def _divisions(theory, full):
    """The test mesh, or with ``full`` the default mesh of a 20 kHz band."""
    if not full:
        return TEST_MESHES[theory]
    res = resolve(Plate(), theory=theory, fmax_hz=20000.0, count=None, accuracy=1e-3,
                  user_mesh=False, divisions=None)  # fmt: skip
    return res.divisions


def _ritz(basis, ball, theory):
    """The basis plus the solver's Ritz tail (plate.tail = "ritz", tail_modes "auto") at the
    ball's first contact point, as simulate_scene_modal builds it."""
    modal = ModalPlateSettings(theory=theory, damping_ratio=0.0, tail="ritz")
    scene = Scene((ball,), Plate(), ContactSettings(damping=0.0), duration=RECORD_S,
                  plate_model="modal", modal=modal)  # fmt: skip
    with quiet():
        return ritz_tail_basis(scene, basis, "auto")[0]


def _default_settings(case, basis, ref, theory, band, divisions):
    """Errors of the scene path with the default solver settings (plate.tail "auto", here
    the Ritz tail with the default tail_modes; 200 steps/contact) on ``basis``."""
    modal = ModalPlateSettings(theory=theory, damping_ratio=0.0, fmax_hz=band,
                               mesh_divisions=divisions)  # fmt: skip
    scene = Scene((case.ball,), Plate(), ContactSettings(damping=0.0), duration=float(ref.t[-1]),
                  plate_model="modal", modal=modal)  # fmt: skip
    with quiet():
        res = simulate_scene_modal(scene, basis=basis)
    return dict(result_errors(case, res, ref), n_modes=res.plate.basis.n_modes)


def study_theory(theory, divisions, dt, steps, bands=BANDS):
    """Rows of (theory, band, n_modes, variant, contact error, sensor error) for one theory
    on the mesh of ``divisions`` elements per side."""
    plate = Plate()
    model = assemble_plate(plate, "SSSS", theory=theory, divisions=divisions)
    ball = Ball("b", SANDSTONE, R, (*IMPACT, R + 1e-5), (0.0, 0.0, -1.0))
    law = ball_plate_law(SANDSTONE, R, CARBON_STEEL)
    case = Case(model, ball, law, SENSOR)
    print(f"{theory}: {divisions} divisions, {model.n_dofs} DOFs", flush=True)
    steps_study = fe_time_step_study(model, ball, law, 5e-4, [4 * dt, 2 * dt, dt],
                                     load_radius=case.load_radius, max_work=1e14)  # fmt: skip
    print(f"  reference step study (orders, error estimate at dt = {dt:g} s):",
          {k: (round(v[0], 2), f"{steps_study['error_estimate'][k]:.1e}")
           for k, v in steps_study["orders"].items()}, flush=True)  # fmt: skip
    t0 = time.perf_counter()
    ref = case.reference(dt, max_work=1e14)
    print(f"  reference: {time.perf_counter() - t0:.0f} s", flush=True)
    rows = []
    for band in bands:

        def basis(band=band):
            return compute_modes(plate, "SSSS", theory=theory, divisions=divisions, fmax_hz=band)

        none = modal_errors(case, basis(), ref, residual_flexibility=False, steps_per_contact=steps)
        new = modal_errors(case, basis(), ref, steps_per_contact=steps)
        default = modal_errors(case, basis(), ref)  # 200 steps per contact, as shipped
        ritz_basis = _ritz(basis(), ball, theory)  # plate.tail = "ritz", tail_modes "auto"
        ritz = modal_errors(case, ritz_basis, ref, steps_per_contact=steps)
        ritz200 = modal_errors(case, ritz_basis, ref)
        defaults = _default_settings(case, basis(), ref, theory, band, divisions)
        n = new["n_modes"]
        rows += [
            (theory, band, n, VARIANTS[0], none["contact"], none["sensor_no_qs"]),
            (theory, band, n, VARIANTS[1], new["contact"], new["sensor_no_qs"]),
            (theory, band, n, VARIANTS[2], new["contact"], new["sensor"]),
            (theory, band, n, QS200, default["contact"], default["sensor"]),
            (theory, band, ritz["n_modes"], RITZ, ritz["contact"], ritz["sensor"]),
            (theory, band, ritz["n_modes"], f"{RITZ}, 200 steps/contact", ritz200["contact"],
             ritz200["sensor"]),
            (theory, band, defaults["n_modes"], DEFAULTS, defaults["contact"],
             defaults["sensor"]),
        ]  # fmt: skip
        print(f"  {band:7.0f} Hz {n:4d} modes: contact {none['contact']:.2e} / "
              f"{new['contact']:.2e}; sensor {none['sensor_no_qs']:.2e} / "
              f"{new['sensor_no_qs']:.2e} / {new['sensor']:.2e}", flush=True)  # fmt: skip
    return rows, divisions, model.n_dofs, steps_study


def _orders(rows):
    out = {}
    for theory in sorted({r[0] for r in rows}):
        for variant in VARIANTS:
            sel = [r for r in rows if r[0] == theory and r[3] == variant and r[1] >= 14000.0]
            bands = [r[1] for r in sel]
            out[theory, variant] = (observed_order(bands, [r[4] for r in sel]),
                                    observed_order(bands, [r[5] for r in sel]))  # fmt: skip
    return out


def write_table(rows, meta, out: Path):
    with open(out / "study.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["theory", "band_hz", "n_modes", "variant", "contact_err", "sensor_err"])
        w.writerows(rows)
    orders = _orders(rows)
    lines = ["| theory | band (kHz) | modes | variant | contact error | sensor error (0-10 kHz) |",
             "|---|---|---|---|---|---|"]  # fmt: skip
    for r in rows:
        lines.append(f"| {r[0]} | {r[1] / 1000:g} | {r[2]} | {r[3]} | {r[4]:.1e} | {r[5]:.1e} |")
    lines += ["", "Observed order in the band (error ~ band^-order, fit over 14-40 kHz):", "",
              "| theory | variant | contact | sensor |", "|---|---|---|---|"]  # fmt: skip
    for (theory, variant), (oc, os_) in orders.items():
        lines.append(f"| {theory} | {variant} | {oc:.1f} | {os_:.1f} |")
    lines += ["", *meta]
    (out / "study.md").write_text("\n".join(lines) + "\n")
    return "\n".join(lines)


def plot(rows, out: Path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    theories = sorted({r[0] for r in rows})
    fig, axes = plt.subplots(len(theories), 2, figsize=(10, 3.8 * len(theories)), squeeze=False)
    styles = {VARIANTS[0]: "o:", VARIANTS[1]: "^-", VARIANTS[2]: "D-", RITZ: "x-",
              DEFAULTS: "P-."}  # fmt: skip
    for i, theory in enumerate(theories):
        for j, (col, what) in enumerate(((4, "contact (max of 4 quantities)"),
                                         (5, "sensor, 0-10 kHz, first 3 ms"))):  # fmt: skip
            ax = axes[i, j]
            for c, (variant, style) in enumerate(styles.items()):
                if j == 0 and variant == VARIANTS[2]:
                    continue  # the sensor correction does not change the contact
                sel = [r for r in rows if r[0] == theory and r[3] == variant]
                ax.loglog(
                    [r[1] / 1000 for r in sel],
                    [r[col] for r in sel],
                    style,
                    color=f"C{c}",
                    label=variant,
                )  # fmt: skip (one colour per variant)
            if j == 0:
                ax.axhline(2e-5, color="grey", lw=0.8)
                ax.text(10.2, 2.2e-5, "2e-5", color="grey", fontsize=8)
            else:
                ax.axhline(1.5e-3, color="grey", lw=0.8)
                ax.text(10.2, 1.6e-3, "1.5e-3", color="grey", fontsize=8)
            ax.set_xlabel("modal band (kHz)")
            ax.set_ylabel("relative error vs full FE")
            ax.set_title(f"{theory}: {what}", fontsize=10)
            ticks = sorted({r[1] / 1000 for r in rows})
            ax.set_xticks(ticks, labels=[f"{b:g}" for b in ticks])
            ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
            ax.grid(True, which="both", alpha=0.3)
    handles, labels = axes[0, 1].get_legend_handles_labels()  # every variant has a sensor line
    fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=8, frameon=False)
    fig.suptitle("Modal solver against the full FE of the same mesh (800 steps/contact unless "
                 "marked; ritz tail: k chosen a posteriori)", fontsize=10)  # fmt: skip
    fig.tight_layout(rect=(0.0, 0.1 / len(theories), 1.0, 1.0))
    fig.savefig(out / "study.png", dpi=120)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--full", action="store_true", help="default meshes of a 20 kHz band")
    ap.add_argument("--divisions", type=int, default=None, help="this mesh instead (elements/side)")
    ap.add_argument("--theory", choices=("kirchhoff", "mindlin", "both"), default="both")
    ap.add_argument("--dt", type=float, default=1e-7, help="reference step, s")
    ap.add_argument("--steps", type=int, default=800, help="modal steps per contact")
    ap.add_argument("--bands", type=float, nargs="+", default=BANDS, help="modal bands, Hz")
    ap.add_argument("--replot", action="store_true", help="redraw study.png from study.csv")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.replot:
        with open(out / "study.csv") as fh:
            rows = [(r[0], float(r[1]), int(r[2]), r[3], float(r[4]), float(r[5]))
                    for r in list(csv.reader(fh))[1:]]  # fmt: skip
        plot(rows, out)
        return rows
    theories = ("kirchhoff", "mindlin") if args.theory == "both" else (args.theory,)
    rows, meta = [], []
    for theory in theories:
        divisions = args.divisions or _divisions(theory, args.full)
        r, divisions, n_dofs, st = study_theory(theory, divisions, args.dt, args.steps, args.bands)
        rows += r
        est = max(st["error_estimate"].values())
        order = min(min(v) for v in st["orders"].values())
        meta.append(f"{theory}: {divisions}x{divisions} mesh, {n_dofs} DOFs; reference dt "
                    f"{args.dt:g} s (step study: order >= {order:.2f}, contact error "
                    f"<= {est:.0e}); modal {args.steps} steps/contact.")  # fmt: skip
    print(write_table(rows, meta, out))
    plot(rows, out)
    return rows


if __name__ == "__main__":
    sys.exit(0 if main() else 1)
