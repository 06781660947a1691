"""A dataset's signals out to vibration software: one UFF 58 file per case and a labels.csv.

``export_dataset(dataset_dir, out_dir, "uff58")`` reads ``dataset.zarr`` (a sweep's, or one
made by ``tailbeam import``: ``acceleration`` (case, sensor, time) in m/s^2) and writes into
``out_dir`` ``case_<id>.uff`` for every case it holds (tailbeam.io.uff: one dataset 58 per
sensor) and ``labels.csv``: ``file``, ``label``, then every coordinate of ``case`` (``case``,
``case_hash``, seed, labels, swept values, ...) as the dataset holds it. ``out_dir`` is
replaced whole (tailbeam.io.output), with a manifest.json.
"""

from pathlib import Path

import numpy as np

from tailbeam.errors import InputError
from tailbeam.io.output import atomic_output_dir, check_output_dir, describe
from tailbeam.io.uff import UNIT, note_interval, write_labels_csv, write_uff58
from tailbeam.progress import task

FORMATS = ("uff58",)


def check_format(fmt: str, field: str = "format") -> str:
    """``fmt`` if it is one of FORMATS, else InputError naming ``field``."""
    if fmt not in FORMATS:
        raise InputError(field, f"unknown format {fmt!r}; choose from {', '.join(FORMATS)}")
    return fmt


def zarr_path(dataset_dir) -> Path:
    """The dataset.zarr of a dataset folder (or the store itself); InputError if missing."""
    path = Path(dataset_dir)
    store = path if path.name.endswith(".zarr") else path / "dataset.zarr"
    if not store.is_dir():
        raise InputError("DATASET", f"no dataset.zarr in {str(path)!r}")
    return store


def export_dataset(dataset_dir, out_dir, fmt: str = "uff58", *, command: str = "") -> dict:
    """Write every case of a dataset as UFF 58 files and labels.csv into ``out_dir``.

    Parameters
    ----------
    dataset_dir : path-like
        A folder holding ``dataset.zarr`` (or the store itself).
    out_dir : path-like
        The export folder: new, empty or an earlier export (replaced whole).
    fmt : str
        "uff58".
    command : str
        The command line, for the manifest.

    Returns
    -------
    dict
        ``cases`` (files written), ``sample_rate_hz``, ``out_dir``.
    """
    import xarray as xr

    check_format(fmt)
    store = zarr_path(dataset_dir)
    check_output_dir(out_dir)
    with xr.open_zarr(store) as ds:
        if "acceleration" not in ds or ds["acceleration"].dims != ("case", "sensor", "time"):
            rule = f"{str(store)!r} holds no acceleration (case, sensor, time)"
            raise InputError("DATASET", rule)
        fs = _sample_rate(ds)
        note_interval(fs)
        rows = _case_rows(ds)
        with atomic_output_dir(out_dir, command=command) as tmp:
            _write_cases(ds, tmp, rows, fs)
            labels = write_labels_csv(tmp / "labels.csv", rows)
            describe(labels, rows="one per .uff file")
    return {"cases": len(rows), "sample_rate_hz": fs, "out_dir": str(out_dir)}


def _sample_rate(ds) -> float:
    if "sample_rate_hz" in ds.attrs:
        return float(ds.attrs["sample_rate_hz"])
    t = ds["time"].values
    if len(t) < 2:
        raise InputError("DATASET", "needs at least 2 samples per record")
    return float((len(t) - 1) / (t[-1] - t[0]))


def _scalar(value):
    """A numpy scalar as the plain Python value the CSV writer expects."""
    return value.item() if isinstance(value, np.generic) else value


def _case_rows(ds) -> list:
    """One labels.csv row per case: file, label, then every coordinate of ``case``."""
    coords = [n for n, c in ds.coords.items() if c.dims == ("case",)]
    values = {n: ds[n].values for n in coords}
    ids = values.get("case", np.arange(ds.sizes["case"]))
    width = max(4, len(str(int(np.max(ids))))) if len(ids) else 4
    rows = []
    for i, cid in enumerate(ids):
        row = {"file": f"case_{int(cid):0{width}d}.uff"}
        row["label"] = _scalar(values["label"][i]) if "label" in values else ""
        row.update({n: _scalar(values[n][i]) for n in coords if n != "label"})
        rows.append(row)
    return rows


def _write_cases(ds, folder: Path, rows: list, fs: float) -> None:
    """The UFF files, read one Zarr chunk of cases at a time (not one case at a time: a chunk
    holds many cases and would be decoded once per case)."""
    acc = ds["acceleration"]
    sensors = [str(s) for s in ds["sensor"].values]
    t0 = float(ds["time"].values[0]) if ds.sizes["time"] else 0.0
    sizes = acc.chunks[0] if acc.chunks else (ds.sizes["case"],)
    start = 0
    with task(f"UFF 58 export of {len(rows)} cases", total=len(rows), unit="cases") as bar:
        for size in sizes:
            block = acc.isel(case=slice(start, start + size)).values
            for k, signals in enumerate(block):
                row = rows[start + k]
                path = write_uff58(
                    folder / row["file"],
                    dict(zip(sensors, signals, strict=True)),
                    fs,
                    case=Path(row["file"]).stem,
                    label=str(row["label"]),
                    t0=t0,
                )
                describe(path, units={"t": "s", "acceleration": UNIT}, sample_rate_hz=fs)
            start += size
            bar.update(size)
