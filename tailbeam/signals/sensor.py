"""An accelerometer chain on the plate: what a real sensor + DAQ would record (m/s^2).

The chain, per ``SensorSpec``:
1. the true plate acceleration normal to the plate at the sensor point, evaluated exactly (modal
   closed form) on a fine grid, ``oversample`` times the output rate (>= 2.5 x the top mode);
2. the mounted accelerometer: a lightly damped 2nd-order resonance (seismic mass on the crystal
   and the mount), H(s) = wr^2 / (s^2 + 2 zr wr s + wr^2), applied exactly in the frequency
   domain (no bilinear warping of the resonance or the band);
3. the DAQ's anti-alias filter: a linear-phase FIR low-pass whose passband ends at the
   bandwidth and whose stopband starts at fs - bandwidth, so everything that folds back below
   the bandwidth is attenuated >= 90 dB (the delta-sigma DAQ design, "alias-free bandwidth");
   its group delay is compensated, as DAQ software does;
4. sampling at ``sample_rate`` (decimation of the fine grid);
5. measurement noise, if the spec has any (``tailbeam.signals.noise``), added to the samples.

Defaults (docs/coupled-and-sensors.md, "Sensor chain"): sample rate 51.2 kHz; bandwidth
fs/2.56 = 20 kHz, the classic
FFT-analyser ratio (commercial DAQs quote 0.39-0.45 fs alias-free); mounted resonance 3 x the
bandwidth (+12.5 % at the band edge, the usual "+/- 1 dB to 1/3 of the mounted resonance"
rule) with damping ratio 0.03 (Q ~ 17, typical of stud-mounted piezoelectric sensors).
"""

import math
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from tailbeam.errors import InputError, require_positive, require_vector
from tailbeam.signals.noise import NoiseSpec, noise

BANDWIDTH_FRACTION = 1.0 / 2.56  # of the sample rate
RESONANCE_FACTOR = 3.0  # mounted resonance / bandwidth
RESONANCE_DAMPING = 0.03
STOPBAND_DB = 90.0


AXES = "xyz"  # the letters of ``axes``, one per axis of the plate frame


@dataclass(frozen=True)
class SensorSpec:
    """An accelerometer on the plate or structure, measuring acceleration (m/s^2).

    position: (x, y) m, a point of the impact face; or (x, y, z) m, a point of the surface
    (plate frame: the impact face is z = 0, the structure lies below it). direction: (dx, dy,
    dz) the measuring axis (normalised here; None: the impact face's normal +z); axes: a
    subset of "xyz" in any order, one signal per axis (``channels``), or None. sample_rate in
    Hz; bandwidth_hz: upper edge of the usable band (None: chosen from the sample rate);
    mounted_resonance_hz (None: chosen from the bandwidth).
    """

    name: str
    position: tuple
    sample_rate: float = 51200.0
    bandwidth_hz: float | None = None
    mounted_resonance_hz: float | None = None
    noise: NoiseSpec | None = None  # measurement noise added to the output (tailbeam.signals.noise)
    direction: tuple | None = None
    axes: str | None = None

    def __post_init__(self):
        field_ = f"sensors[{self.name}]"
        object.__setattr__(self, "position", _position(f"{field_}.position", self.position))
        object.__setattr__(
            self, "sample_rate", require_positive(f"{field_}.sample_rate", self.sample_rate)
        )
        if self.bandwidth_hz is not None:
            bw = require_positive(f"{field_}.bandwidth", self.bandwidth_hz)
            if bw >= 0.5 * self.sample_rate:
                raise InputError(
                    f"{field_}.bandwidth",
                    f"must be below Nyquist, {0.5 * self.sample_rate:g} Hz, got {bw:g}",
                )
            object.__setattr__(self, "bandwidth_hz", bw)
        if self.mounted_resonance_hz is not None:
            object.__setattr__(
                self,
                "mounted_resonance_hz",
                require_positive(f"{field_}.mounted_resonance", self.mounted_resonance_hz),
            )
        self._check_direction(field_)

    def _check_direction(self, field_: str) -> None:
        if self.direction is not None and self.axes is not None:
            raise InputError(f"{field_}.axes", "give direction or axes, not both")
        if self.direction is not None:
            d = np.array(require_vector(f"{field_}.direction", self.direction, 3))
            norm = float(np.linalg.norm(d))
            if not norm > 0.0:
                raise InputError(f"{field_}.direction", "must be a nonzero (dx, dy, dz) vector")
            object.__setattr__(self, "direction", tuple(float(v) for v in d / norm))
        if self.axes is not None:
            axes = self.axes
            if (
                not isinstance(axes, str)
                or not axes
                or any(a not in AXES for a in axes)
                or len(set(axes)) != len(axes)
            ):
                raise InputError(
                    f"{field_}.axes",
                    f"must be distinct letters of {AXES!r} (e.g. 'xyz', 'z'), got {axes!r}",
                )

    @property
    def plain(self) -> bool:
        """True for a point (x, y) of the impact face read along +z (no direction, no axes)."""
        return len(self.position) == 2 and self.direction is None and self.axes is None

    def channels(self) -> tuple:
        """One single-direction SensorSpec per output signal: itself, or with ``axes`` one per
        letter named ``<name>_<letter>`` along that axis (its noise drawn for that name)."""
        if self.axes is None:
            return (self,)
        unit = {a: tuple(float(a == b) for b in AXES) for a in AXES}
        return tuple(
            replace(self, name=f"{self.name}_{a}", direction=unit[a], axes=None) for a in self.axes
        )


