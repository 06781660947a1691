"""Convergence of many-ball two-way runs on the modal plate with the tolerance and the band.

    python benchmarks/study_stream_convergence.py --out DIR [--quick]

Reproduces the table of docs/streams.md ("Convergence with tolerance and band"). Scenes: the
ten-ball scene of the tests (ball-ball contacts in flight, a 3-ball cluster, a stacked pair;
tests/stream_scenes.py) on a horizontal and on a 20-degree plate, and a generated stream of
~40 particles on the 20-degree plate (c = 300 N s/m; ``--quick``: the two ten-ball scenes,
fewer settings, truth band 20 kHz). Plate: the closed-form SSSS Kirchhoff basis of the default
0.6 x 0.6 x 0.01 m steel plate (exact modes at any band, so the band study has no mesh
error), 1 % modal damping, two-way coupling through the fast stream solver
(``tailbeam.solvers.stream.driver.loop.solve_stream`` with a ``StreamPlate``).

1. Tolerance: rtol 1e-6 ... 1e-11 against rtol 1e-13 (band 5 kHz).
2. Band: 2.5, 5, 10, 20 kHz against 40 kHz (rtol 1e-12), with the residual flexibility of the
   truncated modes at the contacts (the default) and without it.

Each truth is run in the same run. A stream is chaotic (docs/streams.md): a change of
tolerance or band can change which balls meet, and then everything after. So each run's
contact records (ball, partner, in order of start) are compared with the truth's over their
common prefix only, and the table gives that prefix's length. Errors: over each ball's first
impact (its first contact that ends separated, approaching faster than 0.1 m/s: the chatter
of balls settling on the plate or on each other is not an impact), where both runs have the
same one, the largest relative difference of the duration, the peak force and the separation
speed (approach_out, relative to the approach speed). Later impacts of a ball that bounces in
a stacked pair on the vibrating plate diverge exponentially with the contact count (1e-10 on
the first impacts, 1e-2 after ten bounces of the pair at rtol 1e-10 against 1e-13): the
chaos, not the solver's error.

Writes DIR/convergence.csv, DIR/table.md and DIR/convergence.png; prints the fitted orders
(log-log slopes).
"""

import argparse
import csv
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from stream_scenes import first_impact_difference, ten_ball_scene  # noqa: E402

from tailbeam.physics.bodies import Plate  # noqa: E402
from tailbeam.physics.incline import InclinedPlate  # noqa: E402
from tailbeam.plate.closed_forms import ssss_kirchhoff_basis  # noqa: E402
from tailbeam.solvers.stream.driver.loop import solve_stream  # noqa: E402
from tailbeam.solvers.stream.plate import StreamPlate  # noqa: E402
from tailbeam.streams.generator import Particle, generate_particles  # noqa: E402

DAMPING = 300.0  # N s/m, every contact
ZETA = 0.01  # modal damping ratio


def _particles(balls):
    return [
        Particle(b.name, "", "coal", b.material, b.radius, b.mass, 0.0, tuple(b.position),
                 tuple(b.velocity))
        for b in balls
    ]  # fmt: skip


def scenes(quick: bool) -> dict:
    """name -> (particles, incline, duration s)."""
    flat, tilted = InclinedPlate(), InclinedPlate(inclination=20.0)
    out = {
        "ten balls, 0 deg": (_particles(ten_ball_scene(flat)), flat, 0.25),
        "ten balls, 20 deg": (_particles(ten_ball_scene(tilted)), tilted, 0.25),
    }
    if not quick:
        settings = dict(name="s", rate=200.0, start=0.0, stop=0.2, gangue_fraction=0.3,
                        radius=[0.01, 0.03], area=[[-0.15, 0.15], [-0.15, 0.15]],
                        height=[0.02, 0.15], velocity=[0.0, 0.0, -1.0], velocity_spread=0.5,
                        seed=7)  # fmt: skip
        out["stream of ~40, 20 deg"] = (generate_particles([settings], tilted), tilted, 0.3)
    return out


def run(particles, incline, duration, band_hz, rtol, residual=True):
    basis = ssss_kirchhoff_basis(Plate(), band_hz)
    plate = StreamPlate(basis, np.full(basis.n_modes, ZETA), residual_flexibility=residual)
    t0 = time.perf_counter()
    res = solve_stream(particles, incline, duration, damping=DAMPING, rtol=rtol,
                       progress=False, plate=plate)  # fmt: skip
    return res.contacts, time.perf_counter() - t0, basis.n_modes


