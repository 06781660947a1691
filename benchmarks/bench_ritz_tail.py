"""Cost and accuracy of the Ritz tail (``plate.tail = "ritz"``) beside the quasi-static tail.

    python benchmarks/bench_ritz_tail.py --out DIR [--cases test default sweep] [--quick]

Reproduces the table of docs/fe-convergence.md ("What the Ritz tail costs"). Through the scene
path (``simulate_scene_modal``, default 200 steps per contact), each case runs with
``tail = "quasi-static"`` (the baseline, in the same run), the default ``tail = "auto"``
(here the Ritz tail with tail_modes = 32) and ``"ritz"`` with ``tail_modes = "auto"`` (k
chosen a posteriori); default and sweep also with tail_modes = 64. Cases:

- test: the FE test case of tests/test_coupled_fe.py (Argyris 8x8, 20 kHz, sandstone 30 mm at
  1 m/s, no damping, 0.6 ms); truth: the full-FE reference (Newmark, 1e-7 s, ~7 s).
- default: the same impact on the default Argyris 23x23 mesh (4805 DOFs) at 20 kHz; cost only
  (its FE reference takes ~10 min: docs/fe-convergence.md has the errors).
- sweep: the base case of benchmarks/bench_sweep.py (examples/single_impact_base.toml: SSSS,
  fmax 5 kHz, auto mesh = Mindlin P4 12x12, coal 30 mm at 2 m/s, 25 ms, sensor at
  12.8 kHz, 1 % damping); truth: the same scene at fmax 40 kHz with tail = "ritz" and
  tail_modes = "auto" (its difference to 40 kHz quasi-static is reported as the truth's own
  uncertainty).

Reported: the Ritz pre-pass time (choose k per point and build), k, modes, the run time (best
of 3, numba warm), the first impact's contact error (restitution, peak force, duration, max
penetration: the largest of the four) and the in-band sensor error (relative L2, 0-10 kHz for
test, 0-5 kHz for sweep). Timings on a shared machine are noisy. ``--quick``: the test case
only. Writes DIR/table.md.
"""

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from tailbeam.io.scene_file import load_scene
from tailbeam.physics.bodies import Ball, Plate
from tailbeam.physics.materials import SANDSTONE
from tailbeam.progress import quiet
from tailbeam.scene import DEFAULT_TAIL_MODES, ContactSettings, ModalPlateSettings, Scene
from tailbeam.solvers.coupled.fe_reference import (
    QUANTITIES,
    impact_quantities,
    in_band,
    relative_l2,
)
from tailbeam.solvers.modal_setup.band import choose_band
from tailbeam.solvers.modal_setup.setup import build_basis
from tailbeam.solvers.single_ball import simulate_scene_modal

ROOT = Path(__file__).parents[1]
FIXED_K = (32, 64)  # also run with plate.tail_modes set (32 is the default) on default/sweep


def _variants(fixed=FIXED_K):
    """(tail, extra ModalPlateSettings) of the compared runs: the baseline, the default
    (tail "auto": the Ritz tail with tail_modes 32), k chosen a posteriori, fixed k."""
    auto = [("quasi-static", {}), ("auto", {}), ("ritz", {"tail_modes": "auto"})]
    return auto + [("ritz", {"tail_modes": k}) for k in fixed if k != DEFAULT_TAIL_MODES]


def _with_tail(scene, tail, **modal):
    m = scene.modal
    fields = {k: getattr(m, k) for k in m.__dataclass_fields__}
    return Scene(scene.balls, scene.plate, scene.contact, duration=scene.duration,
                 plate_model="modal", modal=ModalPlateSettings(**{**fields, **modal, "tail": tail}),
                 sensors=scene.sensors, gravity=scene.gravity)  # fmt: skip


def _impact_scene(divisions, duration=6e-4):
    ball = Ball("b", SANDSTONE, 0.03, (0.05, 0.03, 0.03001), (0.0, 0.0, -1.0))
    modal = ModalPlateSettings(theory="kirchhoff", damping_ratio=0.0, fmax_hz=20000.0,
                               mesh_divisions=divisions)  # fmt: skip
    return Scene((ball,), Plate(), ContactSettings(damping=0.0), duration=duration,
                 plate_model="modal", modal=modal)  # fmt: skip


def _run(scene, basis, repeats=3):
    """(result, best run time s, pre-pass s): the pre-pass is timed once (first call)."""
    best, first = np.inf, None
    for _ in range(repeats):
        t0 = time.perf_counter()
        with quiet():
            res = simulate_scene_modal(scene, basis=basis)
        elapsed = time.perf_counter() - t0
        build = res.info.get("tail", {}).get("build_s", 0.0)
        first = build if first is None else first
        best = min(best, elapsed - build)
    return res, best, first


def _contact_errors(res, q_ref) -> dict:
    q = impact_quantities(res.impacts[0])
    out = {n: abs(q[n] / q_ref[n] - 1.0) for n in QUANTITIES}
    out["contact"] = max(out.values())
    return out


def _sensor_error(res, t, a_ref, point, band_hz):
    a = res.plate.sample(t, [point])["a"][0]
    return relative_l2(in_band(t, a, band_hz), a_ref)


