"""The study scripts (examples/study_*.py) run end to end in quick mode: sweep on a local Dask
cluster, features, grouped cross-validation; their outputs have the promised shape."""

import importlib.util
import math
import sys
from pathlib import Path

import pytest

pytest.importorskip("dask.distributed")
pytest.importorskip("sklearn")

EXAMPLES = Path(__file__).parents[1] / "examples"


def _load(name):
    sys.path.insert(0, str(EXAMPLES))
    try:
        spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    finally:
        sys.path.remove(str(EXAMPLES))
    return module


@pytest.fixture(scope="module")
def client():
    from dask.distributed import Client

    from tailbeam.study.sweep import local_cluster

    cluster = local_cluster(1)
    with Client(cluster) as c:
        yield c
    cluster.close()


def test_single_impact_study_quick(tmp_path, client):
    module = _load("study_single_impacts")
    rows = module.main(quick=True, out=tmp_path, client=client)
    assert [r["snr_db"] for r in rows] == [math.inf, 0.0]
    assert rows[0]["n_cases"] == 12 and rows[0]["noise_rms"] == 0.0
    assert rows[1]["noise_rms"] == pytest.approx(rows[1]["reference_rms"])  # 0 dB
    assert all(0.0 <= r["accuracy"] <= 1.0 for r in rows)
    assert (tmp_path / "accuracy_vs_snr.csv").is_file()


def test_sensor_placement_study_quick(tmp_path, client):
    module = _load("study_sensor_placement")
    rows = module.main(quick=True, out=tmp_path, client=client)
    assert [(r["x"], r["y"]) for r in rows] == [
        (-0.24, -0.24),
        (0.24, -0.24),
        (-0.24, 0.24),
        (0.24, 0.24),
    ]
    assert all(r["n_cases"] == 12 for r in rows)


def test_stream_gangue_fraction_study_quick(tmp_path, client):
    module = _load("study_stream_gangue_fraction")
    rows = module.main(quick=True, out=tmp_path, client=client)
    assert [r["snr_db"] for r in rows] == [math.inf, 0.0]
    assert rows[1]["noise_rms"] == pytest.approx(rows[1]["reference_rms"])  # 0 dB
    assert rows[0]["n_cases"] == 6 and rows[0]["n_rows"] == 12  # two windows after the first
    assert 0.0 <= rows[0]["fraction_min"] <= rows[0]["fraction_max"] <= 0.5
    assert all(r["mae"] >= 0.0 and r["count_reference_mae"] >= 0.0 for r in rows)
    assert (tmp_path / "gangue_fraction_vs_snr.csv").is_file()
    assert module.visualize(rows, tmp_path / "f.png").stat().st_size > 0


@pytest.mark.slow
def test_transfer_study_quick(tmp_path, client):
    module = _load("study_transfer")
    rows = module.main(quick=True, out=tmp_path, client=client)
    cv = [r for r in rows if r["cross_validated"] and math.isinf(r["snr_db"])]
    tests = [r for r in rows if not r["cross_validated"]]
    # three training sets x two sensor sets x normalise or not; 2, 3 and 3 test sets
    assert len(cv) == 12 and len(tests) == 4 * 2 + 4 * 3 + 4 * 3
    assert {r["tested_on"] for r in tests} == {"nominal", "h12", "cccc"}
    assert all(r["n_cases"] == 8 for r in tests if r["tested_on"] != "nominal")
    assert [r["snr_db"] for r in rows if r["cross_validated"]][-2:] == [10.0, 10.0]
    assert all(0.0 <= r["accuracy"] <= 1.0 for r in rows)
    assert module.visualize(rows, tmp_path / "t.png").stat().st_size > 0


def test_stream_models_study_quick(tmp_path, client):
    module = _load("study_stream_models")
    rows = module.main(quick=True, out=tmp_path, client=client)
    assert [(r["sensors"], r["snr_db"]) for r in rows] == [
        ("S1", math.inf),
        ("S1+S2+S3", math.inf),
        ("S1", 0.0),
        ("S1+S2+S3", 0.0),
    ]
    assert all(r["n_cases"] == 6 and r["n_rows"] == 12 for r in rows)
