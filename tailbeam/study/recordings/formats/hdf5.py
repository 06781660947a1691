"""HDF5 files (h5py, streamed). Datasets become channels by the rule of
tailbeam.study.recordings.formats.arrays; attributes of a dataset, the groups above it and the file
give its rate and unit. A MATLAB v7.3 file is read the same way (its text variables are
MATLAB ``char`` arrays; the ``#refs#`` group is skipped)."""

from pathlib import Path

import numpy as np

from tailbeam.errors import InputError
from tailbeam.study.recordings.formats.arrays import Variable, channels
from tailbeam.study.recordings.formats.recording import Recording


def _attrs(obj) -> dict:
    return {str(k): v for k, v in obj.attrs.items() if not str(k).startswith("MATLAB_")}


def _scopes(h5, name: str) -> list:
    """Attributes of the dataset ``name`` and of each group above it, nearest first."""
    parts = name.split("/")
    return [_attrs(h5["/".join(parts[:k]) or "/"]) for k in range(len(parts), -1, -1)]


def _matlab_text(ds) -> str | None:
    cls = ds.attrs.get("MATLAB_class")
    if cls is not None and (cls.decode() if isinstance(cls, bytes) else str(cls)) == "char":
        return "".join(chr(c) for c in np.ravel(ds[()]))
    return None


def _variables(h5) -> list:
    import h5py

    out = []

    def visit(name, obj):
        if name.startswith("#") or not isinstance(obj, h5py.Dataset):
            return
        text = _matlab_text(obj)
        if text is not None:
            out.append(Variable(name, text=text.strip()))
        elif obj.dtype.kind in "SOU":
            value = obj[()]
            value = value.decode() if isinstance(value, bytes) else str(value)
            out.append(Variable(name, text=value.strip()))
        elif obj.dtype.kind in "iuf" and obj.ndim <= 2:
            out.append(Variable(name, data=obj, attrs=_scopes(h5, name)))

    h5.visititems(visit)
    return out


def open_hdf5(path: Path, matlab: bool = False) -> Recording:
    import h5py

    try:
        h5 = h5py.File(path, "r")
        variables = _variables(h5)
    except OSError as err:
        raise InputError(str(path), f"not a readable HDF5 file ({err})") from None
    names, rate, units, n, read = channels(path, variables, [_attrs(h5)])
    return Recording(
        path=path,
        reader="hdf5 (h5py)",
        channels=names,
        sample_rate=rate,
        units=units,
        n_samples=n,
        read=read,
        close=h5.close,
    )
