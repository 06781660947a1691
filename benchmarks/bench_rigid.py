"""The rigid-plate solver against scipy's solve_ivp: error and time against the tolerance.

    python benchmarks/bench_rigid.py --out DIR [--quick]

Reproduces the speed figure of docs/rigid-solver.md ("Speed"). Scenes (paper section 4; the
contact parameters of tailbeam.scene.ContactSettings, plus one scene at c = 800 N s/m with
more bounces): one ball dropped from 0.1 m gap, coal at 1 m/s, coal at 2 m/s, sandstone at
1 m/s, 1 s simulated. Truth: the rigid reference (tailbeam.solvers.rigid.reference: DOP853 at
rtol 1e-12 restarted at every kink). Error: the largest relative error over every impact's
peak force and every apex height reached within the run. Baseline, in the same run: solve_ivp
(LSODA, RK45, DOP853, Radau, BDF) on the full ODE in (z, vz) with the IMPACT force, contact
start and end as terminal events (restarted there), dF/dt = 0 and vz = 0 as events for the
peaks and apexes (located, not sampled; the force at every step point is also a peak
candidate, in case a dF/dt root is stepped over). Also the numba compile time of a fresh
install. ``--quick``: one scene, two tolerances, DOP853 and LSODA (under a minute).

Writes DIR/bench_rigid.csv, DIR/table.md and DIR/bench_rigid.png. Run single-threaded
(OMP_NUM_THREADS=1) for reproducible timings.
"""

import argparse
import csv
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

from tailbeam import CARBON_STEEL, COAL, SANDSTONE, Ball, Plate
from tailbeam.io.output import atomic_output_dir
from tailbeam.physics import impact
from tailbeam.physics.bodies import STANDARD_GRAVITY as G
from tailbeam.physics.contact_law import impact_force_scalar
from tailbeam.scene import ContactSettings
from tailbeam.solvers.rigid import simulate_rigid
from tailbeam.solvers.rigid.reference import simulate_rigid_reference

CONTACT = ContactSettings()  # the scene defaults

DURATION = 1.0
GAP = 0.1
RADIUS = 0.03
# (label, material, speed m/s, damping N s/m or None for the scene default)
SCENES = (
    ("coal 1 m/s", COAL, 1.0, None),
    ("coal 2 m/s", COAL, 2.0, None),
    ("sandstone 1 m/s", SANDSTONE, 1.0, None),
    ("coal 1 m/s, c=800", COAL, 1.0, 800.0),
)
METHODS = ("LSODA", "RK45", "DOP853", "Radau", "BDF")
RTOLS = tuple(10.0**-k for k in range(4, 13))
QUICK_RTOLS = (1e-6, 1e-9)
TIME_BUDGET = 30.0  # s: a method slower than this at some rtol is not run at tighter ones


def _law(material, damping=None):
    import dataclasses

    contact = CONTACT if damping is None else dataclasses.replace(CONTACT, damping=damping)
    return contact.law_for(Ball("x", material, RADIUS, (0, 0, 1)), CARBON_STEEL)


def _scene(material, speed, damping=None):
    ball = Ball("A", material, RADIUS, (0.0, 0.0, RADIUS + GAP), (0.0, 0.0, -speed))
    return ball, _law(material, damping)


def _ref_lists(ref):
    """Reference peak forces, and the apex heights reached within the run."""
    peaks = [i.peak_force for i in ref.impacts]
    apexes = [
        i.next_apex_height
        for i in ref.impacts
        if math.isfinite(i.next_apex_height) and i.t_end + i.v_out / G <= DURATION
    ]
    return peaks, apexes


def _metric(peaks, apexes, ref):
    """Max relative error of peak forces and apex heights against the reference impacts
    (inf if any is missing or nan)."""
    ref_peaks, ref_apex = _ref_lists(ref)
    if len(peaks) < len(ref_peaks) or len(apexes) < len(ref_apex):
        return math.inf
    pairs = list(zip(peaks, ref_peaks, strict=False)) + list(zip(apexes, ref_apex, strict=False))
    errs = [abs(p / q - 1.0) for p, q in pairs]
    return max(errs) if all(math.isfinite(x) for x in errs) else math.inf


