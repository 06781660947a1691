"""Study 4: a model trained on one plate and tested on another, and what domain randomisation
recovers; with study 1 by model (forest, MiniRocket) and by sensors (one, three).

    python examples/study_transfer.py [--full] [--out DIR] [--workers N]

Training set: the single impacts of study 1 (examples/study_single_impacts.py: coal or
sandstone, radius 10-100 mm, 1-5 m/s, anywhere over |x|, |y| <= 0.25 m; 0.6 x 0.6 x 0.01 m
SSSS steel plate, modes to 5 kHz, 1 % damping) recorded by three accelerometers at 12.8 kHz:
S1 (0.1, 0.15) m as in study 1, S2 (-0.15, 0.05) m and S3 (0.05, -0.2) m. Test sets, a
stand-in for the gap between the simulation a model is trained on and the plate it meets: the
same design on a 12 mm plate (``h12``) and on the 10 mm plate clamped on all edges
(``cccc``). A domain-randomised training set draws per case the plate damping ratio
(0.3-5 %, log-uniform), the contact damping (30-3000 N s/m, log-uniform), each sensor's
mounted resonance (7-25 kHz) and white noise floor (0-300 m/s^2 RMS), and a wider size and
speed distribution (radius 7-140 mm log-uniform, 0.5-6 m/s); its plate stays the nominal one.
A second one (``plates``, 150 cases per class) draws the plate too: thickness 8, 11 or 14 mm,
edges SSSS or CSCS (clamped left and right), neither test plate among them.

Windows: 20 ms from 0.5 ms before each ball's first impact, no added noise (the randomised set
holds its own noise). Each model is scored by 5-fold cross-validation grouped by case on its
training set, then fitted on all of it and scored on the other sets, beside the majority class
of the training set. Separability of simulated signals under this model, not field accuracies.

Quick mode (the tests run it): 6 cases per class to train (4 for ``plates``), 4 per class to
test, 3 folds, the forest only, of 20 trees (200 in the full study).
"""

import argparse
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))

from study_single_impacts import WINDOW_S, base_scene, sweep_table  # noqa: E402

from tailbeam.study import separability  # noqa: E402
from tailbeam.study.design import parse_sweep  # noqa: E402
from tailbeam.study.learn import Samples, learn  # noqa: E402
from tailbeam.study.separability import write_rows  # noqa: E402
from tailbeam.study.sweep import run_sweep  # noqa: E402
from tailbeam.study.windows import feature_table, window_table  # noqa: E402

SENSORS = (("S1", (0.1, 0.15)), ("S2", (-0.15, 0.05)), ("S3", (0.05, -0.2)))
SENSOR_SETS = {"S1": ["S1"], "S1+S2+S3": ["S1", "S2", "S3"]}
FULL = {"train": 200, "test": 100, "plates": 150, "folds": 5, "models": ("forest", "minirocket"),
        "trees": 200}  # fmt: skip
QUICK = {"train": 6, "test": 4, "plates": 4, "folds": 3, "models": ("forest",), "trees": 20}
PLATE_THICKNESSES = [0.008, 0.011, 0.014]  # m
PLATE_BOUNDARIES = ["SSSS", "CSCS"]
WINDOWS = {"window": "impact", "length": WINDOW_S, "pre": 0.0005, "first_only": True}
SNR_DB = 10.0  # study 1 by model and sensors: also at this SNR (and without added noise)
TRAINING = {"nominal": "train", "randomised": "train_randomised", "plates": "train_plates"}
TESTS = {"nominal": ("h12", "cccc"), "randomised": ("nominal", "h12", "cccc"),
         "plates": ("nominal", "h12", "cccc")}  # fmt: skip


def plate_variant(scene: dict, thickness=None, boundary=None) -> dict:
    """``scene`` with another plate thickness (m) or boundary."""
    plate = dict(scene["plate"])
    if thickness is not None:
        plate["size"] = [0.6, 0.6, thickness]
    if boundary is not None:
        plate["boundary"] = boundary
    return {**scene, "plate": plate}


