"""Block-wise rational resampling, equal to one scipy.signal.resample_poly call on the whole
record.

The rate ratio is a fraction up/down (``ratio``). resample_poly filters with a linear-phase
FIR low-pass (Kaiser window, beta 5, cut-off at the lower Nyquist frequency, 20 max(up, down)
+ 1 taps) and keeps every ``down``-th sample of the ``up``-times upsampled record. Each output
sample depends only on the input within half the filter's length of it, so a block of input
that starts on a multiple of ``down``, given ``context`` samples on each side, yields exactly
the output samples of its own span; the record's two ends are zero-padded, as resample_poly
does with the whole record.
"""

import math
from fractions import Fraction

import numpy as np

from tailbeam.errors import InputError

MAX_TERMS = 1000  # largest up or down of the ratio


def ratio(source_hz: float, target_hz: float, field: str) -> tuple:
    """(up, down): the fraction nearest target/source with terms <= MAX_TERMS, and the rate
    it gives (Hz)."""
    frac = Fraction(target_hz / source_hz).limit_denominator(MAX_TERMS)
    while frac.numerator > MAX_TERMS:  # a large upsampling ratio: coarser
        frac = Fraction(target_hz / source_hz).limit_denominator(frac.denominator // 2)
    if frac <= 0:
        raise InputError(field, f"cannot resample {source_hz:g} Hz to {target_hz:g} Hz")
    return frac.numerator, frac.denominator


class Resampler:
    """Feed blocks (channels, k) with ``push``; each call returns the output samples now
    complete; ``finish`` returns the rest. ``up == down == 1`` passes blocks through."""

    def __init__(self, up: int, down: int):
        from scipy.signal import firwin

        g = math.gcd(up, down)
        self.up, self.down = up // g, down // g
        half_len = 10 * max(self.up, self.down)
        if self.up != self.down:
            cutoff = 1.0 / max(self.up, self.down)
            self.taps = firwin(2 * half_len + 1, cutoff, window=("kaiser", 5.0))
        need = half_len / self.up + 2  # input samples on each side an output sample depends on
        self.context = self.down * math.ceil(need / self.down)
        self.buf = None  # input not yet consumed, from global index self.start - self.left
        self.start = 0  # global input index of the next output block's first sample
        self.left = 0  # input samples before self.start kept in buf

    def _run(self, x: np.ndarray) -> np.ndarray:
        from scipy.signal import resample_poly

        return resample_poly(x, self.up, self.down, axis=1, window=self.taps)

    def push(self, block: np.ndarray) -> np.ndarray:
        self.n_channels = block.shape[0]
        if self.up == self.down:
            return block
        self.buf = block if self.buf is None else np.concatenate([self.buf, block], axis=1)
        ready = self.buf.shape[1] - self.left - self.context  # inputs with full right context
        n = (ready // self.down) * self.down
        if n <= 0:
            return self.buf[:, :0]
        y = self._run(self.buf[:, : self.left + n + self.context])
        j0 = self.left * self.up // self.down
        out = y[:, j0 : j0 + n * self.up // self.down]
        keep = min(self.context, self.left + n)  # left context of the next block
        self.buf = self.buf[:, self.left + n - keep :]
        self.start += n
        self.left = keep
        return out

    def finish(self) -> np.ndarray:
        if self.up == self.down or self.buf is None or self.buf.shape[1] <= self.left:
            return np.zeros((getattr(self, "n_channels", 0), 0))
        y = self._run(self.buf)
        return y[:, self.left * self.up // self.down :]