def _position(field: str, value) -> tuple:
    """(x, y) or (x, y, z) m, finite."""
    try:
        n = len(value)
    except TypeError:
        n = 0
    return require_vector(field, value, 3 if n == 3 else 2)


def channel_names(sensors) -> list:
    """The output signal names of ``sensors`` (``SensorSpec.channels``), in order."""
    return [c.name for s in sensors for c in s.channels()]


@dataclass(frozen=True)
class SensorChain:
    """Resolved chain parameters: Hz, the fine-grid oversampling factor (integer)."""

    sample_rate: float
    bandwidth_hz: float
    mounted_resonance_hz: float
    resonance_damping: float
    oversample: int

    @property
    def fine_rate(self) -> float:
        return self.sample_rate * self.oversample


def resolve(spec: SensorSpec, max_frequency_hz: float = 0.0) -> SensorChain:
    """Fill in the defaults of ``spec``. The fine grid (an integer multiple >= 2 of the sample
    rate) resolves every mode: fine rate >= 2.5 x max_frequency_hz (the highest mode), so the
    true acceleration is sampled without aliasing; its Nyquist frequency (>= fs) lies above the
    FIR's stopband edge fs - bandwidth. The resonance acts on that content exactly (FFT)."""
    fs = spec.sample_rate
    bw = spec.bandwidth_hz if spec.bandwidth_hz is not None else BANDWIDTH_FRACTION * fs
    fr = spec.mounted_resonance_hz
    if fr is None:
        fr = RESONANCE_FACTOR * bw
    if fr <= bw:
        raise InputError(
            f"sensors[{spec.name}].mounted_resonance",
            f"must lie above the bandwidth {bw:g} Hz, got {fr:g}",
        )
    oversample = max(2, int(math.ceil(2.5 * max_frequency_hz / fs)))
    return SensorChain(fs, bw, fr, RESONANCE_DAMPING, oversample)


@dataclass(frozen=True)
class SensorOutput:
    """Sampled signal t (s), acceleration (m/s^2); one-sided amplitude spectrum freq (Hz),
    amplitude (m/s^2, peak); the chain that produced it."""

    name: str
    t: np.ndarray
    acceleration: np.ndarray
    freq: np.ndarray
    amplitude: np.ndarray
    chain: SensorChain


def mounted_resonance(chain: SensorChain, freq_hz) -> np.ndarray:
    """Complex response of the mounted accelerometer, wr^2 / (wr^2 - w^2 + 2 i zr wr w)."""
    w = 2 * np.pi * np.asarray(freq_hz, dtype=float)
    wr = 2 * math.pi * chain.mounted_resonance_hz
    return wr**2 / (wr**2 - w**2 + 2j * chain.resonance_damping * wr * w)


