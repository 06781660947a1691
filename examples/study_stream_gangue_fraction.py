"""Study 2: the gangue fraction of a caving stream, estimated from 1 s windows of one sensor.

    python examples/study_stream_gangue_fraction.py [--full] [--out DIR] [--workers N]

A caving stream of coal and sandstone lumps (radius uniform 10-40 mm, 100 per second, Poisson
arrivals, released 0.3-0.8 m above a 0.4 x 0.4 m area on the upper part of the plate) falls
on the tail beam, inclined 30 degrees (a smaller examples/caving_stream.toml: SSSS plate,
modes to 5 kHz, contact damping 300 N s/m). The stream solver finds every ball-ball and
ball-plate contact, the plate's modes taking part (two-way, docs/streams.md). One
accelerometer at (0.1, 0) m samples at 12.8 kHz (5 kHz bandwidth).

Each case has its own gangue fraction (the probability that a lump is gangue, uniform 0-0.5)
and its own particles (the sweep seeds every stream from the case seed). The 3 s record is
cut into fixed 1 s windows (``tailbeam features --window fixed --length 1``); the first,
which holds the stream's arrival (first impacts after ~0.3 s), is left out, so each case
gives two windows of a steady stream. A random forest regresses the case's gangue fraction
from each window's features (``tailbeam learn --target gangue_fraction``: 5-fold CV grouped
by case), against white noise added at SNRs relative to the median RMS of the clean windows;
beside it the mean predictor (the trivial baseline) on the same folds and, as a reference
that no vibration enters, the realised fraction of gangue among all the case's particles
(what an observer who counts every lump would say). Two conditions: the rate fixed at 100
particles/s (known), and the rate uniform 50-150 particles/s per case (unknown, as in a mine:
then the vibration's power no longer tells the gangue fraction by itself). The numbers are
the separability of simulated signals under this model, not a field accuracy.

Quick mode (the tests run it): 6 cases of 0.3 s with 0.1-0.15 m drops, 0.1 s windows,
3 folds, two SNRs, the first condition. Full mode: two conditions of 100 cases of 3 s, five
SNRs (~5 min on 2 shared cores).
"""

import argparse
import math
from pathlib import Path

import numpy as np

from tailbeam.study import separability
from tailbeam.study.design import parse_sweep
from tailbeam.study.learn import learn
from tailbeam.study.separability import write_rows
from tailbeam.study.sweep import run_sweep
from tailbeam.study.windows import feature_table

SENSOR = "S1"
AXIS = "streams.cave.gangue_fraction"
SNR_DB = (math.inf, 20.0, 10.0, 0.0, -10.0)
QUICK_SNR_DB = (math.inf, 0.0)
FULL = {"samples": 100, "duration": 3.0, "window": 1.0, "height": [0.3, 0.8], "folds": 5}
QUICK = {"samples": 6, "duration": 0.3, "window": 0.1, "height": [0.1, 0.15], "folds": 3}


def base_scene(duration: float, height: list) -> dict:
    """The stream scene every case starts from (the sweep sets gangue_fraction and seed)."""
    return {
        "duration": duration,
        "contact": {"damping": 300.0, "penetration": 1e-4},
        "plate": {"model": "modal", "boundary": "SSSS", "inclination": 30.0, "fmax": 5000.0},
        "streams": [
            {
                "name": "cave",
                "rate": 100.0,
                "start": 0.0,
                "stop": duration,
                "gangue_fraction": 0.25,
                "radius": [0.01, 0.04],
                "area": [[-0.3, 0.1], [-0.2, 0.2]],
                "height": height,
            }
        ],
        "sensors": [
            {"name": SENSOR, "position": [0.1, 0.0], "sample_rate": 12800.0, "bandwidth": 5000.0}
        ],
    }


