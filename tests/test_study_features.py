"""tailbeam.study.features against closed forms: sine and square-wave amplitude statistics,
Gaussian and exponential moments, Parseval for the band energies, a damped sine's decay."""

import math

import numpy as np
import pytest

pytest.importorskip("pywt")

from tailbeam.study import features as F  # noqa: E402

FS = 10000.0
T = np.arange(10000) / FS  # 1 s: whole periods of every test tone


def test_sine_amplitude_statistics():
    # 2.5 kHz at 10 kHz: samples at quarter periods hit the peaks exactly
    x = 3.0 * np.sin(2 * np.pi * 2500 * T + 0.5 * np.pi)
    assert F.rms(x) == pytest.approx(3.0 / math.sqrt(2), rel=1e-12)
    assert F.peak(x) == pytest.approx(3.0, rel=1e-12)
    assert F.crest_factor(x) == pytest.approx(math.sqrt(2), rel=1e-12)
    # a sine's kurtosis is 3/2 and its skewness 0 (any sampling over whole periods)
    y = np.sin(2 * np.pi * 130 * T)
    assert F.kurtosis(y) == pytest.approx(1.5, rel=1e-9)
    assert abs(F.skewness(y)) < 1e-9


def test_square_wave_crest_factor_is_one():
    x = np.sign(np.sin(2 * np.pi * 100 * T + 0.1))
    assert F.crest_factor(x) == pytest.approx(1.0, rel=1e-12)
    assert F.kurtosis(x) == pytest.approx(1.0, abs=1e-3)


def test_gaussian_and_exponential_moments():
    n = 400_000
    rng = np.random.default_rng(1)
    g = rng.standard_normal((2, n))
    # standard errors: sqrt(24/n) for kurtosis, sqrt(6/n) for skewness; allow 5 of them
    assert F.kurtosis(g) == pytest.approx([3.0, 3.0], abs=5 * math.sqrt(24 / n))
    assert np.all(np.abs(F.skewness(g)) < 5 * math.sqrt(6 / n))
    e = rng.exponential(size=n)  # skewness 2, kurtosis 9
    assert F.skewness(e) == pytest.approx(2.0, abs=0.05)
    assert F.kurtosis(e) == pytest.approx(9.0, abs=0.5)


def test_batch_shape_is_kept():
    x = np.random.default_rng(0).standard_normal((3, 4, 512))
    for name, v in F.all_features(x, FS).items():
        assert v.shape == (3, 4), name
    assert F.rms(x)[1, 2] == pytest.approx(F.rms(x[1, 2]))


def test_spectral_centroid_of_tones():
    x = np.sin(2 * np.pi * 1200 * T)
    assert F.spectral_centroid(x, FS) == pytest.approx(1200.0, rel=1e-9)
    # two tones of amplitudes 1 and 2: power-weighted mean (1 * 500 + 4 * 3000) / 5
    y = np.sin(2 * np.pi * 500 * T) + 2 * np.sin(2 * np.pi * 3000 * T)
    assert F.spectral_centroid(y, FS) == pytest.approx(2500.0, rel=1e-9)


def test_third_octave_bands_parseval_and_placement():
    x = 2.0 * np.sin(2 * np.pi * 1000 * T)
    centres = F.third_octave_centres(FS)
    bands = F.band_energies(x, FS, centres)
    # energy of A sin over 1 s: A^2 / 2 (m/s^2)^2 s, all of it in the 1 kHz band
    assert bands[np.argmin(np.abs(centres - 1000))] == pytest.approx(2.0, rel=1e-9)
    assert bands.sum() == pytest.approx(2.0, rel=1e-9)
    # adjacent band edges touch: fc_k 2^(1/6) == fc_(k+1) 2^(-1/6)
    np.testing.assert_allclose(centres[:-1] * 2 ** (1 / 6), centres[1:] * 2 ** (-1 / 6))


def test_wavelet_packet_energies_add_up_and_localise():
    rng = np.random.default_rng(3)
    x = rng.standard_normal((2, 1024))
    wp = F.wavelet_packet_energies(x, FS, level=3)
    assert wp.shape == (2, 8)
    np.testing.assert_allclose(wp.sum(axis=-1), np.sum(x**2, axis=-1) / FS, rtol=1e-10)
    # a tone in the middle of node 5's band (5/8..6/8 of Nyquist) puts most energy there
    tone = np.sin(2 * np.pi * (5.5 / 16) * FS * np.arange(1024) / FS)
    e = F.wavelet_packet_energies(tone, FS, level=3)
    assert np.argmax(e) == 5 and e[5] > 0.8 * e.sum()


def test_welch_summary_of_white_noise_and_a_tone():
    rng = np.random.default_rng(5)
    x = 0.7 * rng.standard_normal(200_000)
    s = F.welch_summary(x, FS)
    assert s["psd_power"] == pytest.approx(0.49, rel=0.02)  # variance of white noise
    assert s["psd_median_hz"] == pytest.approx(FS / 4, rel=0.05)  # flat PSD: half at fs/4
    tone = F.welch_summary(np.sin(2 * np.pi * 1250 * T), FS)
    assert tone["psd_peak_hz"] == pytest.approx(1250.0, abs=FS / 256)


def test_decay_rate_of_damped_sines():
    for sigma in (20.0, 80.0):
        x = np.exp(-sigma * T) * np.sin(2 * np.pi * 700 * T)
        assert F.decay_rate(x, FS) == pytest.approx(sigma, rel=0.01)
    assert F.decay_rate(np.sin(2 * np.pi * 700 * T), FS) == pytest.approx(0.0, abs=0.5)