def study(quick: bool):
    rows = []
    rtols = [1e-6, 1e-8, 1e-10] if quick else [1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11]
    bands = [2500.0, 5000.0, 10000.0] if quick else [2500.0, 5000.0, 10000.0, 20000.0]
    band_fixed, band_truth = 5000.0, (20000.0 if quick else 40000.0)
    for name, (particles, incline, duration) in scenes(quick).items():
        truth, wall, n = run(particles, incline, duration, band_fixed, 1e-13)
        for rtol in rtols:
            got, wall, n = run(particles, incline, duration, band_fixed, rtol)
            rows.append(_row(name, "rtol", rtol, n, wall, first_impact_difference(got, truth)))
        for residual, kind in ((True, "band_hz"), (False, "band_hz, no residual")):
            truth, wall, n = run(particles, incline, duration, band_truth, 1e-12, residual)
            for band in bands:
                got, wall, n = run(particles, incline, duration, band, 1e-12, residual)
                rows.append(_row(name, kind, band, n, wall, first_impact_difference(got, truth)))
    return rows


def _row(scene, kind, value, n_modes, wall, cmp):
    prefix, total, impacts, worst = cmp
    print(f"{scene}: {kind} {value:g}: prefix {prefix}/{total}, {impacts} first impacts, "
          f"worst {worst:.2e}", flush=True)  # fmt: skip
    return {"scene": scene, "kind": kind, "value": value, "modes": n_modes, "wall_s": wall,
            "prefix": prefix, "contacts": total, "impacts": impacts, "worst": worst}  # fmt: skip


def orders(rows) -> dict:
    """Fitted log-log slope of the worst error against rtol and against the band, per scene."""
    out = {}
    for scene in dict.fromkeys(r["scene"] for r in rows):
        for kind in ("rtol", "band_hz", "band_hz, no residual"):
            sel = [r for r in rows if r["scene"] == scene and r["kind"] == kind and r["worst"] > 0]
            if len(sel) >= 2:
                x = np.log([r["value"] for r in sel])
                y = np.log([r["worst"] for r in sel])
                out[(scene, kind)] = float(np.polyfit(x, y, 1)[0])
    return out


def write(rows, out_dir: Path) -> None:
    out_dir.mkdir(parents=True, exist_ok=True)
    with (out_dir / "convergence.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    fits = orders(rows)
    lines = ["| scene | setting | value | modes | common prefix | first impacts compared "
             "| worst rel. error | wall (s) |", "|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for r in rows:
        lines.append(
            f"| {r['scene']} | {r['kind']} | {r['value']:g} | {r['modes']} | "
            f"{r['prefix']}/{r['contacts']} | {r['impacts']} | {r['worst']:.2e} "
            f"| {r['wall_s']:.2f} |"
        )
    head = "| scene | fitted order in rtol | fitted order in band | the same without residual |"
    lines += ["", head, "|---|---|---|---|"]
    for scene in dict.fromkeys(r["scene"] for r in rows):
        a, b = fits.get((scene, "rtol"), np.nan), fits.get((scene, "band_hz"), np.nan)
        c = fits.get((scene, "band_hz, no residual"), np.nan)
        lines.append(f"| {scene} | {a:.2f} | {-b:.2f} | {-c:.2f} |")
    (out_dir / "table.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    _plot(rows, out_dir / "convergence.png")


def _plot(rows, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    panels = ((axes[0], ("rtol",), "rtol"),
              (axes[1], ("band_hz", "band_hz, no residual"), "band (Hz)"))  # fmt: skip
    for ax, kinds, label in panels:
        for i, scene in enumerate(dict.fromkeys(r["scene"] for r in rows)):
            for kind in kinds:
                sel = [r for r in rows if r["scene"] == scene and r["kind"] == kind]
                style = "o--" if "no residual" in kind else "o-"
                tag = " (no residual)" if "no residual" in kind else ""
                ax.loglog([r["value"] for r in sel], [max(r["worst"], 1e-16) for r in sel],
                          style, color=f"C{i}", label=scene + tag)  # fmt: skip
        ax.set_xlabel(label)
        ax.set_ylabel("worst relative error, each ball's first impact")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    axes[0].set_title("two-way stream: tolerance (band 5 kHz; truth rtol 1e-13)")
    axes[1].set_title("two-way stream: band (rtol 1e-12; truth: 2 x the widest)")
    fig.savefig(path, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="output folder")
    ap.add_argument("--quick", action="store_true", help="fewer settings, the two ten-ball scenes")
    args = ap.parse_args()
    write(study(args.quick), Path(args.out))
