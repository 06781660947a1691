"""The imported dataset written chunk by chunk, in the layout of a sweep's dataset
(tailbeam.study.dataset): ``dataset.zarr`` with ``acceleration`` (case, sensor, time) float32
in m/s^2, ``impacts.parquet`` (one row per detected onset) and ``cases.csv`` (one row per
case). Signals are staged one Zarr chunk at a time, so memory stays bounded whatever the
length of a case; the per-case coordinates are written when the last case is."""

import json
import warnings
from pathlib import Path

import numpy as np

from tailbeam.study.dataset import CASE_COORD_CHUNK, CHUNK_BYTES

TIME_CHUNK = 1 << 20  # samples per chunk of the time coordinate
IMPACT_COLUMNS = ("case", "case_hash", "ball", "index", "material", "class", "v_in", "t_start",
                  "partner", "t_source")  # fmt: skip


def chunk_shape(n_sensor: int, n_time: int) -> tuple:
    """(cases, time samples) per chunk of acceleration: whole cases up to CHUNK_BYTES."""
    per_case = 4 * n_sensor * n_time
    if per_case <= CHUNK_BYTES:
        return max(1, CHUNK_BYTES // per_case), n_time
    return 1, max(1, CHUNK_BYTES // (4 * n_sensor))


class SignalWriter:
    """``acceleration`` and ``time`` of dataset.zarr; ``put(case, t0, block)`` stages a
    (sensor, k) block of case ``case`` at time sample ``t0``; a chunk is written once full."""

    def __init__(self, zarr_path: Path, sensors: list, n_time: int, fs: float):
        import zarr

        self.group = zarr.open_group(zarr_path, mode="w")
        self.n_sensor, self.n_time = len(sensors), n_time
        self.cc, self.tc = chunk_shape(len(sensors), n_time)
        self.array = self.group.create_array(
            "acceleration",
            shape=(0, len(sensors), n_time),
            chunks=(self.cc, len(sensors), self.tc),
            dtype="float32",
            fill_value=np.nan,
            dimension_names=("case", "sensor", "time"),
            attributes={"units": "m/s^2", "long_name": "sensor acceleration, as measured"},
        )
        self._write_time(fs)
        self.staged = {}  # (case chunk, time chunk) -> [buffer, samples filled]
        self.n_cases = 0

    def _write_time(self, fs: float) -> None:
        time = self.group.create_array(
            "time",
            shape=(self.n_time,),
            chunks=(min(TIME_CHUNK, self.n_time),),
            dtype="float64",
            dimension_names=("time",),
            attributes={"units": "s"},
        )
        for lo in range(0, self.n_time, TIME_CHUNK):
            hi = min(lo + TIME_CHUNK, self.n_time)
            time[lo:hi] = np.arange(lo, hi) / fs

    def _time_len(self, tk: int) -> int:
        return min(self.tc, self.n_time - tk * self.tc)

    def put(self, case: int, t0: int, block: np.ndarray) -> None:
        self.n_cases = max(self.n_cases, case + 1)
        ck = case // self.cc
        pos = 0
        while pos < block.shape[1]:
            t = t0 + pos
            tk = t // self.tc
            k = min(block.shape[1] - pos, (tk + 1) * self.tc - t)
            entry = self.staged.setdefault(
                (ck, tk), [np.full((self.cc, self.n_sensor, self._time_len(tk)), np.nan, "f4"), 0]
            )
            entry[0][case - ck * self.cc, :, t - tk * self.tc : t - tk * self.tc + k] = block[
                :, pos : pos + k
            ]
            entry[1] += k
            if entry[1] == self.cc * self._time_len(tk):
                self._flush(ck, tk)
            pos += k

    def _flush(self, ck: int, tk: int) -> None:
        buf, _n = self.staged.pop((ck, tk))
        rows = min(self.cc, self.n_cases - ck * self.cc)
        if self.array.shape[0] < ck * self.cc + rows:
            self.array.resize((max(self.array.shape[0], (ck + 1) * self.cc), *self.array.shape[1:]))
        t = tk * self.tc
        self.array[ck * self.cc : ck * self.cc + rows, :, t : t + buf.shape[2]] = buf[:rows]

    def close(self, n_cases: int) -> None:
        """Write the partly filled chunks and trim the case axis to ``n_cases``."""
        self.n_cases = n_cases
        for key in sorted(self.staged):
            if key[0] * self.cc < n_cases:
                self._flush(*key)
        self.staged.clear()
        self.array.resize((n_cases, *self.array.shape[1:]))


def write_coordinates(zarr_path: Path, cases, sensors: list, positions, attrs: dict) -> None:
    """The per-case coordinates (a DataFrame, one row per case in order), ``sensor``,
    ``sensor_x``/``sensor_y`` ((case, sensor) arrays, m), then the attributes and the
    consolidated metadata."""
    import xarray as xr
    import zarr

    coords = {"case": ("case", cases["case"].to_numpy(np.int64))}
    coords["sensor"] = ("sensor", np.array(sensors, dtype=object))
    for col in cases.columns.drop("case"):
        values = cases[col].to_numpy()
        coords[col] = ("case", values.astype(object) if values.dtype.kind in "OUT" else values)
    for axis, name in enumerate(("sensor_x", "sensor_y")):
        coords[name] = (("case", "sensor"), positions[axis], {"units": "m"})
    ds = xr.Dataset(coords=coords)
    enc = {n: {"chunks": (CASE_COORD_CHUNK, *v.shape[1:])} for n, v in ds.coords.items()
           if v.dims and v.dims[0] == "case"}  # fmt: skip
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message="Consolidated metadata")
        ds.to_zarr(zarr_path, mode="a", encoding=enc, consolidated=False)
        group = zarr.open_group(zarr_path, mode="a")
        group.attrs.update(attrs)
        zarr.consolidate_metadata(zarr_path)


def write_tables(folder: Path, cases, impacts: list) -> None:
    """impacts.parquet (IMPACT_COLUMNS, one row per onset) and cases.csv."""
    import pandas as pd

    table = pd.DataFrame(impacts, columns=list(IMPACT_COLUMNS))
    table = table.astype({"case": "int64", "ball": "int64", "index": "int64", "v_in": "float64",
                          "t_start": "float64", "t_source": "float64"})  # fmt: skip
    table.to_parquet(folder / "impacts.parquet")
    ledger = cases.assign(status="ok", error="")
    first = ["case", "case_hash", "status", "error"]
    ledger[first + [c for c in ledger.columns if c not in first]].to_csv(
        folder / "cases.csv", index=False
    )


def json_attr(value) -> str:
    """A JSON text for a Zarr attribute (numpy numbers as plain numbers)."""
    return json.dumps(value, default=lambda o: o.item() if hasattr(o, "item") else str(o))
