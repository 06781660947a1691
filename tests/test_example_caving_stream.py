"""examples/caving_stream.py runs and shows what it claims: gangue lumps strike harder."""

import importlib.util
import math
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "caving_stream.py"


def _example():
    spec = importlib.util.spec_from_file_location("caving_stream", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_coal_only_and_gangue_streams(tmp_path):
    ex = _example()
    results = ex.run(n_particles=40, fmax_hz=2000.0)
    rows = {row["case"]: row for row in ex.summary(results)}
    coal, mixed = rows["coal only"], rows["30 % gangue"]
    assert math.isnan(coal["median_peak_force_gangue_N"])
    # the same arrivals: the same particles, some of them sandstone in the second case
    assert coal["particles"] == mixed["particles"] >= 30
    labels = set(results["30 % gangue"].particles_table()["label"])
    assert labels == {"coal", "gangue"}
    # sandstone is denser and stiffer: its plate impacts are harder (Hertz: F ~ m^0.6 E*^0.4)
    assert mixed["median_peak_force_gangue_N"] > 1.3 * mixed["median_peak_force_coal_N"]
    assert ex.visualize(results, tmp_path).stat().st_size > 50_000