def randomised(table: dict, samples: int) -> dict:
    """The study-1 sweep ``table`` with domain randomisation: plate damping, contact damping,
    each sensor's mounted resonance and noise floor, and a wider size and speed distribution."""

    def uniform(lo, hi, kind="uniform"):
        return {"distribution": kind, "low": lo, "high": hi, "samples": samples}

    axes = dict(table["axes"])
    axes["balls.rock.radius"] = uniform(0.007, 0.14, "loguniform")
    axes["balls.rock.velocity[2]"] = uniform(-6.0, -0.5)
    axes["plate.damping_ratio"] = uniform(0.003, 0.05, "loguniform")
    axes["contact.damping"] = uniform(30.0, 3000.0, "loguniform")
    for name, _ in SENSORS:
        axes[f"sensors.{name}.mounted_resonance"] = uniform(7000.0, 25000.0)
        axes[f"sensors.{name}.noise"] = uniform(0.0, 300.0)
    return {**table, "axes": axes}


def plate_randomised(table: dict, samples: int) -> dict:
    """``randomised(table)`` with the plate drawn too: thickness and edge conditions (neither
    the 12 mm nor the clamped plate of the test sets among them)."""

    def choice(values):
        return {"distribution": "choice", "values": values, "samples": samples}

    out = randomised(table, samples)
    out["axes"]["plate.size[2]"] = choice(PLATE_THICKNESSES)
    out["axes"]["plate.boundary"] = choice(PLATE_BOUNDARIES)
    return out


def designs(mode: dict) -> dict:
    """Folder name -> sweep table of the four datasets."""
    n, m = mode["train"], mode["test"]
    return {
        "train": sweep_table(n, base_scene(SENSORS), seed=1),
        "test_h12": sweep_table(m, plate_variant(base_scene(SENSORS), thickness=0.012), seed=11),
        "test_cccc": sweep_table(m, plate_variant(base_scene(SENSORS), boundary="CCCC"), seed=12),
        "train_randomised": randomised(sweep_table(n, base_scene(SENSORS), seed=13), n),
        "train_plates": plate_randomised(
            sweep_table(mode["plates"], plate_variant(base_scene(SENSORS), 0.01), seed=14),
            mode["plates"],
        ),
    }


def samples(folder, name: str, model: str, noise_rms: float = 0.0) -> Samples:
    """The first-impact windows of the dataset in ``folder`` as ``model`` reads them."""
    settings = {**WINDOWS, "noise_rms": noise_rms}
    if model == "forest":
        return Samples(feature_table(folder, **settings), name=name)
    meta, windows, sensors, fs = window_table(folder, **settings)
    return Samples(meta, windows, sensors, fs, name)


def main(
    quick: bool = True, out="out/study_transfer", workers=None, client=None, sweep=True
) -> list:
    """Run the four sweeps (``sweep``; else take the datasets in ``out`` as they are), then
    every model; returns the rows (also in DIR/transfer.csv)."""
    mode = QUICK if quick else FULL
    out = Path(out)
    folders = {}
    for name, table in designs(mode).items():
        folders[name] = out / name
        if sweep:
            workers = workers or (1 if quick else None)
            run_sweep(parse_sweep(table), folders[name], workers=workers, client=client)
    rows = []
    for model in mode["models"]:
        trees = mode["trees"] if model == "forest" else None
        rows += transfer_rows(folders, model, mode["folds"], trees=trees)
        rows += snr_rows(folders["train"], model, mode["folds"], trees=trees)
    write_rows(out / "transfer.csv", rows)
    return rows


def _row(model, sensors, training, normalise, tested, s, cv=False) -> dict:
    return {
        "model": model,
        "sensors": sensors,
        "training": training,
        "normalise": int(normalise),
        "tested_on": tested,
        "snr_db": math.inf,
        "accuracy": s["accuracy"],
        "f1_macro": s["f1_macro"],
        "majority": s["dummy"]["accuracy"],
        "n_rows": s["n_rows"],
        "n_cases": s["n_cases"],
        "cross_validated": int(cv),
    }


def transfer_rows(folders: dict, model: str, folds: int, trainings=tuple(TESTS), trees=None):
    """Each training set of ``trainings`` x sensor set x normalise: its grouped CV score and
    its scores on the other sets (a list of rows); ``trees``: the forest's."""
    keys = {**TRAINING, "h12": "test_h12", "cccc": "test_cccc"}
    data = {name: samples(folders[key], name, model) for name, key in keys.items()}
    rows = []
    for training in trainings:
        train = data[training]
        for label, sensors in SENSOR_SETS.items():
            for normalise in (False, True):
                s = learn(train, folds=folds, sensors=sensors, model=model, trees=trees,
                          normalise=normalise, test=[data[t] for t in TESTS[training]])  # fmt: skip
                rows.append(_row(model, label, training, normalise, training, s, cv=True))
                rows += [
                    _row(model, label, training, normalise, t["dataset"], t) for t in s["test"]
                ]
    return rows


