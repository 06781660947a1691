"""Signal features of vibration windows, as used in the coal/gangue recognition literature.

Pure functions on arrays: ``x`` is (..., n) samples in m/s^2 along the last axis, every leading
axis is a batch (cases, sensors, windows); ``fs`` is the sample rate in Hz. Each feature
returns an array of the batch shape (band energies add one trailing axis).

- amplitude statistics: RMS, peak, crest factor, kurtosis (3 for a Gaussian), skewness;
- spectrum: spectral centroid (Hz), 1/3-octave band energies, Welch PSD summaries;
- wavelet-packet band energies (PyWavelets, orthogonal wavelet, periodization: the energies
  add up to the window's energy exactly);
- decay rate (1/s) of the envelope after the peak.
Energies are sum(x^2) / fs, in (m/s^2)^2 s.
"""

import numpy as np
from scipy import signal

THIRD_OCTAVE_BASE_HZ = 1000.0  # band centres f_k = 1000 * 2^(k/3) Hz (base-2, IEC 61260)
SCALAR_FEATURES = (
    "rms",
    "peak",
    "crest_factor",
    "kurtosis",
    "skewness",
    "spectral_centroid",
    "energy",
    "decay_rate",
    "psd_power",
    "psd_peak_hz",
    "psd_median_hz",
)
# the features that scale with the signal (a sensor's gain); every other one is scale-free:
# a window times g > 0 gives the same value
SCALE_FEATURES = ("rms", "peak", "energy", "psd_power")


def is_feature_name(name: str) -> bool:
    """True for the names all_features returns (scalar features, band_<fc>Hz, wp_<k>)."""
    return name in SCALAR_FEATURES or name.startswith(("band_", "wp_"))


def rms(x):
    """Root mean square, units of x."""
    return np.sqrt(np.mean(np.square(x), axis=-1))


def peak(x):
    """Largest absolute value, units of x."""
    return np.max(np.abs(x), axis=-1)


def crest_factor(x):
    """peak / RMS (1); sqrt(2) for a sine, 1 for a square wave."""
    return peak(x) / rms(x)


def _standard_moment(x, k: int):
    d = x - np.mean(x, axis=-1, keepdims=True)
    var = np.mean(d * d, axis=-1)
    return np.mean(d**k, axis=-1) / var ** (k / 2)


def kurtosis(x):
    """Fourth standardized moment (Pearson; 3 for a Gaussian, 1.5 for a sine)."""
    return _standard_moment(x, 4)


def skewness(x):
    """Third standardized moment (0 for a symmetric distribution, 2 for an exponential)."""
    return _standard_moment(x, 3)


def power_spectrum(x, fs: float):
    """freq (Hz) and one-sided energy per bin, (m/s^2)^2 s: sums to sum(x^2)/fs (Parseval)."""
    n = x.shape[-1]
    spec = np.abs(np.fft.rfft(x, axis=-1)) ** 2 / (n * fs)
    spec[..., 1:] *= 2.0
    if n % 2 == 0:
        spec[..., -1] *= 0.5
    return np.fft.rfftfreq(n, 1.0 / fs), spec


def spectral_centroid(x, fs: float):
    """Energy-weighted mean frequency of the spectrum, Hz."""
    freq, p = power_spectrum(x, fs)
    return np.sum(p * freq, axis=-1) / np.sum(p, axis=-1)


def third_octave_centres(fs: float, f_low: float = 20.0):
    """Centres (Hz) of the 1/3-octave bands from ``f_low`` whose upper edge is below fs/2."""
    k = np.arange(-40, 60)
    fc = THIRD_OCTAVE_BASE_HZ * 2.0 ** (k / 3)
    return fc[(fc >= f_low) & (fc * 2 ** (1 / 6) <= fs / 2)]


def band_energies(x, fs: float, centres):
    """Energy in the 1/3-octave bands of ``centres`` (Hz), (m/s^2)^2 s, shape (..., bands).
    Bins are assigned to the band whose edges fc 2^(-1/6), fc 2^(1/6) contain them."""
    freq, p = power_spectrum(x, fs)
    centres = np.asarray(centres, dtype=float)
    lo = centres * 2 ** (-1 / 6)
    hi = centres * 2 ** (1 / 6)
    member = (freq[None, :] >= lo[:, None]) & (freq[None, :] < hi[:, None])
    return p @ member.T.astype(float)


