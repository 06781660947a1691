"""Study 3: where to mount the accelerometer: coal/gangue separability over a grid of positions.

    python examples/study_sensor_placement.py [--full] [--out DIR] [--workers N]

The single impacts of study 1 (examples/study_single_impacts.py: coal or sandstone, radius
10-100 mm, 1-5 m/s, anywhere over |x|, |y| <= 0.25 m) recorded at once by a grid of
accelerometers (5 x 5 over |x|, |y| <= 0.24 m; 2 x 2 in quick mode). White noise of one RMS for
every sensor (a noise floor) is added at 10 dB below the median first-impact window RMS over
all sensors; then one grouped cross-validated forest per sensor, on that sensor's features only.
Separability of simulated signals, one model of the plate (SSSS, 1 % damping, modes to 5 kHz).
"""

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))

from study_single_impacts import WINDOW_S, base_scene, sweep_table  # noqa: E402

from tailbeam.study import separability  # noqa: E402
from tailbeam.study.design import parse_sweep  # noqa: E402
from tailbeam.study.learn import learn  # noqa: E402
from tailbeam.study.separability import write_rows  # noqa: E402
from tailbeam.study.sweep import run_sweep  # noqa: E402
from tailbeam.study.windows import feature_table  # noqa: E402

SNR_DB = 10.0


def sensor_grid(n: int, half: float = 0.24) -> list:
    """(name, (x, y)) of an n x n grid over |x|, |y| <= half (m)."""
    xs = np.linspace(-half, half, n)
    return [(f"x{i}y{j}", (float(x), float(y))) for j, y in enumerate(xs) for i, x in enumerate(xs)]


def main(
    quick: bool = True, out="out/study_sensor_placement", workers=None, client=None, wide=True
) -> list:
    """Run the sweep and score every sensor; returns rows (sensor, x, y, accuracy, ...).
    ``client``: a dask.distributed Client to run the sweep on (default: a local cluster).
    ``wide``: radius and speed vary as in study 1; False: 30 mm at 3 m/s (known), SNR 0 dB."""
    out = Path(out)
    grid = sensor_grid(2 if quick else 5)
    spec = parse_sweep(sweep_table(6 if quick else 150, base_scene(grid), seed=3, wide=wide))
    run_sweep(spec, out / "dataset", workers=workers or (1 if quick else None), client=client)
    clean = feature_table(out / "dataset", length=WINDOW_S, first_only=True)
    ref = float(np.median(clean[[f"{name}.rms" for name, _ in grid]].to_numpy()))
    snr = SNR_DB if wide else 0.0
    noisy = feature_table(
        out / "dataset", length=WINDOW_S, first_only=True, noise_rms=ref / 10 ** (snr / 20)
    )
    rows = []
    for name, (x, y) in grid:
        s = learn(noisy, "label", folds=3 if quick else 5, sensors=[name])
        rows.append(
            {
                "sensor": name,
                "x": x,
                "y": y,
                "accuracy": s["accuracy"],
                "f1_macro": s["f1_macro"],
                "dummy_accuracy": s["dummy"]["accuracy"],
                "n_cases": s["n_cases"],
                "noise_rms": ref / 10 ** (snr / 20),
                "snr_db": snr,
                "condition": "size and speed vary" if wide else "30 mm at 3 m/s",
            }
        )
    write_rows(out / "accuracy_by_position.csv", rows)
    return rows


def visualize(rows: list, path) -> Path:
    """Accuracy at each sensor position over the plate outline."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5.8, 4.6), constrained_layout=True)
    ax.add_patch(plt.Rectangle((-0.3, -0.3), 0.6, 0.6, fill=False, lw=1.5, color="0.3"))
    acc = np.array([r["accuracy"] for r in rows])
    sc = ax.scatter([r["x"] for r in rows], [r["y"] for r in rows], c=acc, s=500, marker="s",
                    cmap="viridis", vmin=min(0.5, acc.min()), vmax=1.0)  # fmt: skip
    for r in rows:
        colour = "white" if r["accuracy"] < 0.5 + 0.6 * (1.0 - 0.5) else "black"
        ax.text(r["x"], r["y"], f"{r['accuracy']:.2f}", ha="center", va="center", fontsize=7,
                color=colour)  # fmt: skip
    fig.colorbar(sc, ax=ax, label="accuracy, grouped CV")
    ax.set_xlim(-0.32, 0.32)
    ax.set_ylim(-0.32, 0.32)
    ax.set_aspect("equal")
    ax.set_xlabel("sensor x (m)")
    ax.set_ylabel("sensor y (m)")
    n = int(rows[0]["n_cases"])
    se = float(np.sqrt(acc.mean() * (1 - acc.mean()) / n))  # binomial standard error
    ax.set_title(
        f"coal vs sandstone per sensor position, {rows[0].get('condition', 'size and speed vary')}"
        f", SNR {rows[0].get('snr_db', SNR_DB):g} dB\n({n} cases, impacts over |x|, |y| <= "
        f"0.25 m, SSSS edges; standard error ~{se:.2f})",
        fontsize=9,
    )
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return Path(path)


def read_rows(path) -> list:
    """Rows of a previous run's accuracy_by_position.csv (to redraw the figure)."""
    return separability.read_rows(path, text=("sensor", "condition"))


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--full", action="store_true", help="5 x 5 sensors, 150 cases per class")
    parser.add_argument("--out", default="out/study_sensor_placement")
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--known", action="store_true", help="radius 30 mm, 3 m/s; SNR 0 dB")
    args = parser.parse_args()
    result = main(quick=not args.full, out=args.out, workers=args.workers, wide=not args.known)
    for r in result:
        print(f"{r['sensor']} ({r['x']:+.2f}, {r['y']:+.2f}) m: accuracy {r['accuracy']:.3f}")
    print(visualize(result, Path(args.out) / "accuracy_by_position.png"))
