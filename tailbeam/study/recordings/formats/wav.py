"""WAV files (scipy.io.wavfile parses the header; the samples are then read block by block
from the data chunk with plain reads, not memory-mapped, so memory stays bounded). The rate
is in the header, channels are named ``ch1``, ``ch2``, ... in file order, and the unit always
comes from the labels file (WAV has no field for it). Integer samples are divided by their
digital full scale (2^15 for 16-bit, 2^31 for 32-bit, 128 around 128 for 8-bit), so they
read as fractions of full scale."""

import warnings
from pathlib import Path

import numpy as np

from tailbeam.errors import InputError
from tailbeam.study.recordings.formats.recording import Recording

FULL_SCALE = {"int16": 2.0**15, "int32": 2.0**31, "uint8": 128.0}


def open_wav(path: Path) -> Recording:
    from scipy.io import wavfile

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # a short data chunk warns; it is a truncated file
            rate, data = wavfile.read(path, mmap=True)
    except (ValueError, Warning) as err:
        raise InputError(str(path), f"not a complete WAV file ({err})") from None
    frames, width = len(data), (data.shape[1] if data.ndim == 2 else 1)
    dtype, offset_bytes = data.dtype, int(data.offset)
    del data  # the memory map: blocks are read with plain reads below
    kind = dtype.name
    if kind not in FULL_SCALE and dtype.kind != "f":
        raise InputError(str(path), f"WAV sample format {kind} is not supported")
    scale = FULL_SCALE.get(kind, 1.0)
    offset = 128.0 if kind == "uint8" else 0.0

    def read(start: int, stop: int) -> np.ndarray:
        with open(path, "rb") as fh:
            fh.seek(offset_bytes + start * width * dtype.itemsize)
            raw = np.fromfile(fh, dtype=dtype, count=(stop - start) * width)
        return (raw.reshape(stop - start, width).T.astype(float) - offset) / scale

    return Recording(
        path=path,
        reader="wav (scipy.io.wavfile)",
        channels=[f"ch{i + 1}" for i in range(width)],
        sample_rate=float(rate),
        units=[None] * width,
        n_samples=frames,
        read=read,
        full_scale=dtype.kind != "f",
        details={"sample_format": kind},
    )
