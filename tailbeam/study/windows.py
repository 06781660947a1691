"""Windows cut from a sweep dataset, and their feature table (features.parquet).

Two kinds of window, each a row of the table with one column per sensor and feature
(``<sensor>.<feature>``):
- ``impact``: ``length`` s starting ``pre`` s before each impact of impacts.parquet (of a
  stream dataset: its plate rows only, not the ball-ball rows); the row's
  ``label`` is the class of the ball that struck (coal | gangue). Impacts whose window would
  run past the record are left out (and counted).
- ``fixed``: consecutive non-overlapping windows of ``length`` s; the row's ``label`` is the
  case's label (coal | gangue | mixed) and ``gangue_fraction`` the case's.
Every row also carries ``case`` (for grouped cross-validation), ``window``, ``t_start`` (s),
the case's labels and swept values. ``window_table`` gives the same rows with the raw windows
instead of their features (for models that read the signal itself, e.g. MiniRocket).
"""

import numpy as np

from tailbeam.errors import InputError
from tailbeam.progress import note, task
from tailbeam.study.features import all_features

BLOCK_CASES = 256  # cases read from the Zarr store at a time


def open_dataset(path):
    """(xarray Dataset, folder) of a sweep dataset: ``path`` is the sweep's output folder or
    its dataset.zarr."""
    from pathlib import Path

    import xarray as xr

    path = Path(path)
    store = path if path.name.endswith(".zarr") else path / "dataset.zarr"
    if not store.exists():
        raise InputError("DATASET", f"no dataset.zarr at {str(path)!r} (run tailbeam sweep first)")
    return xr.open_zarr(store), store.parent


def case_table(ds):
    """The per-case coordinates (labels, swept values, seed) as a DataFrame indexed by case."""
    names = [c for c, v in ds.coords.items() if v.dims == ("case",) and c != "case"]
    return ds[names].reset_coords().to_dataframe()[names]


def add_noise(acc, fs: float, rms: float, seeds, sensors) -> np.ndarray:
    """``acc`` (case, sensor, time) plus white noise of RMS ``rms`` (m/s^2), the model of
    ``[[sensors]] noise`` (tailbeam.signals.noise) drawn from each case's seed and sensor name."""
    from tailbeam.signals.noise import NoiseSpec, noise

    out = np.array(acc, dtype=float)
    for i, seed in enumerate(seeds):
        spec = NoiseSpec(rms=rms, seed=int(seed))
        for k, name in enumerate(sensors):
            out[i, k] += noise(spec, f"added:{name}", out.shape[-1], fs)
    return out


def _impact_starts(impacts, case_ids, n_time, fs, length, pre):
    imp = impacts[impacts["case"].isin(case_ids)].copy()
    imp["start"] = np.round((imp["t_start"].to_numpy() - pre) * fs).astype(int).clip(0)
    fits = imp["start"] + length <= n_time
    return imp[fits], int((~fits).sum())


def _features_frame(windows, fs, sensors, meta):
    import pandas as pd

    feats = all_features(windows, fs)  # each (rows, sensors)
    cols = {f"{s}.{name}": v[:, i] for name, v in feats.items() for i, s in enumerate(sensors)}
    return pd.concat([meta.reset_index(drop=True), pd.DataFrame(cols)], axis=1)


def _impact_block(acc, ids, impacts, fs, length, pre):
    rows, dropped = _impact_starts(impacts, ids, acc.shape[-1], fs, length, pre)
    pos = {c: i for i, c in enumerate(ids)}
    ci = rows["case"].map(pos).to_numpy()
    idx = rows["start"].to_numpy()[:, None] + np.arange(length)[None, :]
    win = acc[ci[:, None], :, idx].transpose(0, 2, 1)  # (rows, sensor, length)
    meta = rows[["case", "ball", "index", "material", "class", "v_in", "t_start"]].rename(
        columns={"index": "impact_index", "class": "label"}
    )
    meta = meta.assign(window=rows["index"].to_numpy() - 1, t_start=rows["t_start"] - pre)
    return win, meta, dropped


def _fixed_block(acc, ids, fs, length):
    import pandas as pd

    k = acc.shape[-1] // length
    if k < 1:
        raise InputError("--length", f"is longer than the record, {acc.shape[-1] / fs:g} s")
    win = acc[..., : k * length].reshape(len(ids), acc.shape[1], k, length)
    win = win.transpose(0, 2, 1, 3).reshape(len(ids) * k, acc.shape[1], length)
    meta = pd.DataFrame(
        {
            "case": np.repeat(ids, k),
            "window": np.tile(np.arange(k), len(ids)),
            "t_start": np.tile(np.arange(k) * length / fs, len(ids)),
        }
    )
    return win, meta