def snr_rows(folder, model: str, folds: int, trees=None) -> list:
    """Study 1 by model and sensors at SNR_DB (noise re the median clean window RMS over the
    three sensors, one RMS for all); ``trees``: the forest's."""
    clean = feature_table(folder, **WINDOWS)
    ref = float(np.median(clean[[f"{n}.rms" for n, _ in SENSORS]].to_numpy()))
    noise = ref / 10 ** (SNR_DB / 20)
    data = samples(folder, "nominal", model, noise)
    rows = []
    for label, sensors in SENSOR_SETS.items():
        s = learn(data, folds=folds, sensors=sensors, model=model, trees=trees)
        rows.append({**_row(model, label, "nominal", False, "nominal", s, cv=True),
                     "snr_db": SNR_DB})  # fmt: skip
    return rows


def visualize(rows: list, path) -> Path:
    """Accuracy of every model and training set on each dataset, beside the majority class."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    mine = [r for r in rows if math.isinf(r["snr_db"])]
    order = list(TRAINING)
    groups = sorted(
        {(r["model"], r["sensors"], r["training"], r["normalise"]) for r in mine},
        key=lambda g: (g[0], g[1], order.index(g[2]), g[3]),
    )
    colours = {"nominal": "tab:blue", "randomised": "tab:purple", "plates": "tab:brown",
               "h12": "tab:orange", "cccc": "tab:green"}  # fmt: skip
    fig, ax = plt.subplots(figsize=(max(12.0, 0.8 * len(groups)), 5.6), constrained_layout=True)
    width, seen = 0.2, set()
    for i, g in enumerate(groups):
        bars = [r for r in mine if (r["model"], r["sensors"], r["training"], r["normalise"]) == g]
        bars.sort(key=lambda r: list(colours).index(r["tested_on"]))
        for j, r in enumerate(bars):
            t = r["tested_on"]
            label = f"{t} (grouped CV)" if r["cross_validated"] else t
            ax.bar(i + (j - (len(bars) - 1) / 2) * width, r["accuracy"], width,
                   color=colours[t], hatch="//" if r["cross_validated"] else None,
                   edgecolor="white", label=None if label in seen else label)  # fmt: skip
            seen.add(label)
    ax.axhline(0.5, color="k", ls="--", lw=1, label="majority class (0.50)")
    names = [f"{m}\n{s.replace('S1+S2+S3', '3 sensors')}\n{tr}\n{'norm.' if n else ''}"
             for m, s, tr, n in groups]  # fmt: skip
    ax.set_xticks(range(len(groups)), names, fontsize=6.5)
    ax.set_ylim(0.3, 0.9)
    ax.set_ylabel("accuracy (hatched: grouped CV on the training set)")
    n = {r["tested_on"]: int(r["n_cases"]) for r in mine}
    ax.set_title(
        "coal vs sandstone, first impacts: trained on the 10 mm SSSS plate (nominal), the "
        f"randomised set (randomised, {n.get('randomised', 0)} cases) or randomised plates "
        f"(plates, {n.get('plates', 0)} cases),\ntested on 12 mm SSSS (h12, "
        f"{n['h12']} cases), 10 mm CCCC (cccc, {n['cccc']} cases) and the nominal set "
        f"({n['nominal']} cases); norm.: --normalise",
        fontsize=9,
    )
    ax.legend(fontsize=7, ncol=3, loc="upper right")
    ax.grid(axis="y", alpha=0.3)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return Path(path)


def read_rows(path) -> list:
    """Rows of a previous run's transfer.csv (to redraw the figure)."""
    return separability.read_rows(path, text=("model", "sensors", "training", "tested_on"))


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--full", action="store_true", help="200 + 200 training cases, both models")
    parser.add_argument("--out", default="out/study_transfer")
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument(
        "--no-sweep", action="store_true", help="use the datasets in --out as they are"
    )
    args = parser.parse_args()
    result = main(quick=not args.full, out=args.out, workers=args.workers, sweep=not args.no_sweep)
    for r in result:
        print(
            f"{r['model']:>10} {r['sensors']:>8} trained {r['training']:>10}"
            f"{' norm.' if r['normalise'] else '      '} SNR {r['snr_db']:>4} dB on "
            f"{r['tested_on']:>10}{' (CV)' if r['cross_validated'] else '     '}: "
            f"accuracy {r['accuracy']:.3f} (majority {r['majority']:.3f}; {r['n_cases']} cases)"
        )
    print(visualize(result, Path(args.out) / "transfer.png"))
