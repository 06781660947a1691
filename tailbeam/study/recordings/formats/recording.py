"""What a reader gives: a recording's channels, its rate and units as the file says them, and
its samples block by block."""

from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tailbeam.errors import InputError

BLOCK_SAMPLES = 1 << 18  # samples per channel read at a time


@dataclass
class Recording:
    """One opened recording.

    Attributes
    ----------
    path : Path
        The file.
    reader : str
        The reader used, e.g. ``"wav (scipy.io.wavfile)"``.
    channels : list of str
        Channel names as the file gives them (the format's rule, see docs/recordings.md).
    sample_rate : float or None
        Samples per second the file states (Hz); None when it does not say.
    units : list of (str or None)
        Each channel's unit as the file states it; None when it does not say.
    n_samples : int
        Samples per channel.
    read : callable
        ``read(start, stop)`` -> float64 array (channels, stop - start) in the file's units.
    full_scale : bool
        True for integer WAV data: the values are fractions of digital full scale, and the
        labels file must say the unit (and optionally the value of full scale).
    details : dict
        What the reader found, for the provenance (e.g. the WAV sample format).
    close : callable
        Releases the file.
    stream : callable, optional
        ``stream(size)`` -> the blocks, for a reader that reads sequentially faster.
    """

    path: Path
    reader: str
    channels: list
    sample_rate: float | None
    units: list
    n_samples: int
    read: Callable[[int, int], np.ndarray]
    full_scale: bool = False
    details: dict = field(default_factory=dict)
    close: Callable[[], None] = lambda: None
    stream: Callable[[int], Iterator[np.ndarray]] | None = None  # a reader's own blocks()

    def blocks(self, size: int = BLOCK_SAMPLES) -> Iterator[np.ndarray]:
        """The samples as consecutive (channels, <= size) float64 blocks, file units."""
        if self.stream is not None:
            yield from self.stream(size)
            return
        for lo in range(0, self.n_samples, size):
            block = np.asarray(self.read(lo, min(lo + size, self.n_samples)), dtype=float)
            if not np.all(np.isfinite(block)):
                bad = int(np.argwhere(~np.isfinite(block))[0, 1]) + lo
                raise InputError(str(self.path), f"sample {bad} is not a finite number")
            yield block


def rate_from_times(times, field: str) -> float:
    """Sample rate (Hz) of a uniformly spaced time vector (s), or InputError naming ``field``."""
    t = np.asarray(times, dtype=float).ravel()
    if t.size < 2:
        raise InputError(field, "needs at least two time values to give a sample rate")
    dt = (t[-1] - t[0]) / (t.size - 1)
    grid = t[0] + dt * np.arange(t.size)
    if not dt > 0 or np.max(np.abs(t - grid)) > 0.1 * dt:  # rounding in a text file passes
        raise InputError(field, "time values must be evenly spaced and increasing")
    return 1.0 / dt


def check_channels(path, channels: list, lengths: list) -> None:
    """Refuse a file without channels, with repeated names or with channels of unequal length."""
    if not channels:
        raise InputError(str(path), "no signal channel found (see docs/recordings.md#formats)")
    if len(set(channels)) != len(channels):
        raise InputError(str(path), f"channel names repeat: {channels}")
    if len(set(lengths)) > 1:
        raise InputError(
            str(path), f"channels differ in length: {dict(zip(channels, lengths, strict=True))}"
        )
