"""Whether two sweep output folders hold the same dataset.

    python tools/compare_sweep_datasets.py DIR_A DIR_B

Compares ``dataset.zarr`` (signals, coordinates, attributes: ``xarray.testing.assert_identical``),
``impacts.parquet`` and ``cases.csv`` (exactly), after ordering the cases by their hash and
leaving out what a run may change: the case ids (they follow completion order) and the
timings (``wall_time``, ``cpu_time``). Within a case, impact rows keep their order. Prints
"identical" and the sizes, or the first difference (exit code 1).

Two revisions' sweeps of one sweep file, with one modal cache so that both read the same
basis file (a basis computed again differs at rounding level), the base's from outside the
work tree (Python puts the current folder first on its path)::

    mkdir /tmp/base && git archive REV | tar -x -C /tmp/base
    export TAILBEAM_CACHE_DIR=/tmp/sweep-cache SWEEP=$PWD/examples/sweeps/single_impacts.toml
    (cd /tmp && PYTHONPATH=/tmp/base python -m tailbeam sweep $SWEEP --out /tmp/sweep-base)
    python -m tailbeam sweep $SWEEP --out /tmp/sweep-this
    python tools/compare_sweep_datasets.py /tmp/sweep-base /tmp/sweep-this

Or the two datasets ``benchmarks/bench_sweep.py --out DIR`` writes (DIR/dataset_1w and
DIR/dataset_2w: one sweep on 1 and on 2 workers).
"""

import argparse
import sys
from pathlib import Path

import pandas as pd
import xarray as xr


def load(folder: Path):
    """(dataset, impact table, ledger) of a sweep folder, ordered by case hash, without case
    ids and timings."""
    with xr.open_zarr(folder / "dataset.zarr") as ds:
        ds = ds.load().sortby("case_hash").drop_vars("case")
    impacts = pd.read_parquet(folder / "impacts.parquet")
    impacts = impacts.assign(row_in_case=impacts.groupby("case_hash").cumcount())
    impacts = impacts.sort_values(["case_hash", "row_in_case"]).drop(columns="case")
    ledger = pd.read_csv(folder / "cases.csv").drop(columns=["case", "wall_time", "cpu_time"])
    ledger = ledger.sort_values("case_hash")
    return ds, impacts.reset_index(drop=True), ledger.reset_index(drop=True)


def main(a: Path, b: Path) -> int:
    (ds_a, imp_a, led_a), (ds_b, imp_b, led_b) = load(a), load(b)
    try:
        xr.testing.assert_identical(ds_a, ds_b)
        pd.testing.assert_frame_equal(imp_a, imp_b, check_exact=True)
        pd.testing.assert_frame_equal(led_a, led_b, check_exact=True)
    except AssertionError as err:
        print(f"different: {str(err).strip().splitlines()[0]}")
        return 1
    print(
        f"identical: {ds_a.sizes['case']} cases, signals {ds_a['acceleration'].shape}, "
        f"{len(imp_a)} impact rows, {len(led_a)} ledger rows"
    )
    return 0


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("a", type=Path)
    parser.add_argument("b", type=Path)
    args = parser.parse_args()
    sys.exit(main(args.a, args.b))