def run_tailbeam(ball, law, rtol, ref, repeats=5):
    simulate_rigid([ball], Plate(), [law], DURATION, rtol=rtol)  # warm (compiled, cached)
    best = math.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = simulate_rigid([ball], Plate(), [law], DURATION, rtol=rtol)
        best = min(best, time.perf_counter() - t0)
    peaks, apexes = _ref_lists(res)
    return best, res.stats["nfev"], _metric(peaks, apexes, ref)


def run_solve_ivp(ball, law, method, rtol, ref):
    """The full ODE in (z, vz); restarted at contact start/end; peaks and apexes as events."""
    m, r = ball.mass, ball.radius
    k, e, c, d, clamp = law.stiffness, law.exponent, law.damping, law.penetration, law.clamp

    def rhs(t, y):
        f = impact_force_scalar(r - y[0], -y[1], k, e, c, d, clamp)
        return [y[1], f / m - G]

    impact.region_force_rate(1e-6, 1.0, 0.0, k, e, c, d, True)  # compiled before the clock runs
    impact_force_scalar(1e-6, 1.0, k, e, c, d, clamp)

    def dforce(t, y):  # dF/dt along the motion (unclamped formula; events only in contact)
        delta, u = r - y[0], -y[1]
        f = impact_force_scalar(delta, u, k, e, c, d, clamp)
        return impact.region_force_rate(delta, u, G - f / m, k, e, c, d, delta < d)

    def surface(t, y):
        return y[0] - r

    def apex(t, y):
        return y[1]

    surface.terminal = True
    dforce.direction = -1.0
    apex.direction = -1.0
    atol = [rtol * 1e-4, rtol * 1.0]
    t, y = 0.0, np.array(ball.position[2:], dtype=float).tolist() + [ball.velocity[2]]
    peaks, apexes, nfev, in_contact = [], [], 0, False
    t0 = time.perf_counter()
    for _ in range(10_000):
        if t >= DURATION:
            break
        surface.direction = 1.0 if in_contact else -1.0
        events = [surface, dforce] if in_contact else [surface, apex]
        sol = solve_ivp(rhs, (t, DURATION), y, method=method, rtol=rtol, atol=atol, events=events)
        nfev += sol.nfev
        if in_contact:  # located dF/dt = 0 points, and every step point (a missed root)
            pts = list(sol.y_events[1]) + list(sol.y.T)
            peaks.append(max(impact_force_scalar(r - z, -v, k, e, c, d, clamp) for z, v in pts))
        else:
            apexes.extend(z - r for z, _ in sol.y_events[1])
        t, y = sol.t[-1], sol.y[:, -1]
        if sol.status != 1:
            break
        in_contact = not in_contact
        if time.perf_counter() - t0 > 5.0 * TIME_BUDGET:
            return time.perf_counter() - t0, nfev, math.inf
    wall = time.perf_counter() - t0
    return wall, nfev, _metric(peaks, apexes[1:] if ball.velocity[2] > 0 else apexes, ref)


def compile_time():
    """Seconds of the first call with an empty numba cache (a fresh install), in a subprocess."""
    code = (
        "import time; t0 = time.perf_counter();"
        "from tailbeam import COAL, CARBON_STEEL, Ball, Plate, ball_plate_law;"
        "from tailbeam.solvers.rigid import simulate_rigid;"
        "law = ball_plate_law(COAL, 0.03, CARBON_STEEL, damping=800.0);"
        "b = Ball('A', COAL, 0.03, (0, 0, 0.031), (0, 0, -1.0));"
        "simulate_rigid([b], Plate(), [law], 0.01); print(time.perf_counter() - t0)"
    )
    out = {}
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        for label in ("cold (compile)", "warm (numba cache)"):
            run = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True)
            out[label] = float(run.stdout.decode().strip() or "nan")
    return out


def main(out_dir, quick=False):
    rtols = QUICK_RTOLS if quick else RTOLS
    scenes = SCENES[:1] if quick else SCENES
    methods = ("DOP853", "LSODA") if quick else METHODS
    rows = []
    laws = {}
    for label, material, speed, damping in scenes:
        ball, law = _scene(material, speed, damping)
        laws[label] = law
        ref = simulate_rigid_reference([ball], Plate(), [law], DURATION)
        n_imp = len(ref.impacts)
        for rtol in rtols:
            wall, nfev, err = run_tailbeam(ball, law, rtol, ref)
            rows.append((label, n_imp, "tailbeam", rtol, err, wall, nfev))
        for method in methods:
            for rtol in rtols:
                wall, nfev, err = run_solve_ivp(ball, law, method, rtol, ref)
                rows.append((label, n_imp, f"solve_ivp {method}", rtol, err, wall, nfev))
                if wall > TIME_BUDGET:
                    break
    compile_s = compile_time()
    with atomic_output_dir(out_dir) as tmp:
        _write(tmp, rows, compile_s, scenes, laws)
    return rows


