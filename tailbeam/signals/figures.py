"""Figures of an accelerometer's record: time history, amplitude spectrum, Welch PSD and
spectrogram, with the sensor's position, the frequency resolutions and peak/RMS written on them.

Drawing only (matplotlib's object-oriented API, Agg); the chain itself is tailbeam.signals.sensor.
The Welch PSD and the spectrogram (scipy.signal) make records with several impacts readable:
the whole-record amplitude spectrum of a multi-impact record is a comb of interference
fringes, while averaged segments (Welch) show the band levels and the spectrogram shows when
each mode rings.
"""

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from scipy import signal

WELCH_SEGMENTS = 4  # target number of non-overlapping segment lengths in the record
SPECTROGRAM_SEGMENTS = 48  # target number of segment lengths for the spectrogram
MIN_SEGMENT = 32  # samples
MAX_WELCH_SEGMENT = 8192
MAX_SPECTROGRAM_SEGMENT = 1024
DB_RANGE = 80.0  # dB shown below the spectrogram's maximum


@dataclass(frozen=True)
class SensorStats:
    """Numbers written on a sensor figure: peak |a| (m/s^2), the signed value there and its
    time (s), RMS over the record (m/s^2), time span t[-1] - t[0] (s), sample count N, the
    resolution fs / N (Hz) of the whole-record spectrum and the segment lengths (samples) of
    the Welch PSD and the spectrogram (resolution fs / segment)."""

    peak: float
    peak_value: float
    t_peak: float
    rms: float
    duration: float
    n_samples: int
    df_spectrum: float
    welch_segment: int
    spectrogram_segment: int


def _segment(n: int, parts: int, largest: int) -> int:
    """Power of two near n / parts within [MIN_SEGMENT, largest], never above n."""
    target = max(n / parts, 1.0)
    seg = 2 ** int(round(np.log2(target)))
    return int(min(max(seg, MIN_SEGMENT), largest, n))


def sensor_stats(output) -> SensorStats:
    """Peak, RMS and resolutions of a tailbeam.signals.sensor.SensorOutput's sampled record."""
    a = np.asarray(output.acceleration, dtype=float)
    n = a.size
    k = int(np.argmax(np.abs(a)))
    fs = output.chain.sample_rate
    return SensorStats(
        peak=float(abs(a[k])),
        peak_value=float(a[k]),
        t_peak=float(output.t[k]),
        rms=float(np.sqrt(np.mean(a**2))),
        duration=float(output.t[-1] - output.t[0]),
        n_samples=n,
        df_spectrum=fs / n,
        welch_segment=_segment(n, WELCH_SEGMENTS, MAX_WELCH_SEGMENT),
        spectrogram_segment=_segment(n, SPECTROGRAM_SEGMENTS, MAX_SPECTROGRAM_SEGMENT),
    )


def welch_psd(output, segment: int):
    """One-sided Welch PSD of the record: freq (Hz), PSD ((m/s^2)^2/Hz); Hann, 50 % overlap."""
    return signal.welch(
        output.acceleration, fs=output.chain.sample_rate, window="hann", nperseg=segment
    )


def time_unit(duration: float) -> tuple:
    """(scale, name) for time axes: ms for records shorter than 2 s, else s."""
    return (1e3, "ms") if duration < 2.0 else (1.0, "s")


def _time_panel(ax, output, stats):
    scale, unit = time_unit(stats.duration)
    ax.plot(output.t * scale, output.acceleration, lw=0.6, color="C0")
    for level in (stats.rms, -stats.rms):
        ax.axhline(level, color="C3", lw=0.8, ls="--")
    marker = "v" if stats.peak_value > 0 else "^"
    ax.plot(stats.t_peak * scale, stats.peak_value, marker, color="C1", ms=7)
    ax.set_xlabel(f"time t ({unit})")
    ax.set_ylabel("acceleration (m/s$^2$)")
    ax.set_title(
        f"record: {stats.n_samples} samples over {stats.duration * scale:.4g} {unit}; "
        f"RMS = {stats.rms:.3g} m/s$^2$ (dashed: ±RMS)\n"
        f"peak |a| = {stats.peak:.3g} m/s$^2$ at t = {stats.t_peak * scale:.4g} {unit} "
        f"(orange marker)",
        fontsize=9,
    )


