"""The stream solver on the reference caving stream: speed, memory and accuracy.

    python benchmarks/bench_stream.py --out DIR [--quick] [--convergence-only] [--top HZ]
        [--particles N]

Reproduces the speed table of docs/streams.md ("Speed") and the per-impact figures of its
"Accuracy over a stream" (first-impact peak forces against the tolerance and the band, and
the chaos floor). The scene is ``examples/caving_stream.toml``: particles released at 200 per
second from 0.3-0.8 m above a 0.4 x 0.4 m area of a 30-degree SSSS plate, radii 10-40 mm, 30 %
gangue, damping 300 N s/m; the stream lasts n / 200 s and the simulation 1 s longer (6 s for
the reference scene's 1000 particles). Every case runs ``tailbeam.simulate`` in its own
process (timed inside it; peak memory = the process's maximum resident set, numba and the
basis included), after one warm-up run that fills the numba and basis caches.

Rows:

- cost against particle count at the same rate (100, 300, 1000, 3000 particles, rigid
  plate): wall time, contacts, and the fitted exponent of time against particles;
- the reference scene on the modal plate (band 10 kHz, basis cached, two 51.2 kHz sensors:
  coupled both ways) as by default (residual flexibility with the contact tails: a few
  oscillators per contact for the modes to 40 kHz), with the static residual spring alone
  (``plate.tail = "quasi-static"``), without residual flexibility, and at the top band
  (``--top``, default 40 kHz, static spring), beside the rigid plate's cost;
- accuracy, each against a converged run of the same stream measured in the same run:
  first-impact peak forces at rtol 1e-10 (the default) against rtol 1e-12 (rigid plate); on
  the two-way modal plate 10 and 20 kHz as by default and 10 kHz with the static spring alone
  against the top band, and without residual flexibility 10 against 20 kHz: first-impact
  peak forces (median, worst) and sensor RMS; and the floor any such comparison has on a
  chaotic stream, the same 10 kHz run at rtol 1e-10 against 1e-11.

``--quick``: rigid 100-1000 particles, modal rows with 200 particles (``--particles`` sets
that count). ``--convergence-only`` runs only the modal rows. Writes DIR/table.md,
DIR/results.json and every case's scene and results (DIR/<case>.toml, DIR/<case>.json).
"""

import argparse
import json
import re
import sys
import time
from pathlib import Path

import numpy as np
from child import run_case_in_child

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "examples" / "caving_stream.toml"
RATE = 200.0


def scene_text(n: int, model: str, fmax: float = 10000.0, residual: bool = True,
               tail: str | None = None) -> str:  # fmt: skip
    """The reference scene with n particles (stream n / RATE s, simulation 1 s longer); on
    the modal plate with or without residual flexibility at the contacts, and with
    ``plate.tail`` set to ``tail`` (None: the scene's, the default "auto")."""
    stop = n / RATE
    text = SCENE.read_text()
    text = text.replace("duration = 6.0 ", f"duration = {stop + 1.0!r} ")
    text = text.replace("stop = 5.0 ", f"stop = {stop!r} ")
    text = text.replace('model = "modal"', f'model = "{model}"')
    text = text.replace("fmax = 10000.0", f"fmax = {fmax!r}")
    if tail is not None:
        text = re.sub(r"(?m)^(fmax = .*)$", f'\\1\ntail = "{tail}"', text, count=1)
    if not residual:
        text = text.replace('boundary = "SSSS"', 'boundary = "SSSS"\nresidual_flexibility = false')
    if model == "rigid":  # no modal keys, no sensors
        text = text[: text.index("[[sensors]]")]
        keep = [ln for ln in text.splitlines() if not ln.startswith(("boundary", "fmax"))]
        text = "\n".join(keep) + "\n"
    return text


IN_BAND_HZ = 10_000.0  # the default stream band: the RMS compared "in band" keeps 0-10 kHz


def run_case(path: str, rtol: float) -> dict:
    """Child process: simulate the scene file, report wall time, peak memory, results."""
    import resource

    import tailbeam
    from tailbeam.io.scene_file import load_scene

    scene = load_scene(path)
    t0 = time.perf_counter()
    result = tailbeam.simulate(scene, rtol=rtol, progress=False)
    wall = time.perf_counter() - t0
    first, touched = {}, set()
    for rec in sorted(result.impacts, key=lambda r: r.t_start):
        if rec.partner != "plate":
            touched.add(rec.ball)
        elif rec.ball not in first:
            # (peak force, start time, whether a ball-ball contact came first)
            first[rec.ball] = (rec.peak_force, rec.t_start, rec.ball in touched)
    outputs = result.sensor_outputs
    rms = {name: float(np.sqrt(np.mean(out.acceleration**2))) for name, out in outputs.items()}
    in_band = {
        name: rms_below(out.t, out.acceleration, IN_BAND_HZ) for name, out in outputs.items()
    }
    return {
        "wall_s": wall,
        "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0,
        "particles": len(result.particles),
        "contacts": len(result.impacts),
        "kernel_steps": result.stats.get("kernel_steps"),
        "first_peaks": first,
        "sensor_rms": rms,
        "sensor_rms_in_band": in_band,
    }


