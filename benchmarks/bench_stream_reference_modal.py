"""The fast stream solver on the two-way modal plate against the slow reference.

    python benchmarks/bench_stream_reference_modal.py --out DIR [--quick]

Reproduces the "mode shapes kept through a contact" figures of docs/streams.md ("What is
approximated, and by how much"). Scenes: ``modal_scene`` of tests/stream_scenes.py (seven
balls: a 3-ball cluster, a stacked pair, oblique landings on the vibrating plate), 30 ms, on
the closed-form SSSS Kirchhoff modes below 1300 Hz (11 modes), 2600 Hz (24) and 10 kHz (106,
the default band of the stream scenes; ``--quick``: 1300 Hz only), modal damping 1 %:
horizontal with c = 0, and 15 degrees with c = 2000 N s/m, d = 2e-5 m (ramp, clamp).

Baseline, in the same run: the slow reference (tailbeam.solvers.stream.reference) with exact
mode shapes and with frozen ones (a contact keeps the shapes of its first touch: the fast
solver's model) at rtol 1e-12, and the frozen one at 1e-13 (the reference's own error).
Against them the fast solver (rtol 1e-12, no residual flexibility, no rest rules) at its
defaults (shapes refreshed every SHAPE_TRAVEL = 1 mm of lateral travel, reused within
SHAPE_REUSE = 0.25 mm) and with both distances set to 1e-4, 1e-5 and 1e-6 m (module
constants of the fast solver, changed here for this study only). Measure: the worst relative
difference over every contact record's fields (tests/test_stream_solver.py: times on 1 ms,
speeds and positions on 1 m/s and 1 m, peak force and penetration relative), and the same
over the impacts only (contacts whose peak force is at least GRAZE = 1 % of the largest: a
graze's relative peak force is ill-conditioned); the wall times.

Writes DIR/bench_stream_reference_modal.csv, DIR/table.md and DIR/refresh.png. Run
single-threaded (OMP_NUM_THREADS=1). The first fast run compiles the kernels (a warm-up, not
kept).
"""

import argparse
import csv
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "tests"))
from stream_scenes import modal_scene  # noqa: E402
from test_stream_solver import _particles, _worst_difference  # noqa: E402

from tailbeam.physics.bodies import Plate  # noqa: E402
from tailbeam.physics.incline import InclinedPlate  # noqa: E402
from tailbeam.plate.closed_forms import ssss_kirchhoff_basis  # noqa: E402
from tailbeam.solvers.stream.active.plate import shapes as active_shapes  # noqa: E402
from tailbeam.solvers.stream.driver import loop as stream  # noqa: E402
from tailbeam.solvers.stream.driver import membership as stream_membership  # noqa: E402
from tailbeam.solvers.stream.plate import StreamPlate  # noqa: E402
from tailbeam.solvers.stream.reference.plate import ReferencePlate  # noqa: E402
from tailbeam.solvers.stream.reference.solver import simulate_stream_reference  # noqa: E402

DURATION, ZETA = 0.03, 0.01
SCENES = {
    "horizontal, c = 0": (0.0, {}),
    "15 deg, c = 2000, clamp": (15.0, dict(damping=2000.0, penetration=2e-5)),
}
GRAZE = 0.01  # contacts with a peak force below this fraction of the largest are grazes
REFRESH = (1e-4, 1e-5, 1e-6)  # m: shape refresh and reuse distances of the fast solver
DEFAULTS = (stream_membership.SHAPE_TRAVEL, active_shapes.SHAPE_REUSE)
DEFAULT_MARKERS = (  # (column, marker, style, legend) of the fast solver at its defaults
    ("vs_frozen", "s", dict(ms=8, mfc="none"), "fast (defaults) vs frozen reference"),
    ("vs_exact", "x", dict(ms=9, mew=2), "fast (defaults) vs exact reference"),
    ("vs_exact_impacts", "+", dict(ms=11, mew=2), "same, impacts only (no grazes)"),
)


def reference(scene, basis, law, shapes, rtol=1e-12):
    balls, incline = scene
    t = time.perf_counter()
    res = simulate_stream_reference(balls, incline, DURATION, rtol=rtol, **law,
                                    plate=ReferencePlate(basis, ZETA, shapes))  # fmt: skip
    return res, time.perf_counter() - t


def fast(scene, basis, law, refresh=None):
    """The fast solver, its shape distances at ``refresh`` (None: its defaults)."""
    travel, reuse = DEFAULTS if refresh is None else (refresh, refresh)
    stream_membership.SHAPE_TRAVEL, active_shapes.SHAPE_REUSE = travel, reuse
    try:
        balls, incline = scene
        plate = StreamPlate(basis, np.full(basis.n_modes, ZETA), residual_flexibility=False)
        t = time.perf_counter()
        run = stream.solve_stream(_particles(balls), incline, DURATION, rtol=1e-12,
                                  rest_speed=0.0, progress=False, plate=plate, **law)  # fmt: skip
        return run, time.perf_counter() - t
    finally:
        stream_membership.SHAPE_TRAVEL, active_shapes.SHAPE_REUSE = DEFAULTS


def _impacts(ref, other):
    """The contacts of ``ref`` and ``other`` (matched one to one in order of ball, partner
    and start) whose reference peak force is at least GRAZE of the largest: a graze's
    relative peak force is ill-conditioned."""

    def order(cs):
        return sorted(cs, key=lambda c: (c.ball, c.partner, c.t_start))

    a, b = order(ref), order(other)
    top = max(c.peak_force for c in a)
    keep = [k for k, c in enumerate(a) if c.peak_force >= GRAZE * top]
    if len(a) != len(b):
        return a, b  # not matched: _worst_difference reports it
    return [a[k] for k in keep], [b[k] for k in keep]


