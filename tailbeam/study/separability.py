"""Separability of coal and gangue against measurement noise, from a sweep dataset.

White noise (the ``[[sensors]] noise`` model) is added to the stored clean signals at levels
set by a signal-to-noise ratio relative to a reference level: the median RMS over the
dataset's clean first-impact windows of the sensor. One noise level applies to every case,
as a sensor's noise floor does, so small, slow coal impacts sit at a lower SNR than large,
fast sandstone ones. For each level: the feature table (first impacts), then the grouped
cross-validated baseline (tailbeam.study.learn).
"""

import math

import numpy as np

from tailbeam.io.results_io import write_csv
from tailbeam.study.learn import learn
from tailbeam.study.windows import feature_table


def reference_rms(path, sensor: str, *, length: float) -> float:
    """Median RMS (m/s^2) of the clean first-impact windows of ``sensor``."""
    table = feature_table(path, length=length, first_only=True)
    return float(np.median(table[f"{sensor}.rms"]))


def accuracy_vs_snr(path, snr_db, sensor: str, *, length=0.02, folds=5, ref_rms=None) -> list:
    """For each SNR (dB; math.inf = no added noise): dict of snr_db, noise_rms (m/s^2),
    accuracy, f1_macro, dummy_accuracy, n_rows, n_cases."""
    ref = ref_rms if ref_rms is not None else reference_rms(path, sensor, length=length)
    rows = []
    for snr in snr_db:
        noise_rms = 0.0 if math.isinf(snr) else ref / 10 ** (snr / 20)
        table = feature_table(path, length=length, noise_rms=noise_rms, first_only=True)
        s = learn(table, "label", folds=folds, sensors=[sensor])
        rows.append(
            {
                "snr_db": snr,
                "noise_rms": noise_rms,
                "accuracy": s["accuracy"],
                "f1_macro": s["f1_macro"],
                "dummy_accuracy": s["dummy"]["accuracy"],
                "n_rows": s["n_rows"],
                "n_cases": s["n_cases"],
                "reference_rms": ref,
            }
        )
    return rows


def write_rows(path, rows: list):
    """Write a list of dicts (one header, the first row's keys) as CSV; returns the path."""
    keys = list(rows[0])
    return write_csv(path, keys, ([r[k] for k in keys] for r in rows))


def read_rows(path, text=()) -> list:
    """Rows written by write_rows, numbers as floats except the columns named in ``text``."""
    import csv
    from pathlib import Path

    with Path(path).open() as fh:
        return [{k: v if k in text else float(v) for k, v in r.items()} for r in csv.DictReader(fh)]
