"""Measurement noise of an accelerometer chain (scene key ``[[sensors]] noise``), in m/s^2.

Two independent zero-mean Gaussian parts, added to the sampled sensor output:
- white noise of RMS ``rms`` (the sensor's and the DAQ's broadband electronic noise floor);
- an optional background of RMS ``background`` confined to the band ``band`` = (f_lo, f_hi) Hz
  (machinery vibration reaching the tail beam: shearer, conveyor, hydraulics). It is white
  Gaussian noise with its spectrum set to zero outside the band; the expected mean square is
  ``background**2`` exactly (the record's own RMS scatters around it like any sample RMS).

Both are drawn from ``numpy.random.default_rng((seed, crc32(sensor name)))``: the same seed and
sensor give the same noise on every machine; two sensors of one scene get independent noise.
"""

import math
import zlib
from dataclasses import dataclass

import numpy as np

from tailbeam.errors import InputError, require_nonnegative, require_vector

DEFAULT_BAND_HZ = (10.0, 1000.0)  # background band when only its level is given


@dataclass(frozen=True)
class NoiseSpec:
    """White RMS (m/s^2), background RMS (m/s^2) in ``band_hz`` (f_lo, f_hi), integer seed."""

    rms: float = 0.0
    background: float = 0.0
    band_hz: tuple[float, float] = DEFAULT_BAND_HZ
    seed: int = 0

    def __post_init__(self):
        object.__setattr__(self, "rms", require_nonnegative("noise.rms", self.rms))
        object.__setattr__(
            self, "background", require_nonnegative("noise.background", self.background)
        )
        lo, hi = require_vector("noise.band", self.band_hz, 2)
        if not 0.0 <= lo < hi:
            raise InputError(
                "noise.band", f"must be [f_lo, f_hi] with 0 <= f_lo < f_hi, got {[lo, hi]}"
            )
        object.__setattr__(self, "band_hz", (lo, hi))
        if isinstance(self.seed, bool) or not isinstance(self.seed, int) or self.seed < 0:
            raise InputError("noise.seed", f"must be a whole number >= 0, got {self.seed!r}")


def rng_for(seed: int, sensor_name: str) -> np.random.Generator:
    """The generator of one sensor's noise: independent per sensor name, fixed by ``seed``."""
    return np.random.default_rng((int(seed), zlib.crc32(sensor_name.encode())))


def band_limited_noise(rng, n: int, sample_rate: float, band_hz, level: float) -> np.ndarray:
    """``n`` samples of Gaussian noise whose spectrum is flat in ``band_hz`` (Hz) and zero
    outside, with expected mean square ``level**2`` ((m/s^2)^2)."""
    freq = np.fft.rfftfreq(n, 1.0 / sample_rate)
    inside = (freq >= band_hz[0]) & (freq <= band_hz[1])
    # weight of each rfft bin in the mean square: 2 for interior bins, 1 for DC and Nyquist
    weight = np.full(freq.shape, 2.0)
    weight[0] = 1.0
    if n % 2 == 0:
        weight[-1] = 1.0
    power = float(np.sum(weight[inside]))
    if level == 0.0 or power == 0.0:
        return np.zeros(n)
    spec = rng.standard_normal(freq.shape) + 1j * rng.standard_normal(freq.shape)
    spec[0] = spec[0].real * math.sqrt(2.0)
    if n % 2 == 0:
        spec[-1] = spec[-1].real * math.sqrt(2.0)
    spec[~inside] = 0.0
    # E|spec_k|^2 = 2; x = irfft(spec) has mean square sum_k w_k |spec_k|^2 / n^2
    scale = level * n / math.sqrt(2.0 * power)
    return np.fft.irfft(spec * scale, n)


def noise(spec: NoiseSpec, sensor_name: str, n: int, sample_rate: float) -> np.ndarray:
    """The noise record (m/s^2) of sensor ``sensor_name``: ``n`` samples at ``sample_rate`` Hz."""
    rng = rng_for(spec.seed, sensor_name)
    out = spec.rms * rng.standard_normal(n)
    if spec.background > 0.0:
        out += band_limited_noise(rng, n, sample_rate, spec.band_hz, spec.background)
    return out