def rms_below(t, a, f_hz: float) -> float:
    """RMS (m/s^2) of the signal a(t) (uniform t, s) keeping only its content at or below
    f_hz (Hz): the in-band RMS, without what the sensor's filter passes above its bandwidth."""
    a = np.asarray(a, dtype=float)
    spectrum = np.fft.rfft(a)
    spectrum[np.fft.rfftfreq(len(a), t[1] - t[0]) > f_hz] = 0.0
    return float(np.sqrt(np.mean(np.fft.irfft(spectrum, len(a)) ** 2)))


def _in_child(out_dir: Path, name: str, text: str, rtol: float = 1e-10) -> dict:
    path = out_dir / f"{name}.toml"
    path.write_text(text)
    result = run_case_in_child("bench_stream", str(path), rtol)
    (out_dir / f"{name}.json").write_text(json.dumps(result))  # (every case kept)
    return result


def _worst(a: dict, b: dict) -> float:
    common = sorted(set(a) & set(b))
    return max(abs(a[k] - b[k]) / abs(b[k]) for k in common)


def first_impacts(a: dict, b: dict, within: float = 1e-6) -> dict:
    """First plate impacts of two runs of one stream. A stream is chaotic: a tiny difference
    changes which balls meet in flight, and then everything after. So compare the particles
    whose first plate impact starts at the same time (``within`` s) in both runs and came
    before any ball-ball contact of theirs (the impact itself, not the history), and count
    the rest. With 1e-6 s the plate under the landing ball is nearly where it is in the other
    run (a start 1e-6 s apart is ~3 um of plate at 3 m/s); with 1e-3 s the plate's state
    there may differ (the runs' histories parted): that spread is the chaos, not the band."""
    same = [k for k in set(a) & set(b)
            if not a[k][2] and not b[k][2] and a[k][0] > 0 and b[k][0] > 0
            and abs(a[k][1] - b[k][1]) < within]  # fmt: skip
    errors = np.array([abs(a[k][0] - b[k][0]) / b[k][0] for k in same])
    if not same:  # no particle comparable (a short stream)
        return {"compared": 0, "particles": len(b), "worst": np.nan, "median": np.nan,
                "within_1pct": np.nan}  # fmt: skip
    return {
        "compared": len(same),
        "particles": len(b),
        "worst": float(errors.max()),
        "median": float(np.median(errors)),
        "within_1pct": float(np.mean(errors < 0.01)),
    }


def modal_rows(out_dir: Path, top: float, n: int = 1000) -> tuple[list, dict]:
    """The reference scene on the two-way modal plate: 10 kHz with and without residual
    flexibility (wall time, memory), and the band convergence (module docstring)."""
    runs = {}
    for label, fmax, residual, rtol, tail in (
        ("10k", 1e4, True, 1e-10, None), ("10k_qs", 1e4, True, 1e-10, "quasi-static"),
        ("10k_off", 1e4, False, 1e-10, None), ("10k_tight", 1e4, True, 1e-11, None),
        ("20k", 2e4, True, 1e-10, None), ("top", top, True, 1e-10, "quasi-static"),
        ("20k_off", 2e4, False, 1e-10, None),
    ):  # fmt: skip
        _in_child(out_dir, f"warm_modal_{label}", scene_text(20, "modal", fmax, residual, tail))
        text = scene_text(n, "modal", fmax, residual, tail)
        runs[label] = _in_child(out_dir, f"modal_{n}_{label}", text, rtol)
        print(f"modal {label}: {runs[label]['wall_s']:.2f} s", file=sys.stderr)
    rows = [
        ("modal 10 kHz, two-way, residual flexibility and contact tails (the default), "
         f"2 sensors, {n} particles ({n / RATE + 1:g} s)", runs["10k"]),
        ("modal 10 kHz, two-way, residual flexibility, no contact tails (plate.tail = "
         "quasi-static), same", runs["10k_qs"]),
        ("modal 10 kHz, two-way, no residual flexibility, same", runs["10k_off"]),
        (f"modal {top / 1e3:g} kHz, two-way, residual flexibility, same", runs["top"]),
    ]  # fmt: skip
    compared = {
        "default, 10 kHz, rtol 1e-10 vs 1e-11 (the chaos floor)": ("10k", "10k_tight"),
        "default (contact tails), 10 vs 20 kHz": ("10k", "20k"),
        f"default (contact tails), 10 vs {top / 1e3:g} kHz": ("10k", "top"),
        f"quasi-static tail, 10 vs {top / 1e3:g} kHz": ("10k_qs", "top"),
        f"default (contact tails), 20 vs {top / 1e3:g} kHz": ("20k", "top"),
        "no residual, 10 vs 20 kHz": ("10k_off", "20k_off"),
    }
    bands = {}
    for name, (a, b) in compared.items():
        peaks = first_impacts(runs[a]["first_peaks"], runs[b]["first_peaks"])
        loose = first_impacts(runs[a]["first_peaks"], runs[b]["first_peaks"], within=1e-3)
        bands[name] = dict(peaks, loose=loose,
                           rms=_worst(runs[a]["sensor_rms"], runs[b]["sensor_rms"]),
                           rms_a=runs[a]["sensor_rms"], rms_b=runs[b]["sensor_rms"])  # fmt: skip
    return rows, bands


