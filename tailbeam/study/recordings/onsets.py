"""Impact onsets in a record: where the envelope rises above a multiple of a robust noise
floor, at most one onset per dead time.

The envelope of each channel is the square root of its squared signal smoothed by a one-pole
low-pass of time constant ``smooth`` (s): an RMS envelope with no look-ahead, computed frame
by frame with the filter's state carried over. The noise floor of a channel is the median of
its envelope over each frame of ``floor_window`` s: robust while impacts fill less than half
of a frame, and following slow changes of the background. An onset is a sample where the
largest of the channels' envelope-to-floor ratios first exceeds ``threshold``, at least
``dead_time`` s after the previous onset. The envelope lags the signal by about ``smooth``,
so a window around an onset should start some time before it.
"""

from dataclasses import dataclass

import numpy as np

from tailbeam.errors import InputError

TINY_FLOOR = 1e-12  # m/s^2: the floor of a channel that is exactly zero


@dataclass(frozen=True)
class OnsetOptions:
    """Parameters of the detector (see module docstring); times in s."""

    threshold: float = 8.0
    dead_time: float = 0.05
    smooth: float = 0.0005
    floor_window: float = 1.0

    def check(self, fs: float) -> None:
        if not self.threshold > 1:
            raise InputError("--threshold", f"must be > 1, got {self.threshold}")
        for name, value in (("--dead-time", self.dead_time), ("--smooth", self.smooth)):
            if not value > 0:
                raise InputError(name, f"must be > 0 s, got {value}")
        if not self.floor_window * fs >= 100:
            raise InputError("--floor-window", f"must span >= 100 samples, {100 / fs:g} s")


class OnsetDetector:
    """Feed consecutive frames of ``floor_window`` s (the last may be shorter) to ``frame``;
    it returns the onsets found, as global sample indices."""

    def __init__(self, fs: float, n_channels: int, options: OnsetOptions):
        self.options = options
        self.alpha = float(np.exp(-1.0 / (options.smooth * fs)))
        self.zi = np.zeros((n_channels, 1))
        self.dead = int(round(options.dead_time * fs))
        self.frame_len = int(round(options.floor_window * fs))
        self.last = None  # the last onset (global index)
        self.above = False  # whether the last sample of the previous frame was above
        self.floor = None

    def envelope(self, x: np.ndarray) -> np.ndarray:
        from scipy.signal import lfilter

        a = self.alpha
        smoothed, self.zi = lfilter([1.0 - a], [1.0, -a], x * x, axis=1, zi=self.zi)
        return np.sqrt(np.maximum(smoothed, 0.0))

    def frame(self, x: np.ndarray, start: int) -> list:
        env = self.envelope(x)
        if self.floor is None or x.shape[1] >= self.frame_len // 2:
            self.floor = np.maximum(np.median(env, axis=1), TINY_FLOOR)
        above = (env / self.floor[:, None]).max(axis=0) > self.options.threshold
        rising = above & ~np.concatenate([[self.above], above[:-1]])
        self.above = bool(above[-1]) if above.size else self.above
        onsets = []
        for i in np.flatnonzero(rising):
            if self.last is None or start + i - self.last >= self.dead:
                self.last = start + int(i)
                onsets.append(self.last)
        return onsets
