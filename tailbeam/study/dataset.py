"""The dataset of a sweep, in its output folder DIR:

- ``dataset.zarr``: an xarray Dataset (Zarr v3). ``acceleration`` (case, sensor, time) float32
  in m/s^2 as each sensor recorded it (chain and noise included); coordinates of ``case``: the
  case hash, seed, repeat, labels (``label``, ``gangue_fraction``, ``n_coal``, ``n_gangue``,
  ``n_coal_impacts``, ``n_gangue_impacts``; for stream scenes also ``gangue_mass_fraction``,
  ``n_particles``, ``n_ball_contacts``), the modal band ``band_hz`` and the band check's
  estimate of the peak-force error ``band_force_error`` (NaN on the rigid plate), ``valid``
  (that estimate within the sweep's ``band_accuracy``) and ``invalid_reason``, and every
  swept value (vector values one coordinate per component, ``key[i]``); per case and sensor
  signal (a sensor, or ``<name>_x``... for each axis of a three-axis one) its point
  ``sensor_x``, ``sensor_y``, ``sensor_z`` in m and the unit direction it reads along,
  ``sensor_dx``, ``sensor_dy``, ``sensor_dz``.
  Attributes: units, sample rate (Hz), duration (s), the base sensor positions, the tailbeam
  version, the sweep file, and ``case_scenes`` (case hash -> the case's scene TOML).
  Finished cases are appended along ``case``; open it with ``xarray.open_zarr(DIR/dataset.zarr)``.
- ``impacts.parquet``: one row per impact of every finished case (``case``, ``case_hash``,
  every impacts.csv column, ``class`` = the ball's ``label``).
- ``cases.csv``: one row per case run so far: ``case``, ``case_hash``, ``status`` (ok | failed),
  ``error`` (one line), ``wall_time`` and ``cpu_time`` (s, on the worker), seed, repeat,
  labels, band, ``valid``, ``invalid_reason`` and the swept values (docs/datasets.md).

Order of writes per batch: impacts.parquet (whole table, atomic rename), then the Zarr append,
then cases.csv. The Zarr store is the record of finished cases: on opening, impact rows of
cases missing from it (a crash mid-batch) are dropped and cases.csv is completed from it.
"""

import json
import os
import tempfile
import warnings
from pathlib import Path

import numpy as np

from tailbeam._version import __version__
from tailbeam.io.scene_file import loads_scene
from tailbeam.solvers.modal_setup.band import BAND_ACCURACY
from tailbeam.study.case import validity

LABEL_COLUMNS = (
    "label",
    "gangue_fraction",
    "n_coal",
    "n_gangue",
    "n_coal_impacts",
    "n_gangue_impacts",
)
# labels of stream scenes only (tailbeam.study.labels.stream_labels, tailbeam.study.case)
STREAM_LABEL_COLUMNS = ("gangue_mass_fraction", "n_particles")
STREAM_RESULT_COLUMNS = ("n_ball_contacts",)
# the modal band of a case and the band check's estimate of its peak-force error (NaN: rigid)
BAND_COLUMNS = ("band_hz", "band_force_error")
# whether that estimate is within the sweep's band_accuracy (tailbeam.study.case.validity)
VALIDITY_COLUMNS = ("valid", "invalid_reason")
LEDGER_COLUMNS = (
    "case",
    "case_hash",
    "status",
    "error",
    "wall_time",
    "cpu_time",
    "seed",
    "repeat",
)
# per case and signal: its point (m) and the unit direction it reads along
SENSOR_COORDS = ("sensor_x", "sensor_y", "sensor_z", "sensor_dx", "sensor_dy", "sensor_dz")
CHUNK_BYTES = 4 << 20  # target size of one Zarr chunk of signals along case
CASE_COORD_CHUNK = 4096  # cases per chunk of the per-case coordinates


def flat_params(params: dict) -> dict:
    """Swept values as scalars: a vector value ``key`` becomes ``key[0]``, ``key[1]``, ..."""
    out = {}
    for key, value in params.items():
        if isinstance(value, list | tuple):
            out.update({f"{key}[{i}]": v for i, v in enumerate(value)})
        else:
            out[key] = value
    return out


def _atomic_write(path: Path, write) -> None:
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    os.close(fd)
    try:
        write(tmp)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