def _write(tmp: Path, rows, compile_s, scenes, laws):
    header = ["scene", "impacts", "method", "rtol", "max_rel_error", "wall_s"]
    header += ["ms_per_ball_per_sim_s", "nfev"]
    with open(tmp / "bench_rigid.csv", "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        for sc, n, meth, rtol, err, wall, nfev in rows:
            w.writerow([sc, n, meth, f"{rtol:.0e}", f"{err:.3e}", f"{wall:.6f}",
                        f"{1e3 * wall / DURATION:.4f}", nfev])  # fmt: skip
    lines = ["# Rigid solver benchmark (1 ball, 1 s simulated, vs reference DOP853 rtol 1e-12)", ""]
    for label, law in laws.items():
        lines.append(
            f"- {label}: c = {law.damping:g} N s/m, d = {law.penetration:g} m, e = "
            f"{law.exponent:g}, k = {law.stiffness:.4g} N/m^e, drop gap {GAP} m"
        )
    lines.append("")
    lines.append("| scene | method | rtol | max rel. error | wall s | ms/ball/sim-s | nfev |")
    lines.append("|---|---|---|---|---|---|---|")
    for sc, _, meth, rtol, err, wall, nfev in rows:
        lines.append(f"| {sc} | {meth} | {rtol:.0e} | {err:.2e} | {wall:.4f} | "
                     f"{1e3 * wall / DURATION:.3f} | {nfev} |")  # fmt: skip
    lines += ["", "## Speed-up at max relative error <= 1e-8", ""]
    lines.append("| scene | tailbeam fastest (ms) | fastest solve_ivp (method, ms) | speed-up |")
    lines.append("|---|---|---|---|")
    for label, *_ in scenes:
        ok = [r for r in rows if r[0] == label and r[4] <= 1e-8]
        ours = [r[5] for r in ok if r[2] == "tailbeam"]
        theirs = [(r[5], r[2]) for r in ok if r[2] != "tailbeam"]
        t_ours = min(ours) if ours else math.nan
        if theirs:
            t_best, who = min(theirs)
            lines.append(f"| {label} | {1e3 * t_ours:.3f} | {who} {1e3 * t_best:.1f} | "
                         f"{t_best / t_ours:.0f}x |")  # fmt: skip
        else:
            lines.append(f"| {label} | {1e3 * t_ours:.3f} | none reached 1e-8 | - |")
    lines += ["", "## numba compile time (first call of a fresh install; s)", ""]
    lines += [f"- {k}: {v:.2f} s" for k, v in compile_s.items()]
    (tmp / "table.md").write_text("\n".join(lines) + "\n")
    _plot(tmp / "bench_rigid.png", rows, scenes)


def _plot(path, rows, scenes):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, len(scenes), figsize=(4.5 * len(scenes), 4.2), squeeze=False)
    for ax, (label, *_) in zip(axes[0], scenes, strict=True):
        for meth in sorted({r[2] for r in rows if r[0] == label}):
            pts = [(r[4], 1e3 * r[5]) for r in rows if r[0] == label and r[2] == meth]
            pts = [p for p in pts if math.isfinite(p[0]) and p[0] > 0]
            if pts:
                x, y = zip(*pts, strict=True)
                ax.loglog(x, y, "o-" if meth == "tailbeam" else ".--", label=meth)
        ax.axvline(1e-8, color="grey", lw=0.8)
        ax.set_title(label)
        ax.set_xlabel("max relative error (peak forces, apex heights)")
        ax.set_ylabel("ms per ball per simulated second")
        ax.grid(True, which="both", lw=0.3)
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="output directory")
    parser.add_argument("--quick", action="store_true", help="small ladder, < 60 s")
    args = parser.parse_args()
    main(args.out, quick=args.quick)
    print((Path(args.out) / "table.md").read_text())
