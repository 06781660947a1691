"""The plate's modes: frequency error against DOFs and wall time over a mesh ladder.

    python benchmarks/bench_modes.py --out DIR [--quick] [--fmax HZ]

Reproduces the speed figure of docs/plate-modes.md ("Speed"). For Kirchhoff (Argyris) and
Mindlin (Lagrange P4) on the default SSSS steel plate, every mode up to ``--fmax`` (10 kHz):
the largest relative frequency error against the SSSS closed form of the same theory (the
baseline: exact modes at no FE cost), DOFs, assembly, eigen-solve, cold total and cached
reload time, over a ladder of meshes, and the package default (theory "auto"). Also fits the
error model err = C (k dx)^q that tailbeam.plate.fe.resolution uses (end of table.md).
``--quick``: three meshes per theory.

Writes DIR/bench_modes.csv, DIR/table.md and DIR/bench_modes.png. Run with single-threaded
BLAS for reproducible timings (OMP_NUM_THREADS=1 OPENBLAS_NUM_THREADS=1).
"""

import argparse
import csv
import tempfile
import time
from pathlib import Path

import numpy as np

from tailbeam.physics.bodies import Plate
from tailbeam.plate import compute_modes
from tailbeam.plate.closed_forms import bending_wavenumber, ssss_modes

LADDER = {"kirchhoff": (8, 10, 12, 14, 16, 20, 24), "mindlin": (8, 10, 12, 14, 16, 18, 20)}
QUICK_LADDER = {"kirchhoff": (8, 12, 16), "mindlin": (8, 12, 16)}
ORDER = {"kirchhoff": 8.0, "mindlin": 7.0}


def run_case(plate: Plate, theory: str, divisions, fmax_hz: float, cache_dir: Path):
    """One ladder rung; theory 'auto' with divisions None is the package default."""
    kw = dict(theory=theory, fmax_hz=fmax_hz, divisions=divisions, cache_dir=cache_dir)
    t0 = time.perf_counter()
    basis = compute_modes(plate, "SSSS", blas_threads=1, **kw)
    cold = time.perf_counter() - t0
    t0 = time.perf_counter()
    again = compute_modes(plate, "SSSS", blas_threads=1, **kw)
    again.deflection(np.array([[0.05, 0.07]]))  # include building the evaluator
    reload = time.perf_counter() - t0
    assert again.info["cache"] == "hit"
    ref = ssss_modes(plate, basis.theory, fmax_hz=fmax_hz).frequencies_hz
    n = min(len(ref), basis.n_modes)
    err = np.abs(basis.frequencies_hz[:n] / ref[:n] - 1.0)
    k = float(bending_wavenumber(plate, ref[n - 1], basis.theory))
    dx = max(plate.size_x, plate.size_y) / basis.info["divisions"]
    return {
        "theory": basis.theory if theory != "auto" else f"auto ({basis.theory})",
        "divisions": basis.info["divisions"],
        "dofs": basis.info["n_dofs"],
        "modes": basis.n_modes,
        "closed_form_modes": len(ref),
        "max_rel_error": float(err.max()),
        "k_dx": k * dx,
        "assembly_s": basis.info["assembly_s"],
        "eigensolve_s": basis.info["eigensolve_s"],
        "cold_total_s": cold,
        "cached_reload_s": reload,
    }


def main(out_dir, quick: bool = False, fmax_hz: float = 10_000.0):
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    plate = Plate()
    rows = []
    with tempfile.TemporaryDirectory() as cache:
        for theory, ladder in (QUICK_LADDER if quick else LADDER).items():
            for n in ladder:
                row = run_case(plate, theory, n, fmax_hz, Path(cache))
                rows.append(row)
                print(
                    f"{theory:9s} n={n:3d} dofs={row['dofs']:6d} err={row['max_rel_error']:.2e}"
                    f" cold={row['cold_total_s']:.2f}s reload={row['cached_reload_s']:.3f}s",
                    flush=True,
                )
        rows.append(run_case(plate, "auto", None, fmax_hz, Path(cache)))
        print(f"default (auto): {rows[-1]}", flush=True)
    with (out / "bench_modes.csv").open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    lines = [
        f"SSSS 0.6 x 0.6 x 0.01 m carbon steel, all modes up to {fmax_hz:.0f} Hz; error = max "
        "relative error against the closed form of the same theory; 1 BLAS thread.",
        "",
        "| theory | divisions | DOFs | modes | max rel. error | k dx | assembly s | eigen s |"
        " cold total s | cached reload s |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['theory']} | {r['divisions']} | {r['dofs']} | {r['modes']} | "
            f"{r['max_rel_error']:.2e} | {r['k_dx']:.2f} | {r['assembly_s']:.2f} | "
            f"{r['eigensolve_s']:.2f} | {r['cold_total_s']:.2f} | {r['cached_reload_s']:.3f} |"
        )
    lines.append("")
    for theory in LADDER:
        sel = [r for r in rows if r["theory"] == theory]  # ladder rows, not the default
        if len(sel) >= 2:
            kdx = np.array([r["k_dx"] for r in sel])
            err = np.array([r["max_rel_error"] for r in sel])
            slope = np.polyfit(np.log(kdx[-3:]), np.log(err[-3:]), 1)[0]
            c_fit = np.max(err / kdx ** ORDER[theory])
            lines.append(
                f"- {theory}: measured order {slope:.2f} (finest three meshes); "
                f"max C in err = C (k dx)^{ORDER[theory]:.0f}: {c_fit:.2e}"
            )
    (out / "table.md").write_text("\n".join(lines) + "\n")
    _plot(rows, out / "bench_modes.png", fmax_hz)
    return rows


def _plot(rows, path, fmax_hz):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))
    for theory, marker in (("kirchhoff", "o"), ("mindlin", "s")):
        sel = [r for r in rows if r["theory"] == theory]
        if not sel:
            continue
        ax1.loglog(
            [r["dofs"] for r in sel], [r["max_rel_error"] for r in sel], marker=marker, label=theory
        )
        ax2.loglog(
            [r["cold_total_s"] for r in sel],
            [r["max_rel_error"] for r in sel],
            marker=marker,
            label=f"{theory} cold",
        )
    for r in rows:
        if r["theory"].startswith("auto"):
            ax1.loglog(r["dofs"], r["max_rel_error"], "k*", ms=12, label=f"default {r['theory']}")
            ax2.loglog(r["cold_total_s"], r["max_rel_error"], "k*", ms=12, label="default")
    for ax in (ax1, ax2):
        ax.axhline(1e-3, color="gray", ls="--", lw=0.8)
        ax.set_ylabel(f"max rel. frequency error up to {fmax_hz:.0f} Hz")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    ax1.set_xlabel("DOFs")
    ax2.set_xlabel("wall time, cold (s)")
    ax2.axvline(10.0, color="gray", ls=":", lw=0.8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--quick", action="store_true", help="three meshes per theory")
    parser.add_argument("--fmax", type=float, default=10_000.0, help="band, Hz (10000)")
    args = parser.parse_args()
    main(args.out, quick=args.quick, fmax_hz=args.fmax)