def _apply_resonance(chain: SensorChain, a_fine: np.ndarray) -> np.ndarray:
    """The resonance applied exactly in the frequency domain. The record starts from rest and is
    zero-padded by 20 decay times 1/(zr wr), so the circular convolution is the linear one."""
    from scipy import fft as sp_fft  # (scipy.signal: loaded only when a sensor is measured)

    wr = 2 * math.pi * chain.mounted_resonance_hz
    pad = int(math.ceil(20.0 / (chain.resonance_damping * wr) * chain.fine_rate))
    n_fft = sp_fft.next_fast_len(len(a_fine) + pad, real=True)
    spec = np.fft.rfft(a_fine, n_fft)
    spec *= mounted_resonance(chain, np.fft.rfftfreq(n_fft, 1.0 / chain.fine_rate))
    return np.fft.irfft(spec, n_fft)[: len(a_fine)]


def anti_alias_fir(chain: SensorChain) -> np.ndarray:
    """Linear-phase FIR taps on the fine grid; length 2 m oversample + 1 (delay m samples)."""
    from scipy import signal  # (scipy.signal: loaded only when a sensor is measured)

    fine = chain.fine_rate
    f_pass = chain.bandwidth_hz
    f_stop = chain.sample_rate - chain.bandwidth_hz
    if f_stop <= f_pass:
        raise InputError("sensors.bandwidth", "must be below half the sample rate")
    numtaps, beta = signal.kaiserord(STOPBAND_DB, (f_stop - f_pass) / (0.5 * fine))
    m = int(math.ceil((numtaps - 1) / (2 * chain.oversample)))
    numtaps = 2 * m * chain.oversample + 1
    return signal.firwin(numtaps, 0.5 * (f_pass + f_stop), window=("kaiser", beta), fs=fine)


def amplitude_spectrum(x, sample_rate: float, *, window: str = "boxcar"):
    """One-sided amplitude spectrum (peak amplitude per frequency): freq (Hz), |X| (units of x).

    A sinusoid of amplitude A on a bin shows as A. The default rectangular window suits impact
    transients recorded whole; a window (e.g. "hann") is corrected for its coherent gain.
    """
    from scipy import signal  # (scipy.signal: loaded only when a sensor is measured)

    x = np.asarray(x, dtype=float)
    n = len(x)
    if n < 2:
        raise InputError("signal", "need at least two samples for a spectrum")
    w = signal.get_window(window, n, fftbins=True)
    spec = np.abs(np.fft.rfft(x * w)) / np.sum(w)
    spec[1:] *= 2.0
    if n % 2 == 0:
        spec[-1] *= 0.5
    return np.fft.rfftfreq(n, 1.0 / sample_rate), spec


def measure(
    spec: SensorSpec,
    true_acceleration: Callable[[np.ndarray], np.ndarray],
    duration: float,
    *,
    max_frequency_hz: float = 0.0,
) -> SensorOutput:
    """Run the chain on the true plate acceleration (a function of time in s) over
    [0, duration] s; the plate is at rest before t = 0."""
    from scipy import signal  # (scipy.signal: loaded only when a sensor is measured)

    chain = resolve(spec, max_frequency_hz)
    taps = anti_alias_fir(chain)
    delay = (len(taps) - 1) // 2  # fine samples, a multiple of oversample
    n_out = int(math.floor(duration * chain.sample_rate + 1e-9)) + 1
    n_fine = (n_out - 1) * chain.oversample + 1 + delay
    t_fine = np.arange(n_fine) / chain.fine_rate
    a_true = np.asarray(true_acceleration(t_fine), dtype=float)
    y = _apply_resonance(chain, a_true)
    y = signal.lfilter(taps, [1.0], y)[delay :: chain.oversample][:n_out]
    if spec.noise is not None:
        y = y + noise(spec.noise, spec.name, n_out, chain.sample_rate)
    t = np.arange(n_out) / chain.sample_rate
    freq, amp = amplitude_spectrum(y, chain.sample_rate)
    return SensorOutput(spec.name, t, y, freq, amp, chain)


def chain_response(chain: SensorChain, freq_hz) -> np.ndarray:
    """Complex response of the sensor chain (resonance x anti-alias FIR, delay removed)."""
    from scipy import signal  # (scipy.signal: loaded only when a sensor is measured)

    f = np.asarray(freq_hz, dtype=float)
    h_res = mounted_resonance(chain, f)
    taps = anti_alias_fir(chain)
    _, h_fir = signal.freqz(taps, worN=f, fs=chain.fine_rate)
    delay = (len(taps) - 1) / 2 / chain.fine_rate
    return h_res * h_fir * np.exp(2j * np.pi * f * delay)
