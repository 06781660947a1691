"""Friction's cost on the reference caving stream, rigid and modal plate, and what its
moment on the modal plate changes at the sensors.

    python benchmarks/bench_friction_stream.py --out DIR [--quick] [--particles N]
        [--stiction V] [--skip-moment]

The scene is ``examples/caving_stream.toml`` (particles at 200 per second onto the 30-degree
SSSS plate, modes to 10 kHz coupled both ways with contact tails, two 51.2 kHz sensors; the
stream lasts n / 200 s and the simulation 1 s longer: 6 s for its 1000 particles). Each case
runs ``tailbeam.simulate`` (the fast stream solver) and then the sensor signals (the modal
plate's replay of the recorded loads) in its own process after one warm-up run that fills
the numba and basis caches. Timed inside it: the process's CPU seconds of the run and of the
sensor signals (the measure to compare on a shared machine) and the wall time of both; peak
memory is the process's maximum resident set (numba and the basis included); the load
average when the case ended is recorded beside them.

Cases, on the rigid and on the modal plate: frictionless, and with ``[contact.friction]``
static 0.5, dynamic 0.4, rolling 0.1 (coal and sandstone on steel in the DEM literature of
top-coal caving: mu 0.3-0.6), stiction velocity V (default 1e-3 m/s, the manual's advice
for lumps that stop) and transition velocity 2 V. On the modal plate once more with the
friction force's moment on the plate left out (a private switch,
``friction_pairs._PLATE_MOMENT``): the relative change of each sensor's in-band RMS (0-10 kHz)
is what the moment contributes (``--skip-moment``: not run).

On the rigid plate the friction case runs once more with the active set integrated as one
set (a private switch, ``loop._ISLANDS``; ``--skip-one-set``: not run): what integrating
its islands each with its own step saves. ``--models`` picks the plates (default both).

``--quick``: 100 particles (``--particles`` sets the count). Writes DIR/table.md,
DIR/results.json and every case's scene and results (DIR/<case>.toml, DIR/<case>.json).
"""

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np
from child import run_case_in_child

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "examples" / "caving_stream.toml"
RATE = 200.0
IN_BAND_HZ = 10_000.0
FRICTION = (
    "\n[contact.friction]\nstatic = 0.5\ndynamic = 0.4\nstiction_velocity = {vs!r}\n"
    "transition_velocity = {vd!r}\nrolling = 0.1\n"
)


def scene_text(n: int, model: str, stiction: float | None) -> str:
    """The reference scene with n particles on ``model`` ("rigid": no modal keys, no
    sensors), with friction of stiction velocity ``stiction`` (m/s) or frictionless (None)."""
    stop = n / RATE
    text = SCENE.read_text()
    text = text.replace("duration = 6.0 ", f"duration = {stop + 1.0!r} ")
    text = text.replace("stop = 5.0 ", f"stop = {stop!r} ")
    if model == "rigid":
        text = text[: text.index("[[sensors]]")]
        text = text.replace('model = "modal"', 'model = "rigid"')
        keep = [ln for ln in text.splitlines() if not ln.startswith(("boundary", "fmax"))]
        text = "\n".join(keep) + "\n"
    if stiction is not None:
        head, tail = text.split("[plate]", 1)
        text = head + FRICTION.format(vs=stiction, vd=2.0 * stiction) + "\n[plate]" + tail
    return text


def run_case(path: str, moment: bool = True, islands: bool = True) -> dict:
    """Child process: simulate the scene file; wall time, peak memory, counts, sensor RMS."""
    import resource

    import tailbeam
    from tailbeam.io.scene_file import load_scene
    from tailbeam.solvers.stream.active import friction_pairs
    from tailbeam.solvers.stream.driver import loop

    friction_pairs._PLATE_MOMENT = moment
    loop._ISLANDS = islands
    scene = load_scene(path)
    t0, c0 = time.perf_counter(), time.process_time()
    result = tailbeam.simulate(scene, solver="stream", progress=False)
    c1 = time.process_time()
    outputs = result.sensor_outputs or {}
    c2, wall = time.process_time(), time.perf_counter() - t0
    loads = getattr(result.plate, "loads", None)
    return {
        "wall_s": wall,
        "cpu_s": c2 - c0,
        "cpu_run_s": c1 - c0,
        "cpu_sensors_s": c2 - c1,
        "load_average": os.getloadavg()[0],
        "load_nodes": None if loads is None else int(loads.n_nodes),
        "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
        "particles": len(result.particles),
        "contacts": len(result.impacts),
        "kernel_steps": result.stats.get("kernel_steps"),
        "energy_friction": result.stats.get("energy_friction", 0.0),
        "sensor_rms_in_band": {
            name: rms_below(out.t, out.acceleration, IN_BAND_HZ) for name, out in outputs.items()
        },
    }


