"""Sensor RMS and first-impact peak forces of the reference caving stream at 10 kHz against
40 kHz, over an ensemble of stream seeds.

    python benchmarks/bench_stream_ensemble.py --out DIR [--seeds N] [--particles N]
        [--top HZ] [--band HZ] [--tail] [--reuse]

Reproduces the ensemble table of docs/streams.md ("Accuracy over a stream"; there with
``--seeds 32 --tail``, about 35 min on an idle 2-core machine). A stream is chaotic: two
runs of one stream at different bands (or tolerances) part after a while, and their sensor
RMS then differ by as much as two runs at one band with rtol 1e-10 and 1e-11. One run cannot
tell whether the band changes the RMS by 1 %; an ensemble can. The reference scene
(examples/caving_stream.toml, ``--particles`` particles (1000), two-way modal plate with
residual flexibility, two 51.2 kHz sensors) with stream seeds 1..N, each at the band under
test (``--band``, default 10 kHz; with ``plate.tail = "quasi-static"``, or with ``--tail``
the contact tails, ``"ritz"``) and at the top band (``--top``, 40 kHz: the baseline, measured
in the same run). Reported per quantity: the paired relative difference (band under test
against top band, paired by seed), its ensemble mean, standard error and 95 % interval
(mean +- t(0.975, seeds - 1) x standard error), and beside them the seed-to-seed spread of
the quantity itself (what a recognition model sees from stream to stream). Quantities: each
sensor's RMS, of the sensor output and in band (its content at or below 10 kHz, by FFT), and
each run's mean first-impact peak force (all first plate impacts, and those before any
ball-ball contact of the particle), with the pooled distributions of both bands (quantile
ratios, two-sample Kolmogorov-Smirnov test). Every run is a child process
(``bench_stream.run_case``), two at a time; ``--reuse`` reads a run's saved DIR/<run>.json
instead when its scene file there is the same text (the runs are deterministic), to redo the
comparisons. A short check: ``--seeds 2 --particles 100 --top 20000``.

Writes DIR/ensemble.csv and DIR/table.md.
"""

import argparse
import csv
import json
import re
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
from bench_stream import _in_child, scene_text
from scipy import stats


def seeded(text: str, seed: int) -> str:
    """The scene text with the stream's seed set to ``seed``."""
    return re.sub(r"(?m)^seed = \d+", f"seed = {seed}", text, count=1)


def runs(out_dir: Path, seeds, n: int, top: float, reuse=False, low=1e4, tail=False) -> list:
    jobs = [(s, band) for s in seeds for band in (low, top)]

    def one(job):
        seed, band = job
        text = seeded(scene_text(n, "modal", fmax=band), seed)
        name = f"seed{seed}_{band / 1e3:g}k"
        if band == low:  # the tail of the band under test, explicit (the default is "auto")
            text = with_tail(text, "ritz" if tail else "quasi-static")
            name += "_tail" if tail else ""
        saved = _saved(out_dir, name, text) if reuse else None
        res = saved if saved is not None else _in_child(out_dir, name, text)
        print(f"seed {seed}, {band / 1e3:g} kHz: {res['wall_s']:.1f} s, RMS {res['sensor_rms']}",
              flush=True)  # fmt: skip
        return seed, band, res

    with ThreadPoolExecutor(2) as pool:  # drives two child processes at a time
        return list(pool.map(one, jobs))


def with_tail(text: str, tail: str) -> str:
    """The scene text with ``plate.tail = tail`` (after its fmax line)."""
    return re.sub(r"(?m)^(fmax = .*)$", f'\\1\ntail = "{tail}"', text, count=1)


def _saved(out_dir: Path, name: str, text: str):
    """The saved result of run ``name`` if its scene file in ``out_dir`` is ``text``, else None."""
    scene, result = out_dir / f"{name}.toml", out_dir / f"{name}.json"
    if scene.is_file() and result.is_file() and scene.read_text() == text:
        return json.loads(result.read_text())
    return None


def _interval(rel) -> tuple:
    """(mean, standard error, 95 % half-width) of the paired differences ``rel``."""
    se = rel.std(ddof=1) / np.sqrt(len(rel))
    return float(rel.mean()), float(se), float(stats.t.ppf(0.975, len(rel) - 1) * se)