def band_lines(bands: dict) -> list:
    lines = ["", "| two-way modal plate, bands | first-impact peaks compared (start within 1 us) "
             "| median | worst | within 1 % | compared (start within 1 ms) | median | worst "
             "| within 1 % | sensor RMS (worst of S1, S2) |",
             "|---|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for name, b in bands.items():
        lo = b["loose"]
        lines.append(
            f"| {name} | {b['compared']} of {b['particles']} | {b['median']:.2e} | "
            f"{b['worst']:.2e} | {b['within_1pct']:.0%} | {lo['compared']} | "
            f"{lo['median']:.2e} | {lo['worst']:.2e} | {lo['within_1pct']:.0%} | {b['rms']:.2e} |"
        )
    return lines


def table_lines(rows) -> list:
    lines = [
        "| case | wall (s) | peak memory (MB) | particles | contacts | kernel steps |",
        "|---|---|---|---|---|---|",
    ]
    for label, r in rows:
        lines.append(
            f"| {label} | {r['wall_s']:.2f} | {r['peak_rss_mb']:.0f} | {r['particles']} | "
            f"{r['contacts']} | {r['kernel_steps']} |"
        )
    return lines


def rigid_rows(out_dir: Path, quick: bool) -> tuple[list, dict]:
    """Cost against particle count and the rtol convergence on the rigid plate."""
    counts = [100, 300, 1000] if quick else [100, 300, 1000, 3000]
    _in_child(out_dir, "warm_rigid", scene_text(100, "rigid"))
    rows, results = [], {}
    for n in counts:
        results[n] = r = _in_child(out_dir, f"rigid_{n}", scene_text(n, "rigid"))
        rows.append((f"rigid, {n} particles ({n / RATE + 1:g} s)", r))
        print(f"rigid {n}: {r['wall_s']:.2f} s", file=sys.stderr)
    n = np.array(counts, dtype=float)
    wall = np.array([results[k]["wall_s"] for k in counts])
    exponent = float(np.polyfit(np.log(n), np.log(wall), 1)[0])
    tight = _in_child(out_dir, "rigid_1000_tight", scene_text(1000, "rigid"), rtol=1e-12)
    peaks = first_impacts(results[1000]["first_peaks"], tight["first_peaks"])
    text = [
        "",
        f"Fitted exponent of wall time against particles (rigid, {counts}): {exponent:.3f}.",
        f"First-impact peak forces, rtol 1e-10 vs 1e-12: {peaks['compared']} of "
        f"{peaks['particles']} particles comparable (same first impact, no ball-ball contact "
        f"before it): worst {peaks['worst']:.2e}, median {peaks['median']:.2e}.",
    ]
    return rows, {"exponent": exponent, "first_impacts": peaks, "text": text}


def main(out_dir, quick=False, convergence_only=False, top=40000.0, particles=None) -> Path:
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    rows, rigid = ([], {"text": []}) if convergence_only else rigid_rows(out_dir, quick)
    more, bands = modal_rows(out_dir, top, particles or (200 if quick else 1000))
    lines = table_lines(rows + more) + rigid["text"] + band_lines(bands)
    table = out_dir / "table.md"
    table.write_text("\n".join(lines) + "\n")
    summary = {k: v for k, v in rigid.items() if k != "text"}
    summary["rows"] = {
        k: {q: v for q, v in r.items() if q != "first_peaks"} for k, r in rows + more
    }
    summary["bands"] = bands
    (out_dir / "results.json").write_text(json.dumps(summary, indent=1, default=float))
    print(table.read_text())
    return table


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--quick", action="store_true", help="rigid 100-1000, modal 200 particles")
    parser.add_argument("--convergence-only", action="store_true", help="the modal rows only")
    parser.add_argument("--top", type=float, default=40000.0, help="top band, Hz (40000)")
    parser.add_argument("--particles", type=int, help="particles of the modal rows (1000)")
    args = parser.parse_args()
    main(args.out, args.quick, args.convergence_only, args.top, args.particles)
