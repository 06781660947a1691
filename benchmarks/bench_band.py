"""The automatic modal band on 30 balls: speed against error, with a converged run as truth.

    python benchmarks/bench_band.py --out DIR [--quick]

Reproduces the figure of docs/band-and-cost.md ("How good the choice is: 30 balls"). Scene:
examples/thirty_balls_modal.toml (30 coal and sandstone balls, radius 10-40 mm, 3 m/s, on a
6 x 5 grid of the default SSSS steel plate; two sensors at 51.2 kHz, 20 kHz band). Rows:

- "auto": the default settings (the band, theory and mesh tailbeam.solvers.modal_setup
  chooses);
- "fmax N kHz": the same scene with [plate] fmax = N kHz, default steps;
- "converged": fmax 40 kHz (``--quick``: 30 kHz) and 400 steps per contact (default 200),
  the truth every row is compared with, measured in the same run.

Errors: peak force, the largest relative difference over the 30 impacts (beside the band's
own estimate for the worst ball, and the largest measured / estimated ratio); sensors: the
relative difference of the in-band RMS (the sampled signal's content up to the sensor
bandwidth) and of the RMS of the whole sampled signal, worst sensor. Timings (wall clock,
one BLAS thread): ``tailbeam simulate`` in a fresh process, "first ever" with empty numba
and basis caches, "cold" with an empty basis cache, "cached" with the basis cached; the
in-process rows time ``simulate_scene_modal`` with the basis cached (the eigen-solve's time
is in the basis columns).

Writes DIR/bench_band.csv and DIR/table.md.
"""

import argparse
import csv
import dataclasses
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from tailbeam.io.output import atomic_output_dir
from tailbeam.io.scene_file import load_scene
from tailbeam.solvers.modal_setup.band import _contacts, force_error_estimate
from tailbeam.solvers.modal_setup.setup import describe_choices
from tailbeam.solvers.single_ball import simulate_scene_modal

SCENE = Path(__file__).resolve().parents[1] / "examples" / "thirty_balls_modal.toml"


def in_band_rms(out) -> float:
    """RMS of a SensorOutput's content up to its bandwidth (FFT mask), m/s^2."""
    spec = np.fft.rfft(out.acceleration)
    freq = np.fft.rfftfreq(len(out.acceleration), 1.0 / out.chain.sample_rate)
    spec[freq > out.chain.bandwidth_hz] = 0.0
    return float(np.sqrt(np.mean(np.fft.irfft(spec, len(out.acceleration)) ** 2)))


def metrics(result) -> dict:
    """Peak force per (ball, impact index); in-band and full RMS per sensor."""
    peaks = {(imp.ball, imp.index): imp.peak_force for imp in result.impacts}
    outs = result.sensor_outputs
    return {
        "peaks": peaks,
        "rms_band": {n: in_band_rms(o) for n, o in outs.items()},
        "rms_all": {n: float(np.sqrt(np.mean(o.acceleration**2))) for n, o in outs.items()},
    }


def compare(m, truth, estimates) -> dict:
    """Largest relative differences of ``m`` against ``truth``; the largest ratio of a ball's
    measured peak-force error to its estimate (``estimates``: ball -> estimated error)."""
    common = truth["peaks"].keys() & m["peaks"].keys()
    missing = len(truth["peaks"]) - len(common)
    errors = {k: abs(m["peaks"][k] / truth["peaks"][k] - 1.0) for k in common}
    force = max(errors.values())
    ratio = max(e / estimates[k[0]] for k, e in errors.items())
    band = max(abs(m["rms_band"][n] / v - 1.0) for n, v in truth["rms_band"].items())
    full = max(abs(m["rms_all"][n] / v - 1.0) for n, v in truth["rms_all"].items())
    return {
        "peak_force": force,
        "worst_measured_over_estimate": ratio,
        "rms_in_band": band,
        "rms_all": full,
        "unmatched": missing,
    }


def run_scene(scene, fmax=None, steps=None):
    """simulate_scene_modal with fmax (Hz) and steps_per_contact; (result, wall s, basis s)."""
    if fmax is not None:
        scene = dataclasses.replace(scene, modal=dataclasses.replace(scene.modal, fmax_hz=fmax))
    options = {} if steps is None else {"steps_per_contact": steps}
    t0 = time.perf_counter()
    result = simulate_scene_modal(scene, **options)
    _ = result.sensor_outputs  # the sensor replay is part of the run
    return result, time.perf_counter() - t0


