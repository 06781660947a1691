"""Study 2 proxy: gangue fraction from 1 s windows of a multi-ball [[balls]] scene.

    python examples/study_gangue_fraction_proxy.py [--full] [--out DIR] [--workers N]

NOT the caving-stream study of issue 8: streams (``[[streams]]``, ball-ball contact, a flowing
layer) are issue 7 and do not exist yet. This is what multi-ball scenes allow today: twelve
balls dropped in fixed lanes (4 x 3 over the plate, 0.13-0.15 m apart, so their paths never
meet: ball-ball contact is not modelled), each coal or sandstone (gangue with probability
1/4, so most cases lie at 0-50 % gangue by mass), radius uniform 15-30 mm, released at rest
from a centre height uniform 0.1-1.1 m (first impacts over 0.1-0.45 s at 1.0-4.6 m/s, then
rebounds). One sensor at (0.1, 0.15) m, 12.8 kHz; SSSS plate, modes to 5 kHz.

Target: the case's gangue mass fraction from its 1 s record (one fixed window per case),
random-forest regression, 5-fold CV grouped by case, against white noise at SNRs relative to
the median window RMS; the mean predictor is the floor. Separability of simulated signals.
"""

import argparse
import math
from pathlib import Path

import numpy as np

from tailbeam.study.design import parse_sweep
from tailbeam.study.learn import learn
from tailbeam.study.separability import write_rows
from tailbeam.study.sweep import run_sweep
from tailbeam.study.windows import feature_table

LANES = [(x, y) for x in (-0.2, -0.067, 0.067, 0.2) for y in (-0.15, 0.0, 0.15)]
SNR_DB = (math.inf, 20.0, 10.0, 0.0)
WINDOW_S = 1.0


def sweep_table(samples: int, seed: int = 5, lanes=LANES, duration=WINDOW_S, top=1.1) -> dict:
    """Balls in ``lanes``, material / radius / height (0.1 m to ``top``) drawn per ball and
    case; ``duration`` s."""
    balls = [
        {"name": f"b{i}", "material": "coal", "radius": 0.02, "position": [x, y, 0.5]}
        for i, (x, y) in enumerate(lanes)
    ]
    axes = {}
    for b in balls:
        n = b["name"]
        axes[f"balls.{n}.material"] = {
            "distribution": "choice",
            "values": ["coal", "coal", "coal", "sandstone"],
            "samples": samples,
        }
        axes[f"balls.{n}.radius"] = {
            "distribution": "uniform",
            "low": 0.015,
            "high": 0.03,
            "samples": samples,
        }
        axes[f"balls.{n}.position[2]"] = {
            "distribution": "uniform",
            "low": 0.1,
            "high": top,
            "samples": samples,
        }
    scene = {
        "duration": duration,
        "plate": {"model": "modal", "boundary": "SSSS", "fmax": 5000.0},
        "balls": balls,
        "sensors": [{"name": "S1", "position": [0.1, 0.15], "sample_rate": 12800.0}],
    }
    return {"scene": scene, "seed": seed, "axes": axes}


def main(
    quick: bool = True, out="out/study_gangue_fraction_proxy", workers=None, client=None
) -> list:
    """Run the sweep (6 or 120 cases) and the regression against SNR; returns its rows.
    ``client``: a dask.distributed Client to run the sweep on (default: a local cluster)."""
    out = Path(out)
    # quick: 4 balls, 0.3 s records (first impacts by 0.25 s), 6 cases
    window = 0.3 if quick else WINDOW_S
    design = (
        sweep_table(6, lanes=LANES[::3], duration=window, top=0.4) if quick else sweep_table(120)
    )
    spec = parse_sweep(design)
    run_sweep(spec, out / "dataset", workers=workers or (1 if quick else None), client=client)
    clean = feature_table(out / "dataset", window="fixed", length=window)
    ref = float(np.median(clean["S1.rms"]))
    rows = []
    for snr in SNR_DB[:2] if quick else SNR_DB:
        noise = 0.0 if math.isinf(snr) else ref / 10 ** (snr / 20)
        table = feature_table(out / "dataset", window="fixed", length=window, noise_rms=noise)
        s = learn(table, "gangue_fraction", folds=3 if quick else 5)
        rows.append(
            {
                "snr_db": snr,
                "noise_rms": noise,
                "mae": s["mae"],
                "r2": s["r2"],
                "mean_predictor_mae": s["dummy"]["mae"],
                "n_cases": s["n_cases"],
                "fraction_min": float(table["gangue_fraction"].min()),
                "fraction_max": float(table["gangue_fraction"].max()),
            }
        )
    write_rows(out / "gangue_fraction_vs_snr.csv", rows)
    return rows


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--full", action="store_true", help="120 cases, four SNRs")
    parser.add_argument("--out", default="out/study_gangue_fraction_proxy")
    parser.add_argument("--workers", type=int, default=None)
    args = parser.parse_args()
    for r in main(quick=not args.full, out=args.out, workers=args.workers):
        print(
            f"SNR {r['snr_db']:>5} dB: MAE {r['mae']:.3f}, R^2 {r['r2']:.2f} "
            f"(mean predictor MAE {r['mean_predictor_mae']:.3f}; {r['n_cases']} cases, "
            f"gangue fraction {r['fraction_min']:.2f}-{r['fraction_max']:.2f})"
        )
