"""MATLAB files: v4 to v7 with scipy.io.loadmat (read whole), v7.3 (an HDF5 file) with h5py,
streamed. Variables become channels by the rule of tailbeam.study.recordings.formats.arrays."""

from pathlib import Path

import numpy as np

from tailbeam.errors import InputError
from tailbeam.study.recordings.formats.arrays import Variable, channels
from tailbeam.study.recordings.formats.recording import Recording

HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"


def _is_v73(path: Path) -> bool:
    with open(path, "rb") as fh:
        head = fh.read(512 + 8)
    return head[512:520] == HDF5_SIGNATURE or head[:8] == HDF5_SIGNATURE


def _variables_v5(path: Path) -> list:
    from scipy.io import loadmat

    try:
        content = loadmat(path, squeeze_me=False, mat_dtype=False)
    except Exception as err:  # scipy raises ValueError, TypeError, struct errors on bad files
        raise InputError(str(path), f"not a readable MAT file ({err})") from None
    out = []
    for name, value in content.items():
        if name.startswith("__") or not isinstance(value, np.ndarray):
            continue
        if value.dtype.kind == "U":
            out.append(Variable(name, text="".join(np.ravel(value).tolist()).strip()))
        elif value.dtype.kind in "iuf" and value.ndim <= 2:
            out.append(Variable(name, data=value))
    return out


def open_mat(path: Path) -> Recording:
    if _is_v73(path):
        from tailbeam.study.recordings.formats.hdf5 import open_hdf5

        rec = open_hdf5(path, matlab=True)
        rec.reader = "mat v7.3 (h5py)"
        return rec
    variables = _variables_v5(path)
    names, rate, units, n, read = channels(path, variables, [])
    return Recording(
        path=path,
        reader="mat v5 (scipy.io.loadmat)",
        channels=names,
        sample_rate=rate,
        units=units,
        n_samples=n,
        read=read,
    )