def wavelet_packet_energies(x, fs: float, level: int = 3, wavelet: str = "db4"):
    """Energies of the 2^level wavelet-packet nodes in frequency order, (m/s^2)^2 s,
    shape (..., 2^level). With an orthogonal wavelet and periodization they sum to
    sum(x^2)/fs."""
    import pywt

    wp = pywt.WaveletPacket(x, wavelet, mode="periodization", maxlevel=level, axis=-1)
    nodes = wp.get_level(level, order="freq")
    return np.stack([np.sum(np.square(nd.data), axis=-1) for nd in nodes], axis=-1) / fs


def welch_summary(x, fs: float, nperseg: int = 256):
    """Welch PSD summaries: dict of "psd_power" (integral, (m/s^2)^2), "psd_peak_hz" (Hz of
    the largest density), "psd_median_hz" (half the power below it, Hz)."""
    nper = min(nperseg, x.shape[-1])
    freq, pxx = signal.welch(x, fs=fs, nperseg=nper, axis=-1)
    df = freq[1] - freq[0]
    cum = np.cumsum(pxx, axis=-1) * df
    total = cum[..., -1]
    median_idx = np.argmax(cum >= 0.5 * total[..., None], axis=-1)
    return {
        "psd_power": total,
        "psd_peak_hz": freq[np.argmax(pxx, axis=-1)],
        "psd_median_hz": freq[median_idx],
    }


def decay_rate(x, fs: float, frame: int = 32):
    """Exponential decay rate sigma (1/s) of x ~ exp(-sigma t) after its peak: a least-squares
    line through log(frame RMS) of the frames from the loudest one on (frames of ``frame``
    samples; frames below 1e-6 of the loudest are left out as noise floor)."""
    n = (x.shape[-1] // frame) * frame
    frames = x[..., :n].reshape(*x.shape[:-1], n // frame, frame)
    level = np.sqrt(np.mean(frames**2, axis=-1))  # (..., m)
    m = level.shape[-1]
    t = (np.arange(m) + 0.5) * frame / fs
    start = np.argmax(level, axis=-1)[..., None]
    top = np.max(level, axis=-1, keepdims=True)
    use = (np.arange(m) >= start) & (level > 1e-6 * top)
    logl = np.log(np.where(use, level, 1.0))
    w = use.astype(float)
    cnt = np.sum(w, axis=-1)
    tm = np.sum(w * t, axis=-1) / cnt
    lm = np.sum(w * logl, axis=-1) / cnt
    cov = np.sum(w * (t - tm[..., None]) * (logl - lm[..., None]), axis=-1)
    var = np.sum(w * (t - tm[..., None]) ** 2, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(cnt >= 2, -cov / var, np.nan)


def all_features(x, fs: float, *, wp_level: int = 3) -> dict:
    """Every feature of windows ``x`` (..., n): name -> array of the batch shape. Band
    energies are given as fractions of the window's energy (``band_<fc>Hz``, ``wp_<k>``)."""
    energy = np.sum(np.square(x), axis=-1) / fs
    out = {
        "rms": rms(x),
        "peak": peak(x),
        "crest_factor": crest_factor(x),
        "kurtosis": kurtosis(x),
        "skewness": skewness(x),
        "spectral_centroid": spectral_centroid(x, fs),
        "energy": energy,
        "decay_rate": decay_rate(x, fs),
        **welch_summary(x, fs),
    }
    # bands narrower than ~4 frequency bins of the window are left out (always near empty)
    centres = third_octave_centres(fs, f_low=max(20.0, 4.0 * fs / x.shape[-1] / 0.23))
    bands = band_energies(x, fs, centres)
    for i, fc in enumerate(centres):
        out[f"band_{fc:.0f}Hz"] = bands[..., i] / energy
    wp = wavelet_packet_energies(x, fs, level=wp_level)
    for k in range(wp.shape[-1]):
        out[f"wp_{k}"] = wp[..., k] / energy
    return out