def window_blocks(
    path, *, window="impact", length=0.02, pre=0.0005, noise_rms=0.0, first_only=False
):
    """The windows of the dataset at ``path`` (see module docstring), a block of cases at a
    time: yields (windows (rows, sensor, samples) in m/s^2, meta DataFrame of the rows) after
    a first item (sensors, sample rate Hz, case table). Arguments as feature_table's."""
    import pandas as pd

    if window not in ("impact", "fixed"):
        raise InputError("--window", f"must be 'impact' or 'fixed', got {window!r}")
    ds, folder = open_dataset(path)
    fs = float(ds.attrs["sample_rate_hz"])
    n = int(round(length * fs))
    if n < 16:
        raise InputError("--length", f"must span at least 16 samples, {16 / fs:g} s")
    impacts = pd.read_parquet(folder / "impacts.parquet") if window == "impact" else None
    if impacts is not None and "partner" in impacts.columns:  # plate rows only (a dataset
        # written before every scene had ``partner`` holds plate rows only: empty cells)
        impacts = impacts[impacts["partner"].fillna("plate") == "plate"]
    if impacts is not None and first_only:
        impacts = impacts[impacts["index"] == 1]
    sensors = [str(s) for s in ds["sensor"].values]
    yield sensors, fs, case_table(ds)
    dropped = 0
    ids_all = ds["case"].values
    with task(f"windows of {len(ids_all)} cases", total=len(ids_all), unit="cases") as bar:
        for lo in range(0, len(ids_all), BLOCK_CASES):
            ids = ids_all[lo : lo + BLOCK_CASES]
            block = ds.isel(case=slice(lo, lo + len(ids)))
            acc = block["acceleration"].values.astype(float)
            if noise_rms > 0.0:
                acc = add_noise(acc, fs, noise_rms, block["seed"].values, sensors)
            if window == "impact":
                win, meta, d = _impact_block(acc, ids, impacts, fs, n, pre)
                dropped += d
            else:
                win, meta = _fixed_block(acc, ids, fs, n)
            if len(meta):
                yield win, meta
            bar.update(len(ids))
    if dropped:
        note(
            f"features: {dropped} impacts left out, their {length:g} s window runs past the record"
        )


def _with_cases(table, cases, window: str):
    if window == "impact":
        cases = cases.rename(columns={"label": "case_label"})
    return table.join(
        cases.drop(columns=[c for c in cases.columns if c in table.columns]), on="case"
    )


def _no_windows():
    return InputError("DATASET", "no windows: the dataset has no impacts that fit a window")


def feature_table(
    path, *, window="impact", length=0.02, pre=0.0005, noise_rms=0.0, first_only=False
):
    """The feature table of the dataset at ``path`` (see module docstring); a DataFrame.

    ``noise_rms`` (m/s^2): white noise added to the stored signals first (add_noise), to
    study separability against SNR without simulating again. ``first_only``: impact windows
    of each ball's first impact only. The window settings are kept in ``table.attrs["windows"]``
    (written to features.parquet), so the raw windows can be cut again (window_table)."""
    import pandas as pd

    settings = dict(
        window=window, length=length, pre=pre, noise_rms=noise_rms, first_only=first_only
    )
    blocks = window_blocks(path, **settings)
    sensors, fs, cases = next(blocks)
    frames = [_features_frame(win, fs, sensors, meta) for win, meta in blocks]
    if not frames:
        raise _no_windows()
    table = _with_cases(pd.concat(frames, ignore_index=True), cases, window)
    table.attrs["windows"] = settings
    return table


def window_table(path, **settings):
    """(meta table, windows (rows, sensor, samples) in m/s^2, sensors, sample rate Hz): the
    raw windows feature_table computes its features of, with the same rows in the same order
    (``settings``: feature_table's keyword arguments, e.g. ``table.attrs["windows"]``)."""
    import pandas as pd

    blocks = window_blocks(path, **settings)
    sensors, fs, cases = next(blocks)
    wins, metas = [], []
    for win, meta in blocks:
        wins.append(win)
        metas.append(meta)
    if not metas:
        raise _no_windows()
    table = _with_cases(
        pd.concat(metas, ignore_index=True), cases, settings.get("window", "impact")
    )
    table.attrs["windows"] = dict(settings)
    return table, np.concatenate(wins), sensors, fs