def sweep_table(mode: dict, vary_rate: bool = False, seed: int = 2) -> dict:
    """The sweep: gangue fraction uniform 0-0.5, one case (and particle draw) per sample;
    ``vary_rate``: the stream's rate too, uniform 50-150 particles/s."""

    def uniform(low, high):
        return {"distribution": "uniform", "low": low, "high": high, "samples": mode["samples"]}

    axes = {AXIS: uniform(0.0, 0.5)}
    if vary_rate:
        axes["streams.cave.rate"] = uniform(50.0, 150.0)
    scene = base_scene(mode["duration"], mode["height"])
    return {"scene": scene, "seed": seed, "axes": axes}


CONDITIONS = {"rate 100/s (known)": False, "rate 50-150/s (unknown)": True}


def windows(folder, mode: dict, noise_rms: float = 0.0):
    """Feature table of the fixed windows after the first (the stream's arrival)."""
    table = feature_table(folder, window="fixed", length=mode["window"], noise_rms=noise_rms)
    return table[table["window"] >= 1].reset_index(drop=True)


def count_reference(table) -> float:
    """MAE of the realised gangue fraction of each case's particles (by number) as an
    estimate of its declared gangue fraction, over the windows of ``table``."""
    realised = table["n_gangue"] / (table["n_coal"] + table["n_gangue"])
    return float(np.mean(np.abs(realised - table["gangue_fraction"])))


def main(quick: bool = True, out="out/study_stream_gangue_fraction", workers=None, client=None):
    """Run the sweeps (quick: the first condition only) and the regressions against SNR;
    returns their rows (also written to DIR/gangue_fraction_vs_snr.csv). ``client``: a
    dask.distributed Client to run the sweeps on (default: a local cluster)."""
    mode = QUICK if quick else FULL
    out = Path(out)
    rows = []
    for k, (condition, vary_rate) in enumerate(CONDITIONS.items()):
        if quick and k:
            break
        folder = out / ("rate_varies" if vary_rate else "rate_fixed") / "dataset"
        spec = parse_sweep(sweep_table(mode, vary_rate))
        run_sweep(spec, folder, workers=workers or (1 if quick else None), client=client)
        scan = snr_scan(folder, mode, QUICK_SNR_DB if quick else SNR_DB)
        rows += [{"condition": condition, **r} for r in scan]
    write_rows(out / "gangue_fraction_vs_snr.csv", rows)
    return rows


def snr_scan(folder, mode: dict, snr_db) -> list:
    """The regression of the dataset in ``folder`` at each SNR (dB; inf = no added noise)."""
    clean = windows(folder, mode)
    ref = float(np.median(clean[f"{SENSOR}.rms"]))
    rows = []
    for snr in snr_db:
        noise = 0.0 if math.isinf(snr) else ref / 10 ** (snr / 20)
        table = clean if noise == 0.0 else windows(folder, mode, noise)
        s = learn(table, "gangue_fraction", folds=mode["folds"], sensors=[SENSOR])
        rows.append(
            {
                "snr_db": snr,
                "noise_rms": noise,
                "reference_rms": ref,
                "window_s": mode["window"],
                "mae": s["mae"],
                "mae_se": s["mae_se"],
                "r2": s["r2"],
                "mean_predictor_mae": s["dummy"]["mae"],
                "mean_predictor_r2": s["dummy"]["r2"],
                "count_reference_mae": count_reference(table),
                "n_rows": s["n_rows"],
                "n_cases": s["n_cases"],
                "fraction_min": float(table["gangue_fraction"].min()),
                "fraction_max": float(table["gangue_fraction"].max()),
                "top_features": " ".join(list(s["importances"])[:3]),
            }
        )
    return rows