def _log_curve(ax, x, y, floor, **style):
    """``y`` against ``x`` on a log axis, cut at ``floor`` times its largest value; a record
    that is zero throughout is drawn flat on a linear axis and said so."""
    top = float(np.max(y)) if len(y) else 0.0
    if top > 0.0:
        ax.semilogy(x, np.maximum(y, top * floor), **style)
        return
    ax.plot(x, np.zeros_like(x), **style)
    _say_zero(ax)


def _say_zero(ax):
    """Write on ``ax`` that the record is zero throughout (nothing to scale a log axis by)."""
    ax.text(0.5, 0.75, "zero throughout", transform=ax.transAxes, ha="center", va="center")


def _spectrum_panel(ax, output, stats, f_max):
    keep = output.freq <= f_max
    amp = output.amplitude[keep]
    _log_curve(ax, output.freq[keep] / 1e3, amp, 1e-9, lw=0.6)
    ax.set_xlim(0.0, f_max / 1e3)
    ax.set_xlabel("frequency (kHz)")
    ax.set_ylabel("amplitude (m/s$^2$, peak)")
    ax.set_title(
        f"amplitude spectrum of the whole record, Δf = fs/N = {stats.df_spectrum:.3g} Hz",
        fontsize=9,
    )


def _welch_panel(ax, output, stats, f_max):
    fs = output.chain.sample_rate
    f, p = welch_psd(output, stats.welch_segment)
    keep = f <= f_max
    _log_curve(ax, f[keep] / 1e3, p[keep], 1e-12, lw=0.8, color="C2")
    ax.set_xlim(0.0, f_max / 1e3)
    ax.set_xlabel("frequency (kHz)")
    ax.set_ylabel("PSD ((m/s$^2$)$^2$/Hz)")
    n_seg = max(1, (stats.n_samples - stats.welch_segment) // (stats.welch_segment // 2) + 1)
    ax.set_title(
        f"Welch PSD: {n_seg} Hann segments of {stats.welch_segment} samples, 50 % overlap, "
        f"Δf = {fs / stats.welch_segment:.3g} Hz",
        fontsize=9,
    )


def _spectrogram_panel(fig, ax, output, stats, f_max):
    fs = output.chain.sample_rate
    seg = stats.spectrogram_segment
    f, t, s = signal.spectrogram(
        output.acceleration, fs=fs, window="hann", nperseg=seg, noverlap=3 * seg // 4
    )
    keep = f <= f_max
    db = 10.0 * np.log10(np.maximum(s[keep], 1e-300))
    top = db.max()
    scale, unit = time_unit(stats.duration)
    mesh = ax.pcolormesh(
        t * scale, f[keep] / 1e3, db, shading="nearest", cmap="magma", vmin=top - DB_RANGE, vmax=top
    )
    fig.colorbar(mesh, ax=ax, label="PSD (dB re 1 (m/s$^2$)$^2$/Hz)")
    if not s.max() > 0.0:
        _say_zero(ax)
    ax.set_xlim(0.0, stats.duration * scale)
    ax.set_ylim(0.0, f_max / 1e3)
    ax.set_xlabel(f"time t ({unit})")
    ax.set_ylabel("frequency (kHz)")
    ax.set_title(
        f"spectrogram: Hann segments of {seg} samples ({seg / fs * 1e3:.3g} ms), "
        f"75 % overlap, Δf = {fs / seg:.3g} Hz",
        fontsize=9,
    )


def sensor_figure(output, path, *, position=None, direction=None, band_hz=None) -> Path:
    """Write build_sensor_figure(output, position, direction, band_hz) to ``path`` (PNG);
    returns the path."""
    path = Path(path)
    build_sensor_figure(output, position, direction, band_hz).savefig(path, dpi=110)
    return path


def build_sensor_figure(output, position=None, direction=None, band_hz=None) -> Figure:
    """One sensor's record as a 2 x 2 figure: acceleration against time (peak and RMS marked),
    the whole-record amplitude spectrum (with its resolution fs/N), a Welch PSD and a
    spectrogram, all up to the sensor's usable bandwidth.

    Parameters
    ----------
    output : tailbeam.signals.sensor.SensorOutput
        The sampled record (m/s^2) and the chain that produced it.
    position : (x, y) or (x, y, z) in m, optional
        The sensor's position on the plate or structure, written in the title.
    direction : (dx, dy, dz), optional
        The sensor's measuring direction (unit, plate frame), written in the title.
    band_hz : float, optional
        The top of the modal band (Hz). Below the sensor's bandwidth it is marked (dotted) on
        the spectra and the spectrogram, and the title says that above it the record holds
        only the truncated modes' contact tails and static response.

    Returns
    -------
    matplotlib.figure.Figure
    """
    stats = sensor_stats(output)
    chain = output.chain
    f_max = min(chain.bandwidth_hz, 0.5 * chain.sample_rate)
    fig = Figure(figsize=(12.0, 7.4), layout="constrained")
    (ax_t, ax_f), (ax_w, ax_s) = fig.subplots(2, 2)
    _time_panel(ax_t, output, stats)
    _spectrum_panel(ax_f, output, stats, f_max)
    if stats.n_samples >= 2 * MIN_SEGMENT:
        _welch_panel(ax_w, output, stats, f_max)
        _spectrogram_panel(fig, ax_s, output, stats, f_max)
    else:
        for ax in (ax_w, ax_s):
            ax.set_axis_off()
            ax.text(
                0.5,
                0.5,
                f"record too short (< {2 * MIN_SEGMENT} samples)",
                ha="center",
                transform=ax.transAxes,
            )
    for ax in (ax_t, ax_f, ax_w):
        ax.grid(alpha=0.3)
    where = _where(position, direction)
    title = (f"sensor {output.name}{where}: fs = {chain.sample_rate:g} Hz, usable band to "
             f"{chain.bandwidth_hz:g} Hz (plots stop there), mounted resonance "
             f"{chain.mounted_resonance_hz:g} Hz")  # fmt: skip
    if band_hz is not None and band_hz < f_max:
        _mark_band(ax_f, ax_w, ax_s, band_hz)
        title += (f"\nmodes to {band_hz:g} Hz (dotted line); above it only the truncated "
                  "modes' contact tails and static response")  # fmt: skip
    fig.suptitle(title, fontsize=10)
    return fig


def _mark_band(ax_f, ax_w, ax_s, band_hz: float) -> None:
    """The modal band's top (Hz) as a dotted line on the spectra and the spectrogram."""
    for ax in (ax_f, ax_w):
        ax.axvline(band_hz / 1e3, ls=":", lw=1.2, color="0.25")
    if ax_s.axison:
        ax_s.axhline(band_hz / 1e3, ls=":", lw=1.2, color="white")


def _where(position, direction) -> str:
    """' at (x, y) = (..) m' (and ' along (..)') for a figure's title."""
    if position is None:
        return ""
    names = "(x, y)" if len(position) == 2 else "(x, y, z)"
    where = f" at {names} = ({', '.join(f'{v:g}' for v in position)}) m"
    if direction is not None:
        where += f" along ({', '.join(f'{v:.3g}' for v in direction)})"
    return where


def sensor_figures(outputs: dict, out_dir, positions: dict | None = None) -> list:
    """sensor_<name>.png in ``out_dir`` for every SensorOutput in ``outputs`` (name -> output);
    ``positions``: name -> (x, y) in m. Returns the paths written."""
    positions = positions or {}
    return [
        sensor_figure(out, Path(out_dir) / f"sensor_{name}.png", position=positions.get(name))
        for name, out in outputs.items()
    ]