class DatasetStore:
    """The dataset files of one output folder: what is done, and appending finished cases."""

    def __init__(self, out_dir, sweep_text: str = "", band_accuracy: float = BAND_ACCURACY):
        import pandas as pd

        self.band_accuracy = band_accuracy
        self.dir = Path(out_dir)  # created by the first record()
        self.zarr_path = self.dir / "dataset.zarr"
        self.sweep_text = sweep_text
        csv = self.dir / "cases.csv"
        self.ledger = pd.read_csv(csv) if csv.is_file() else pd.DataFrame(columns=LEDGER_COLUMNS)
        self.impacts = (
            pd.read_parquet(self.dir / "impacts.parquet")
            if (self.dir / "impacts.parquet").is_file()
            else None
        )
        self._reconcile()

    # -- state ------------------------------------------------------------------------------------

    def stored_hashes(self) -> set:
        """Hashes of the cases in dataset.zarr."""
        if not self.zarr_path.exists():
            return set()
        import xarray as xr

        with xr.open_zarr(self.zarr_path) as ds:
            return {str(h) for h in ds["case_hash"].values}

    def _reconcile(self) -> None:
        import xarray as xr

        stored = self.stored_hashes()
        if self.impacts is not None:
            self.impacts = self.impacts[self.impacts["case_hash"].isin(stored)]
        known = set(self.ledger.loc[self.ledger["status"] == "ok", "case_hash"])
        missing = stored - known
        if missing:  # finished cases whose ledger row was not written: rebuild from the store
            with xr.open_zarr(self.zarr_path) as ds:
                drop = ["acceleration", "sensor", "time", *SENSOR_COORDS]
                coords = ds.drop_vars(drop, errors="ignore")
                df = coords.to_dataframe().reset_index()
            df = df[df["case_hash"].isin(missing)].assign(status="ok", error="")
            self._set_rows(df.to_dict("records"))

    def done(self) -> set:
        """Hashes of finished cases (status ok and stored)."""
        ok = set(self.ledger.loc[self.ledger["status"] == "ok", "case_hash"])
        return ok & self.stored_hashes() if ok else set()

    def case_ids(self, hashes: list) -> list:
        """Integer ids of cases: kept from their first record, else the next free ones."""
        known = dict(zip(self.ledger["case_hash"], self.ledger["case"], strict=True))
        nxt = int(self.ledger["case"].max()) + 1 if len(self.ledger) else 0
        out = []
        for h in hashes:
            if h not in known:
                known[h] = nxt
                nxt += 1
            out.append(int(known[h]))
        return out

    def _set_rows(self, rows: list) -> None:
        import pandas as pd

        new = pd.DataFrame(rows)
        keep = self.ledger[~self.ledger["case_hash"].isin(new["case_hash"])]
        frames = [f for f in (keep, new) if len(f)]
        self.ledger = pd.concat(frames, ignore_index=True) if frames else new
        self.ledger = self.ledger.sort_values("case", kind="stable").reset_index(drop=True)

    # -- writing ----------------------------------------------------------------------------------

    def record(self, batch: list) -> None:
        """Write a batch of (Case, result dict) of finished or failed cases."""
        self.dir.mkdir(parents=True, exist_ok=True)
        rows, ok = [], []
        ids = self.case_ids([case.hash for case, _r in batch])
        for (case, result), cid in zip(batch, ids, strict=True):
            row = {
                "case": cid,
                "case_hash": case.hash,
                "status": result["status"],
                "error": result["error"],
                "wall_time": result["wall_time"],
                "cpu_time": result.get("cpu_time", float("nan")),
                "seed": case.seed,
                "repeat": case.repeat,
                **case.labels,
                "n_coal_impacts": result["n_coal_impacts"],
                "n_gangue_impacts": result["n_gangue_impacts"],
                **{k: result[k] for k in STREAM_RESULT_COLUMNS if k in result},
                **{k: result.get(k, float("nan")) for k in BAND_COLUMNS},
                **self._validity(result),
                **flat_params(case.params),
            }
            rows.append(row)
            if result["status"] == "ok":
                ok.append((row, case, result))
        if ok:
            self._write_impacts(ok)
            self._append_zarr(ok)
        self._set_rows(rows)
        _atomic_write(self.dir / "cases.csv", lambda p: self.ledger.to_csv(p, index=False))

    def _validity(self, result: dict) -> dict:
        """``valid`` and ``invalid_reason`` of a case's result (a failed case: not valid)."""
        if result["status"] != "ok":
            return {"valid": False, "invalid_reason": "failed (see error)"}
        return validity(result, self.band_accuracy)

    def _write_impacts(self, ok: list) -> None:
        import pandas as pd

        rows = [
            {"case": row["case"], "case_hash": case.hash, **impact}
            for row, case, result in ok
            for impact in result["impacts"]
        ]
        frames = [f for f in (self.impacts, pd.DataFrame(rows)) if f is not None and len(f)]
        if not frames:
            return
        table = pd.concat(frames, ignore_index=True)
        cols = ["case", "case_hash"] + [c for c in table.columns if c not in ("case", "case_hash")]
        self.impacts = table[cols]
        _atomic_write(self.dir / "impacts.parquet", lambda p: self.impacts.to_parquet(p))

    def _append_zarr(self, ok: list) -> None:
        import zarr

        ds = self._batch_dataset(ok)
        existing = self.zarr_path.exists()
        scenes = {case.hash: case.toml for _r, case, _res in ok}
        if existing:
            group = zarr.open_group(self.zarr_path, mode="r")
            scenes = {**group.attrs["case_scenes"], **scenes}
            # a store written by an older tailbeam lacks the newer per-case values
            ds = ds.drop_vars([name for name in ds.coords if name not in group])
        ds.attrs["case_scenes"] = scenes
        with warnings.catch_warnings():
            # consolidated metadata is not in the Zarr v3 spec yet; xarray reads it, and
            # without it every xarray.open_zarr warns
            warnings.filterwarnings("ignore", message="Consolidated metadata")
            if existing:
                ds.to_zarr(self.zarr_path, append_dim="case", mode="a")
            else:
                ds.to_zarr(self.zarr_path, mode="w", encoding=self._encoding(ds))

    def _encoding(self, ds) -> dict:
        per_case = ds["acceleration"][0].nbytes
        chunk = max(1, CHUNK_BYTES // max(per_case, 1))
        n_sensor, n_time = ds["acceleration"].shape[1:]
        enc = {"acceleration": {"chunks": (chunk, n_sensor, n_time)}}
        for name, var in ds.coords.items():  # per-case values: few, large chunks
            if var.dims and var.dims[0] == "case":
                enc[name] = {"chunks": (CASE_COORD_CHUNK, *var.shape[1:])}
        return enc

    def _batch_dataset(self, ok: list):
        import xarray as xr

        first_scene = loads_scene(ok[0][1].toml)  # what every case shares (design.expand)
        names = [c.name for s in first_scene.sensors for c in s.channels()]
        fs = first_scene.sensors[0].sample_rate
        acc = np.stack([np.stack([res["signals"][n] for n in names]) for _r, _c, res in ok])
        n_time = acc.shape[-1]
        coords = {
            "case": ("case", np.array([r["case"] for r, *_ in ok], dtype=np.int64)),
            "sensor": ("sensor", np.array(names, dtype=object)),
            "time": ("time", np.arange(n_time) / fs, {"units": "s"}),
        }
        skip = ("case", "status", "error", "wall_time", "cpu_time")
        for col in [c for c in ok[0][0] if c not in skip]:
            values = np.array([r[col] for r, *_ in ok])
            coords[col] = ("case", values.astype(object) if values.dtype.kind == "U" else values)
        for k, name in enumerate(SENSOR_COORDS):
            vectors = "sensor_points" if k < 3 else "sensor_directions"
            values = [[v[k % 3] for v in getattr(case, vectors)] for _r, case, _res in ok]
            coords[name] = (("case", "sensor"), np.array(values), {"units": "m" if k < 3 else "1"})
        acc_attrs = {"units": "m/s^2", "long_name": "sensor acceleration along its direction"}
        return xr.Dataset(
            {"acceleration": (("case", "sensor", "time"), acc.astype(np.float32), acc_attrs)},
            coords=coords,
            attrs={
                "title": "tailbeam sweep: simulated tail-beam vibration, labelled",
                "tailbeam_version": __version__,
                "sample_rate_hz": fs,
                "duration_s": first_scene.duration,
                "units": "acceleration m/s^2, time s, positions m",
                "sensor_positions_m": json.dumps(
                    {s.name: list(s.position) for s in first_scene.sensors}
                ),
                "sweep_file": self.sweep_text,
            },
        )
