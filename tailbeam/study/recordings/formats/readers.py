"""Which reader opens which file, by its extension (case ignored)."""

from pathlib import Path

from tailbeam.errors import InputError
from tailbeam.study.recordings.formats.recording import Recording


def _wav(path):
    from tailbeam.study.recordings.formats.wav import open_wav

    return open_wav(path)


def _csv(path):
    from tailbeam.study.recordings.formats.csvfile import open_csv

    return open_csv(path)


def _uff(path):
    from tailbeam.study.recordings.formats.uff import open_uff

    return open_uff(path)


def _tdms(path):
    from tailbeam.study.recordings.formats.tdms import open_tdms

    return open_tdms(path)


def _mat(path):
    from tailbeam.study.recordings.formats.matfile import open_mat

    return open_mat(path)


def _hdf5(path):
    from tailbeam.study.recordings.formats.hdf5 import open_hdf5

    return open_hdf5(path)


READERS = {
    ".wav": _wav,
    ".csv": _csv,
    ".uff": _uff,
    ".unv": _uff,
    ".tdms": _tdms,
    ".mat": _mat,
    ".h5": _hdf5,
    ".hdf5": _hdf5,
    ".hdf": _hdf5,
}


def open_recording(path) -> Recording:
    """The file opened by the reader of its extension; InputError for an unknown one."""
    path = Path(path)
    opener = READERS.get(path.suffix.lower())
    if opener is None:
        known = ", ".join(sorted(READERS))
        raise InputError(str(path), f"unknown extension {path.suffix!r}; known: {known}")
    if not path.is_file():
        raise InputError(str(path), "no such file")
    try:
        return opener(path)
    except ModuleNotFoundError as err:
        raise InputError(
            "dependencies",
            f"{err.name} not installed; install it with pip install 'tailbeam[study]'",
        ) from None