def cli_time(cache_dir, numba_dir=None) -> float:
    """Wall time of `tailbeam simulate SCENE` in a fresh process."""
    env = dict(os.environ, TAILBEAM_CACHE_DIR=str(cache_dir), OPENBLAS_NUM_THREADS="1")
    env["OMP_NUM_THREADS"] = "1"
    if numba_dir is not None:
        env["NUMBA_CACHE_DIR"] = str(numba_dir)
    with tempfile.TemporaryDirectory() as out:
        t0 = time.perf_counter()
        subprocess.run(
            [sys.executable, "-m", "tailbeam", "simulate", str(SCENE), "--out", out + "/o"],
            env=env,
            check=True,
            capture_output=True,
        )
        return time.perf_counter() - t0


def cli_timings() -> dict:
    """First ever (empty numba and basis caches), cold (empty basis cache), cached (s)."""
    with tempfile.TemporaryDirectory() as tmp:
        first = cli_time(Path(tmp) / "c1", Path(tmp) / "numba")
        cold = cli_time(Path(tmp) / "c2")
        cached = cli_time(Path(tmp) / "c2")
    return {"first_ever_s": first, "cold_s": cold, "cached_s": cached}


def main(out_dir, quick: bool = False) -> Path:
    scene = load_scene(SCENE)
    timings = cli_timings()
    f_conv = 30e3 if quick else 40e3
    truth_result, t_truth = run_scene(scene, fmax=f_conv, steps=400)
    truth = metrics(truth_result)
    rows = []
    auto, t_auto = run_scene(scene)
    rows.append(("auto", auto, t_auto))
    print(describe_choices(auto.info))
    for f in (10e3, 15e3) if quick else (10e3, 15e3, 30e3):
        res, wall = run_scene(scene, fmax=f)
        rows.append((f"fmax {f / 1e3:.0f} kHz", res, wall))
    rows.append((f"converged ({f_conv / 1e3:.0f} kHz, 400 steps)", truth_result, t_truth))
    contacts = _contacts(scene)
    table = []
    for label, res, wall in rows:
        fmax = res.info["band"]["fmax_hz"]
        estimates = {n: force_error_estimate(scene.plate, fmax, c) for n, c in contacts.items()}
        err = compare(metrics(res), truth, estimates)
        basis = res.info["basis"]
        table.append(
            {
                "run": label,
                "fmax_hz": res.info["band"]["fmax_hz"],
                "n_modes": basis["n_modes"],
                "n_dofs": basis.get("n_dofs", ""),
                "eigensolve_s": basis.get("eigensolve_s", ""),
                "run_s_basis_cached": wall,
                "peak_force_err": err["peak_force"],
                "est_force_err": res.info["band"]["truncation_force_error"],
                "worst_measured_over_estimate": err["worst_measured_over_estimate"],
                "rms_in_band_err": err["rms_in_band"],
                "rms_all_err": err["rms_all"],
                "unmatched_impacts": err["unmatched"],
            }
        )
    return _write(out_dir, table, timings)


def _write(out_dir, table, timings) -> Path:
    with atomic_output_dir(out_dir) as tmp:
        with open(tmp / "bench_band.csv", "w", newline="") as fh:
            writer = csv.DictWriter(fh, fieldnames=list(table[0]))
            writer.writeheader()
            writer.writerows(table)
        lines = [
            "| run | fmax [kHz] | modes | DOFs | run [s], basis cached | peak force err "
            "(est.) | worst ball: measured / est. | in-band RMS err | full RMS err |",
            "|---|---|---|---|---|---|---|---|---|",
        ]
        for r in table:
            lines.append(
                f"| {r['run']} | {r['fmax_hz'] / 1e3:.1f} | {r['n_modes']} | {r['n_dofs']} | "
                f"{r['run_s_basis_cached']:.1f} | {r['peak_force_err']:.1e} "
                f"({r['est_force_err']:.1e}) | {r['worst_measured_over_estimate']:.2f} | "
                f"{r['rms_in_band_err']:.1e} | "
                f"{r['rms_all_err']:.1e} |"
            )
        lines.append(
            f"\n`tailbeam simulate examples/thirty_balls_modal.toml`: first ever (empty numba "
            f"and basis caches) {timings['first_ever_s']:.1f} s, cold basis "
            f"{timings['cold_s']:.1f} s, basis cached {timings['cached_s']:.1f} s."
        )
        (tmp / "table.md").write_text("\n".join(lines) + "\n")
    print((Path(out_dir) / "table.md").read_text())
    return Path(out_dir)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--quick", action="store_true", help="converged run at 30 kHz")
    args = parser.parse_args()
    main(args.out, quick=args.quick)