def summarise(results, top: float, key: str = "sensor_rms", band: float = 1e4) -> list:
    """Rows per sensor of the paired ``band`` vs ``top`` comparison of ``key``
    (``sensor_rms``: the sensor's output; ``sensor_rms_in_band``: its content at or below
    10 kHz)."""
    by = {(seed, b): res[key] for seed, b, res in results}
    seeds = sorted({seed for seed, _b, _r in results})
    rows = []
    for sensor in sorted(by[(seeds[0], band)]):
        low = np.array([by[(s, band)][sensor] for s in seeds])
        high = np.array([by[(s, top)][sensor] for s in seeds])
        what = "RMS in band (<= 10 kHz)" if key.endswith("in_band") else "RMS sensor output"
        rows.append(_row(what, sensor, low, high))
    return rows


def _row(what: str, subset: str, low, high) -> dict:
    """The paired comparison of one quantity, per seed at the band under test (low) and the
    top band."""
    mean, se, half = _interval((low - high) / high)
    return {
        "quantity": what,
        "subset": subset,
        "seeds": len(low),
        "mean_paired_rel_diff": mean,
        "standard_error": se,
        "interval_95_low": mean - half,
        "interval_95_high": mean + half,
        "worst_paired_rel_diff": float(np.abs((low - high) / high).max()),
        "ensemble_mean_rel_diff": float(low.mean() / high.mean() - 1.0),
        "seed_to_seed_spread": float(high.std(ddof=1) / high.mean()),
    }


def first_peaks(res: dict, clean: bool) -> np.ndarray:
    """Peak forces (N) of a run's first plate impacts (those that ended with a force), only
    those before any ball-ball contact of the particle if ``clean``."""
    return np.array(
        [p for p, _t, met in res["first_peaks"].values() if p > 0 and not (clean and met)]
    )


def first_impact_rows(results, top: float, band: float = 1e4) -> tuple[list, list]:
    """Rows of the paired comparison of each run's mean first-impact peak force, and lines on
    the pooled distributions (quantile ratios, Kolmogorov-Smirnov p-value)."""
    by = {(seed, b): res for seed, b, res in results}
    seeds = sorted({seed for seed, _b, _r in results})
    rows, lines = [], []
    for subset, clean in (("all first impacts", False), ("before any ball-ball contact", True)):
        low = [first_peaks(by[(s, band)], clean) for s in seeds]
        high = [first_peaks(by[(s, top)], clean) for s in seeds]
        means = [np.array([v.mean() for v in runs_]) for runs_ in (low, high)]
        rows.append(_row("first-impact peak force, mean of a run", subset, *means))
        a, b = np.concatenate(low), np.concatenate(high)
        ratios = ", ".join(
            f"{q}%: {np.percentile(a, q) / np.percentile(b, q) - 1:+.1e}" for q in (10, 50, 90, 99)
        )
        lines.append(
            f"- first-impact peaks pooled over the seeds, {subset}: {len(a)} at "
            f"{band / 1e3:g} kHz, "
            f"{len(b)} at {top / 1e3:g} kHz; quantile ratios - 1 ({ratios}); "
            f"Kolmogorov-Smirnov p = {stats.ks_2samp(a, b).pvalue:.2f}"
        )
    return rows, lines


def write(rows, out_dir: Path, top: float, notes=(), band: float = 1e4) -> None:
    with (out_dir / "ensemble.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    lines = [
        f"| quantity | sensor / subset | seeds | {band / 1e3:g} vs {top / 1e3:g} kHz: mean "
        "paired rel. "
        "difference +- standard error | 95 % interval | worst single pair | ratio of the "
        "ensemble means - 1 | seed-to-seed spread |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['quantity']} | {r['subset']} | {r['seeds']} | "
            f"{r['mean_paired_rel_diff']:+.2e} +- {r['standard_error']:.1e} | "
            f"{r['interval_95_low']:+.1e} ... {r['interval_95_high']:+.1e} | "
            f"{r['worst_paired_rel_diff']:.2e} | {r['ensemble_mean_rel_diff']:+.2e} | "
            f"{r['seed_to_seed_spread']:.2e} |"
        )
    lines += ["", *notes]
    (out_dir / "table.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="output folder")
    ap.add_argument("--seeds", type=int, default=6)
    ap.add_argument("--particles", type=int, default=1000)
    ap.add_argument("--top", type=float, default=40000.0)
    ap.add_argument("--band", type=float, default=10000.0, help="the band under test (Hz)")
    ap.add_argument("--tail", action="store_true", help='the band under test with tail "ritz"')
    ap.add_argument("--reuse", action="store_true", help="read runs already saved in --out")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    band, top = args.band, args.top
    results = runs(out, range(1, args.seeds + 1), args.particles, top, args.reuse, band, args.tail)
    rows = summarise(results, top, band=band)
    rows += summarise(results, top, "sensor_rms_in_band", band)
    impact_rows, notes = first_impact_rows(results, top, band)
    write(rows + impact_rows, out, top, notes, band)