def rms_below(t, a, f_hz: float) -> float:
    """RMS (m/s^2) of a(t) (uniform t, s) keeping only its content at or below f_hz (Hz)."""
    spectrum = np.fft.rfft(np.asarray(a, dtype=float))
    spectrum[np.fft.rfftfreq(len(a), t[1] - t[0]) > f_hz] = 0.0
    return float(np.sqrt(np.mean(np.fft.irfft(spectrum, len(a)) ** 2)))


def _in_child(out_dir: Path, name: str, text: str, moment: bool = True,
              islands: bool = True) -> dict:  # fmt: skip
    path = out_dir / f"{name}.toml"
    path.write_text(text)
    result = run_case_in_child("bench_friction_stream", str(path), moment, islands)
    (out_dir / f"{name}.json").write_text(json.dumps(result))
    return result


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, type=Path)
    parser.add_argument("--quick", action="store_true", help="100 particles")
    parser.add_argument("--particles", type=int, default=None)
    parser.add_argument("--stiction", type=float, default=1e-3, help="m/s")
    parser.add_argument("--skip-moment", action="store_true",
                        help="do not run the modal case without friction's moment")  # fmt: skip
    parser.add_argument("--skip-one-set", action="store_true",
                        help="do not run the rigid friction case as one set")  # fmt: skip
    parser.add_argument("--models", nargs="+", choices=("rigid", "modal"),
                        default=["rigid", "modal"])  # fmt: skip
    args = parser.parse_args(argv)
    n = args.particles or (100 if args.quick else 1000)
    out = args.out
    out.mkdir(parents=True, exist_ok=True)
    print(f"warm-up (numba, basis caches): {min(n, 20)} particles", file=sys.stderr)
    print(f"load: {os.getloadavg()}", file=sys.stderr)
    for model in args.models:
        _in_child(out, f"warmup_{model}", scene_text(min(n, 20), model, args.stiction))
    rows, results = [], {}
    for model in args.models:
        cases = [("frictionless", None, True, True), ("friction", args.stiction, True, True)]
        if model == "modal" and not args.skip_moment:
            cases.append(("friction, no moment", args.stiction, False, True))
        if model == "rigid" and not args.skip_one_set:
            cases.append(("friction, one set", args.stiction, True, False))
        for label, vs, moment, islands in cases:
            name = f"{model}_{label.replace(', ', '_').replace(' ', '_')}"
            print(f"{name}: {n} particles", file=sys.stderr)
            text = scene_text(n, model, vs)
            results[name] = r = _in_child(out, name, text, moment, islands)
            rows.append((model, label, r))
    (out / "results.json").write_text(json.dumps(results, indent=1))
    (out / "table.md").write_text(_table(n, args.stiction, rows, results))
    print((out / "table.md").read_text())
    return 0


def _table(n, stiction, rows, results) -> str:
    lines = [
        f"{n} particles, friction mu_s 0.5, mu_d 0.4, mu_r 0.1, v_s {stiction:g} m/s, "
        f"v_d {2 * stiction:g} m/s",
        "",
        "| plate | case | CPU s: run + sensors | x frictionless (CPU) | wall s | load average "
        "| peak MB | contacts | kernel steps | load nodes |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for model, label, r in rows:
        base = results[f"{model}_frictionless"]["cpu_s"]
        lines.append(
            f"| {model} | {label} | {r['cpu_run_s']:.1f} + {r['cpu_sensors_s']:.1f} | "
            f"{r['cpu_s'] / base:.2f} | {r['wall_s']:.1f} | {r['load_average']:.1f} | "
            f"{r['peak_rss_mb']:.0f} | {r['contacts']} | {r['kernel_steps']} | "
            f"{r['load_nodes'] if r['load_nodes'] is not None else '-'} |"
        )
    if "modal_friction_no_moment" not in results:
        return "\n".join(lines) + "\n"
    with_m = results["modal_friction"]["sensor_rms_in_band"]
    without = results["modal_friction_no_moment"]["sensor_rms_in_band"]
    lines += [
        "",
        "| sensor | in-band RMS with the moment | without | change |",
        "|---|---|---|---|",
    ]
    for name in sorted(with_m):
        change = (without[name] - with_m[name]) / with_m[name]
        lines.append(f"| {name} | {with_m[name]:.4g} | {without[name]:.4g} | {change:+.2%} |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    raise SystemExit(main())
