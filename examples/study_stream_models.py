"""Study 2 by model and sensors: the gangue fraction of a caving stream from 1 s windows, by a
random forest on features and by MiniRocket on the raw windows, from one or three sensors.

    python examples/study_stream_models.py [--full] [--out DIR] [--workers N]

The stream of study 2 (examples/study_stream_gangue_fraction.py: coal and sandstone lumps of
radius 10-40 mm, 100 per second, on the 30 degree SSSS plate; gangue fraction uniform 0-0.5 per
case; 3 s) recorded by three accelerometers at 12.8 kHz (5 kHz bandwidth): S1 (0.1, 0) m as in
study 2, S2 (-0.15, 0.15) m and S3 (0.2, -0.2) m. Fixed 1 s windows without the first (the
stream's arrival); each model regresses the case's gangue fraction, 5-fold cross-validation
grouped by case, without added noise and at SNR_DB (one noise RMS for every sensor, re the
median clean window RMS over the three sensors). Separability of simulated signals under this
model, not field accuracies.

Quick mode (the tests run it): 6 cases of 0.3 s, 0.1 s windows, 3 folds, the forest only.
"""

import argparse
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))

from study_stream_gangue_fraction import FULL, QUICK, sweep_table  # noqa: E402

from tailbeam.study import separability  # noqa: E402
from tailbeam.study.design import parse_sweep  # noqa: E402
from tailbeam.study.learn import Samples, learn  # noqa: E402
from tailbeam.study.separability import write_rows  # noqa: E402
from tailbeam.study.sweep import run_sweep  # noqa: E402
from tailbeam.study.windows import feature_table, window_table  # noqa: E402

SENSORS = (("S1", (0.1, 0.0)), ("S2", (-0.15, 0.15)), ("S3", (0.2, -0.2)))
SENSOR_SETS = {"S1": ["S1"], "S1+S2+S3": ["S1", "S2", "S3"]}
CASES = 30  # full mode (study 2 itself has 100 per condition)
SNR_DB = (math.inf, 0.0)


def sweep(mode: dict) -> dict:
    """Study 2's rate-fixed sweep with three sensors."""
    table = sweep_table(mode)
    table["scene"]["sensors"] = [
        {"name": n, "position": list(p), "sample_rate": 12800.0, "bandwidth": 5000.0}
        for n, p in SENSORS
    ]
    return table


def samples(folder, mode: dict, model: str, noise_rms: float) -> Samples:
    """The fixed windows after the first, as ``model`` reads them."""
    settings = {"window": "fixed", "length": mode["window"], "noise_rms": noise_rms}
    if model == "forest":
        table = feature_table(folder, **settings)
        return Samples(table[table["window"] >= 1].reset_index(drop=True))
    meta, windows, sensors, fs = window_table(folder, **settings)
    keep = (meta["window"] >= 1).to_numpy()
    return Samples(meta[keep].reset_index(drop=True), windows[keep], sensors, fs)


def main(quick: bool = True, out="out/study_stream_models", workers=None, client=None) -> list:
    """Run the sweep and every model; returns the rows (also in DIR/stream_models.csv)."""
    mode = QUICK if quick else {**FULL, "samples": CASES}
    models = ("forest",) if quick else ("forest", "minirocket")
    folder = Path(out) / "dataset"
    run_sweep(parse_sweep(sweep(mode)), folder, workers=workers or (1 if quick else None),
              client=client)  # fmt: skip
    clean = feature_table(folder, window="fixed", length=mode["window"])
    clean = clean[clean["window"] >= 1]
    ref = float(np.median(clean[[f"{n}.rms" for n, _ in SENSORS]].to_numpy()))
    rows = []
    for snr in SNR_DB:
        noise = 0.0 if math.isinf(snr) else ref / 10 ** (snr / 20)
        for model in models:
            data = samples(folder, mode, model, noise)
            for label, sensors in SENSOR_SETS.items():
                s = learn(data, "gangue_fraction", folds=mode["folds"], sensors=sensors,
                          model=model)  # fmt: skip
                rows.append(
                    {
                        "model": model,
                        "sensors": label,
                        "snr_db": snr,
                        "noise_rms": noise,
                        "mae": s["mae"],
                        "mae_se": s["mae_se"],
                        "r2": s["r2"],
                        "mean_predictor_mae": s["dummy"]["mae"],
                        "n_rows": s["n_rows"],
                        "n_cases": s["n_cases"],
                    }
                )
    write_rows(Path(out) / "stream_models.csv", rows)
    return rows


def read_rows(path) -> list:
    """Rows of a previous run's stream_models.csv."""
    return separability.read_rows(path, text=("model", "sensors"))


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--full", action="store_true", help=f"{CASES} cases of 3 s, both models")
    parser.add_argument("--out", default="out/study_stream_models")
    parser.add_argument("--workers", type=int, default=None)
    args = parser.parse_args()
    for r in main(quick=not args.full, out=args.out, workers=args.workers):
        print(
            f"{r['model']:>10} {r['sensors']:>8} SNR {r['snr_db']:>4} dB: MAE {r['mae']:.4f} "
            f"+- {r['mae_se']:.4f}, R^2 {r['r2']:.2f} (mean predictor "
            f"{r['mean_predictor_mae']:.4f}; {r['n_cases']} cases, {r['n_rows']} windows)"
        )