def study(name, fmax):
    """Rows (dicts) of one scene at one band."""
    inclination, law = SCENES[name]
    incline = InclinedPlate(inclination=inclination)
    scene = (modal_scene(incline), incline)
    basis = ssss_kirchhoff_basis(Plate(), fmax)
    exact, t_exact = reference(scene, basis, law, "exact")
    frozen, t_frozen = reference(scene, basis, law, "frozen")
    truth, t_truth = reference(scene, basis, law, "frozen", rtol=1e-13)
    base = dict(scene=name, fmax_hz=fmax, modes=basis.n_modes, contacts=len(exact.contacts))

    def row(case, contacts, wall, steps):
        return dict(base, case=case, vs_exact=_worst_difference(exact.contacts, contacts),
                    vs_frozen=_worst_difference(frozen.contacts, contacts),
                    vs_exact_impacts=_worst_difference(*_impacts(exact.contacts, contacts)),
                    wall_s=wall, steps=steps)  # fmt: skip

    rows = [
        row("reference, exact shapes", exact.contacts, t_exact, exact.steps),
        row("reference, frozen shapes", frozen.contacts, t_frozen, frozen.steps),
        row("reference, frozen, rtol 1e-13", truth.contacts, t_truth, truth.steps),
    ]
    run, wall = fast(scene, basis, law)
    rows.append(row("fast, defaults (1 mm / 0.25 mm)", run.contacts, wall,
                    run.stats["kernel_steps"]))  # fmt: skip
    for d in REFRESH:
        run, wall = fast(scene, basis, law, d)
        rows.append(row(f"fast, refresh {d:g} m", run.contacts, wall, run.stats["kernel_steps"]))
    for r in rows:
        print(f"{name:24s} {fmax:6.0f} Hz  {r['case']:32s} vs exact {r['vs_exact']:.2e} "
              f"(impacts {r['vs_exact_impacts']:.2e})  vs frozen {r['vs_frozen']:.2e}  "
              f"{r['wall_s']:.2f} s", flush=True)  # fmt: skip
    return rows


def plot(rows, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(SCENES), figsize=(11, 6.4), sharey=True)
    for ax, name in zip(axes, SCENES, strict=True):
        for k, fmax in enumerate(sorted({r["fmax_hz"] for r in rows})):
            mine = [r for r in rows if r["scene"] == name and r["fmax_hz"] == fmax]
            ref = {r["case"]: r for r in mine}
            runs = [r for r in mine if r["case"].startswith("fast, refresh")]
            d = [float(r["case"].split()[2]) for r in runs]
            color = f"C{k}"
            label = f"{fmax:.0f} Hz ({mine[0]['modes']} modes)"
            ax.loglog(d, [r["vs_frozen"] for r in runs], "o-", color=color,
                      label=f"fast vs frozen reference, {label}")  # fmt: skip
            default = ref["fast, defaults (1 mm / 0.25 mm)"]
            for key, marker, style, what in DEFAULT_MARKERS:
                ax.loglog([DEFAULTS[0]], [default[key]], marker, color=color,
                          label=f"{what}, {label}", **style)  # fmt: skip
            ax.axhline(ref["reference, exact shapes"]["vs_frozen"], color=color, ls="--",
                       label=f"exact vs frozen reference, {label}")  # fmt: skip
            ax.axhline(ref["reference, frozen, rtol 1e-13"]["vs_frozen"], color=color, ls=":",
                       label=f"reference rtol 1e-13 vs 1e-12, {label}")  # fmt: skip
        ax.set_title(name)
        ax.set_xlabel("shape refresh distance of the fast solver (m); at 1e-3: its defaults")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("worst relative difference, every ContactRecord field")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, fontsize=7, loc="lower center", ncol=3)
    fig.tight_layout(rect=(0, 0.27, 1, 1))
    fig.savefig(path, dpi=120)
    plt.close(fig)


def write(rows, out):
    with open(out / "bench_stream_reference_modal.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    lines = ["| scene | band | case | vs exact ref. | vs exact, impacts | vs frozen ref. | "
             "wall (s) | steps |", "|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for r in rows:
        lines.append(f"| {r['scene']} | {r['fmax_hz']:.0f} Hz, {r['modes']} modes | {r['case']} | "
                     f"{r['vs_exact']:.2e} | {r['vs_exact_impacts']:.2e} | {r['vs_frozen']:.2e} | "
                     f"{r['wall_s']:.2f} | {r['steps']} |")  # fmt: skip
    (out / "table.md").write_text("\n".join(lines) + "\n")


def main(out_dir, quick: bool = False):
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    bands = (1300.0,) if quick else (1300.0, 2600.0, 10000.0)
    warm = (modal_scene(InclinedPlate()), InclinedPlate())
    fast(warm, ssss_kirchhoff_basis(Plate(), 1300.0), {})  # compile the kernels
    rows = [r for fmax in bands for name in SCENES for r in study(name, fmax)]
    write(rows, out)
    plot(rows, out / "refresh.png")
    print(f"wrote {out}/bench_stream_reference_modal.csv, table.md, refresh.png")
    return rows


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--quick", action="store_true", help="only the 1300 Hz band")
    args = parser.parse_args()
    main(args.out, quick=args.quick)