def case_test():
    sys.path.insert(0, str(ROOT / "tests"))
    from test_coupled_fe import _basis, _case

    case = _case("kirchhoff")
    ref = case.reference(1e-7)
    scene = _impact_scene(8, duration=float(ref.t[-1]))
    basis = _basis("kirchhoff", fmax_hz=20000.0)
    q_ref = impact_quantities(ref.impacts[0])
    a_ref = in_band(ref.t, ref.sensor_a[0], 10_000.0)
    win = ref.t <= 3e-3
    rows = []
    for tail, extra in _variants(fixed=()):
        res, run_s, build_s = _run(_with_tail(scene, tail, **extra), basis)
        err = _contact_errors(res, q_ref)
        a = in_band(ref.t, res.plate.sample(ref.t, [case.sensor])["a"][0], 10_000.0)
        err["sensor"] = relative_l2(a[win], a_ref[win])
        rows.append(_row("test (8x8, 20 kHz)", tail, res, basis, run_s, build_s, err))
    return rows


def case_default():
    scene = _impact_scene(None)
    t0 = time.perf_counter()
    basis = build_basis(scene, choose_band(scene))
    print(f"default basis: {basis.info.get('divisions')} divisions, {basis.n_modes} modes, "
          f"{time.perf_counter() - t0:.1f} s (cache {basis.info.get('cache')})")  # fmt: skip
    rows = []
    for tail, extra in _variants():
        res, run_s, build_s = _run(_with_tail(scene, tail, **extra), basis)
        rows.append(_row("default (23x23, 20 kHz)", tail, res, basis, run_s, build_s, {}))
    return rows


def case_sweep():
    base = load_scene(ROOT / "examples" / "single_impact_base.toml")
    base = Scene(
        base.balls,
        base.plate,
        base.contact,
        duration=base.duration,
        plate_model="modal",
        modal=base.modal,
        gravity=base.gravity,
    )  # fmt: skip (no noisy sensor)
    point = (0.1, 0.15)
    truth_scene = _with_tail(base, "ritz", fmax_hz=40000.0, tail_modes="auto")
    basis = build_basis(base, choose_band(base))
    divisions = basis.info.get("divisions")
    truth_scene = _with_tail(truth_scene, "ritz", mesh_divisions=divisions, theory=basis.theory)
    truth_basis = build_basis(truth_scene, choose_band(truth_scene))
    truth, _, _ = _run(truth_scene, truth_basis, repeats=1)
    truth_qs, _, _ = _run(_with_tail(truth_scene, "quasi-static"), truth_basis, repeats=1)
    t = np.arange(0.0, base.duration, 1.0 / 51200.0)
    a_ref = in_band(t, truth.plate.sample(t, [point])["a"][0], 5000.0)
    q_ref = impact_quantities(truth.impacts[0])
    uncertainty = _contact_errors(truth_qs, q_ref)["contact"]
    print(f"sweep truth: {truth_basis.n_modes} modes at 40 kHz ({basis.theory}, {divisions} "
          f"divisions); 40 kHz quasi-static vs ritz: {uncertainty:.1e}")  # fmt: skip
    rows = []
    for tail, extra in _variants():
        res, run_s, build_s = _run(_with_tail(base, tail, **extra), basis)
        err = _contact_errors(res, q_ref)
        err["sensor"] = _sensor_error(res, t, a_ref, point, 5000.0)
        rows.append(_row("sweep base (5 kHz, 25 ms)", tail, res, basis, run_s, build_s, err))
    return rows


def _row(case, tail, res, basis, run_s, build_s, err):
    info = res.info.get("tail", {})
    if tail == "auto":
        tail = f"auto (default): {info.get('model')}"
    if info.get("model") == "ritz":
        tail = f"{tail}, tail_modes = {info['tail_modes']}"
    return {"case": case, "tail": tail, "k": info.get("k", "-"),
            "modes": res.plate.basis.n_modes, "prepass_s": build_s, "run_s": run_s,
            "contact": err.get("contact"), "sensor": err.get("sensor")}  # fmt: skip


def _fmt(v, spec):
    return "-" if v is None else format(v, spec)


def main(out_dir, cases=("test", "default", "sweep")):
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for name in cases:
        rows += {"test": case_test, "default": case_default, "sweep": case_sweep}[name]()
    lines = [
        "| case | tail | k | modes | Ritz pre-pass s | run s (best of 3) | contact error | "
        "sensor error |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['case']} | {r['tail']} | {r['k']} | {r['modes']} | {r['prepass_s']:.3f} | "
            f"{r['run_s']:.3f} | {_fmt(r['contact'], '.2e')} | {_fmt(r['sensor'], '.2e')} |"
        )
    text = "\n".join(lines) + "\n"
    (out / "table.md").write_text(text)
    print(text)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--cases", nargs="+", default=["test", "default", "sweep"],
                        choices=["test", "default", "sweep"])  # fmt: skip
    parser.add_argument("--quick", action="store_true", help="the test case only")
    args = parser.parse_args()
    main(args.out, ["test"] if args.quick else args.cases)
