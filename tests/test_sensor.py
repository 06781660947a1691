"""The accelerometer chain against closed forms (2nd-order resonance, aliasing, spectra)."""

import math

import numpy as np
import pytest

from tailbeam.errors import InputError
from tailbeam.signals.sensor import SensorSpec, amplitude_spectrum, chain_response, measure, resolve

FS = 51200.0


def _sine(freq, amp=1.0):
    return lambda t: amp * np.sin(2 * np.pi * freq * t)


def _steady_amplitude(out, freq):
    # least-squares sinusoid fit over the second half (filters settled)
    t = out.t[len(out.t) // 2 :]
    y = out.acceleration[len(out.t) // 2 :]
    basis = np.column_stack([np.sin(2 * np.pi * freq * t), np.cos(2 * np.pi * freq * t)])
    coef, *_ = np.linalg.lstsq(basis, y, rcond=None)
    return math.hypot(*coef), math.atan2(coef[1], coef[0])


def test_defaults_follow_the_daq_conventions():
    chain = resolve(SensorSpec("s", (0.0, 0.0)))
    assert chain.sample_rate == FS
    assert chain.bandwidth_hz == pytest.approx(FS / 2.56)  # 20 kHz
    assert chain.mounted_resonance_hz == pytest.approx(3 * FS / 2.56)
    assert chain.fine_rate >= 2 * FS
    assert resolve(SensorSpec("s", (0.0, 0.0)), 50000.0).fine_rate >= 2.5 * 50000.0


@pytest.mark.parametrize("freq", [500.0, 5000.0, 15000.0])
def test_in_band_sine_gain_is_the_mounted_resonance_closed_form(freq):
    # Pass band: the FIR is flat (< 1e-4 ripple at 90 dB Kaiser design) and delay-compensated, so
    # the gain is that of the 2nd-order resonance |H| = 1 / sqrt((1 - r^2)^2 + (2 zeta r)^2) and
    # the phase its phase, r = f / f_r.
    spec = SensorSpec("s", (0.0, 0.0))
    out = measure(spec, _sine(freq), 0.05)
    chain = out.chain
    r = freq / chain.mounted_resonance_hz
    zr = chain.resonance_damping
    gain = 1.0 / math.hypot(1 - r**2, 2 * zr * r)
    phase = -math.atan2(2 * zr * r, 1 - r**2)
    amp, ph = _steady_amplitude(out, freq)
    assert amp == pytest.approx(gain, rel=2e-4)
    assert ph == pytest.approx(phase, abs=2e-3)
    assert abs(chain_response(chain, [freq])[0]) == pytest.approx(gain, rel=2e-4)


def test_out_of_band_content_is_not_aliased_into_the_band():
    # 46.2 kHz would alias to 5 kHz at 51.2 kHz sampling without the anti-alias filter.
    spec = SensorSpec("s", (0.0, 0.0))
    out = measure(spec, _sine(FS - 5000.0), 0.05)
    amp, _ = _steady_amplitude(out, 5000.0)
    assert amp < 10 ** (-80 / 20)


def test_amplitude_spectrum_of_a_bin_centred_sine():
    n, fs = 4096, 8192.0
    t = np.arange(n) / fs
    x = 0.7 + 2.5 * np.sin(2 * np.pi * 1000.0 * t)
    f, a = amplitude_spectrum(x, fs)
    assert a[0] == pytest.approx(0.7, rel=1e-12)
    assert a[np.argmin(np.abs(f - 1000.0))] == pytest.approx(2.5, rel=1e-12)
    _, ah = amplitude_spectrum(x, fs, window="hann")
    assert ah[np.argmin(np.abs(f - 1000.0))] == pytest.approx(2.5, rel=1e-12)


def test_custom_rates_and_bad_input():
    spec = SensorSpec("s", (0.0, 0.0), sample_rate=25600.0, bandwidth_hz=10000.0,
                      mounted_resonance_hz=40000.0)  # fmt: skip
    out = measure(spec, _sine(1000.0), 0.02)
    assert np.allclose(np.diff(out.t), 1 / 25600.0)
    assert out.chain.bandwidth_hz == 10000.0
    with pytest.raises(InputError, match="mounted_resonance"):
        resolve(SensorSpec("s", (0.0, 0.0), bandwidth_hz=10000.0, mounted_resonance_hz=9000.0))


def test_sensor_on_a_coupled_run_reads_the_plate_acceleration_in_band():
    # The sensor output of a coupled impact vs the exact plate acceleration sampled at the same
    # instants, both low-passed (zero phase) to 3 kHz where the chain's gain is 1 + 0.25 %:
    # they agree to that gain (the chain neither delays nor distorts the band).
    from scipy import signal as sp_signal

    from tailbeam.physics.bodies import Ball, Plate
    from tailbeam.physics.contact_law import ball_plate_law
    from tailbeam.physics.materials import CARBON_STEEL, COAL
    from tailbeam.plate.closed_forms import ssss_kirchhoff_basis
    from tailbeam.solvers.coupled import simulate_coupled

    basis = ssss_kirchhoff_basis(Plate(), 10000.0)
    ball = Ball("c", COAL, 0.03, (0.1, 0.05, 0.031), (0.0, 0.0, -1.0))
    spec = SensorSpec("s", (-0.1, 0.12))
    res = simulate_coupled([ball], basis, [ball_plate_law(COAL, 0.03, CARBON_STEEL)], 0.05,
                           sensors=(spec,), gravity=0.0)  # fmt: skip
    t, measured = res.sensor_signals["s"]
    true = res.plate.acceleration(spec.position, t)
    sos = sp_signal.butter(8, 3000.0, fs=FS, output="sos")
    a, b = sp_signal.sosfiltfilt(sos, measured), sp_signal.sosfiltfilt(sos, true)
    err = np.sqrt(np.mean((a - b) ** 2) / np.mean(b**2))
    assert np.sqrt(np.mean(b**2)) > 1.0 and err < 5e-3