def visualize(rows: list, path) -> Path:
    """MAE and R^2 against SNR per condition, beside the mean predictor and the
    particle-count reference."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(9.6, 5.0), constrained_layout=True)
    colours = ("tab:blue", "tab:orange")
    for condition, colour in zip(CONDITIONS, colours, strict=True):
        mine = [r for r in rows if r["condition"] == condition]
        if mine:
            _condition_lines(ax, bx, condition, mine, colour)
    ax.set_ylabel("mean absolute error of the gangue fraction (0-1)")
    ax.set_ylim(0.0, None)
    bx.set_ylabel("R$^2$, grouped cross-validation")
    bx.axhline(0.0, color="grey", lw=0.5)
    for axis in (ax, bx):
        axis.set_xlabel("SNR re the median clean window RMS (dB)")
        axis.grid(alpha=0.3)
    first = rows[0]
    pairs = sorted(zip(*ax.get_legend_handles_labels(), strict=True), key=_legend_order)
    fig.legend(*zip(*pairs, strict=True), fontsize=7, loc="outside lower center", ncol=2)
    fig.suptitle(
        f"gangue fraction (0-50 %) of a caving stream from {first['window_s']:g} s windows of "
        "one sensor (simulated, 30° SSSS plate; error bars: standard error over cases)",
        fontsize=9,
    )
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return Path(path)


def _legend_order(pair) -> tuple:
    """Legend rows: the forests with their sizes, no added noise, mean predictors, counts."""
    label = pair[1]
    kinds = ("windows)", "no added noise", "mean predictor", "counting")
    return next(i for i, k in enumerate(kinds) if k in label), label


def _condition_lines(ax, bx, condition: str, mine: list, colour: str) -> None:
    finite = [r for r in mine if math.isfinite(r["snr_db"])]
    clean = [r for r in mine if not math.isfinite(r["snr_db"])]
    snr = [r["snr_db"] for r in finite]
    n = f"{int(mine[0]['n_cases'])} cases, {int(mine[0]['n_rows'])} windows"
    ax.errorbar(snr, [r["mae"] for r in finite], yerr=[r["mae_se"] for r in finite], fmt="o-",
                color=colour, capsize=3, label=f"forest, {condition} ({n})")  # fmt: skip
    bx.plot(snr, [r["r2"] for r in finite], "o-", color=colour)
    if clean:
        for axis, key in ((ax, "mae"), (bx, "r2")):
            axis.axhline(clean[0][key], color=colour, lw=1, ls=":",
                         label=f"forest, {condition}, no added noise")  # fmt: skip
    ax.plot(snr, [r["mean_predictor_mae"] for r in finite], "--", color=colour, lw=1,
            label=f"mean predictor, {condition}")  # fmt: skip
    bx.plot(snr, [r["mean_predictor_r2"] for r in finite], "--", color=colour, lw=1)
    ax.plot(snr, [r["count_reference_mae"] for r in finite], "-.", color=colour, lw=1,
            label=f"counting every lump (no vibration), {condition}")  # fmt: skip


def read_rows(path) -> list:
    """Rows of a previous run's gangue_fraction_vs_snr.csv (to redraw the figure)."""
    return separability.read_rows(path, text=("condition", "top_features"))


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--full", action="store_true", help="two conditions of 100 cases of 3 s, five SNRs"
    )
    parser.add_argument("--out", default="out/study_stream_gangue_fraction")
    parser.add_argument("--workers", type=int, default=None)
    args = parser.parse_args()
    result = main(quick=not args.full, out=args.out, workers=args.workers)
    for r in result:
        print(
            f"{r['condition']}: SNR {r['snr_db']:>5} dB: MAE {r['mae']:.3f} +- {r['mae_se']:.3f}, "
            f"R^2 {r['r2']:.2f} (mean predictor MAE {r['mean_predictor_mae']:.3f}; "
            f"counting lumps {r['count_reference_mae']:.3f}; "
            f"{r['n_cases']} cases, {r['n_rows']} windows; noise {r['noise_rms']:.3g} m/s^2)"
        )
    print(visualize(result, Path(args.out) / "gangue_fraction_vs_snr.png"))
