"""The sensor noise model (tailbeam.signals.noise, scene key [[sensors]] noise): its RMS and band
against their definitions, reproducibility from the seed, and the scene-file key."""

import numpy as np
import pytest

from tailbeam.errors import InputError
from tailbeam.io.scene_dump import dumps_scene
from tailbeam.io.scene_file import loads_scene
from tailbeam.signals.noise import NoiseSpec, band_limited_noise, noise
from tailbeam.signals.sensor import SensorSpec, measure

FS = 20000.0
N = 200_000


def test_white_noise_rms_and_flat_spectrum():
    x = noise(NoiseSpec(rms=0.3, seed=4), "S1", N, FS)
    # sample RMS of Gaussian noise scatters by ~ rms / sqrt(2 N): 0.16 % here; allow 1 %
    assert np.sqrt(np.mean(x**2)) == pytest.approx(0.3, rel=0.01)
    p = np.abs(np.fft.rfft(x)) ** 2
    lo, hi = p[1 : len(p) // 2].mean(), p[len(p) // 2 : -1].mean()
    assert lo == pytest.approx(hi, rel=0.03)


def test_background_is_confined_to_its_band_with_the_given_rms():
    rng = np.random.default_rng(0)
    x = band_limited_noise(rng, N, FS, (50.0, 400.0), 2.0)
    assert np.sqrt(np.mean(x**2)) == pytest.approx(2.0, rel=0.02)
    f = np.fft.rfftfreq(N, 1 / FS)
    p = np.abs(np.fft.rfft(x)) ** 2
    outside = (f < 50.0) | (f > 400.0)
    assert p[outside].sum() < 1e-20 * p.sum()
    # expected mean square over many draws is level^2 exactly (not only on average of one)
    ms = [np.mean(band_limited_noise(rng, 4096, FS, (50.0, 400.0), 2.0) ** 2) for _ in range(400)]
    assert np.mean(ms) == pytest.approx(4.0, rel=0.03)


def test_same_seed_same_noise_other_sensor_independent():
    spec = NoiseSpec(rms=1.0, background=0.5, band_hz=(10.0, 500.0), seed=11)
    a = noise(spec, "S1", 5000, FS)
    np.testing.assert_array_equal(a, noise(spec, "S1", 5000, FS))
    b = noise(spec, "S2", 5000, FS)
    assert abs(np.corrcoef(a, b)[0, 1]) < 0.05
    c = noise(NoiseSpec(rms=1.0, background=0.5, band_hz=(10.0, 500.0), seed=12), "S1", 5000, FS)
    assert not np.array_equal(a, c)


def test_sensor_output_is_the_clean_chain_plus_the_noise():
    def sine(t):
        return 5.0 * np.sin(2 * np.pi * 300.0 * t)

    spec = NoiseSpec(rms=0.2, seed=3)
    clean = measure(SensorSpec("S1", (0.0, 0.0), sample_rate=FS), sine, 0.1)
    noisy = measure(SensorSpec("S1", (0.0, 0.0), sample_rate=FS, noise=spec), sine, 0.1)
    added = noisy.acceleration - clean.acceleration
    np.testing.assert_allclose(added, noise(spec, "S1", len(added), FS), rtol=0, atol=1e-12)


SCENE = """
duration = 0.01
[plate]
model = "modal"
[[balls]]
name = "b"
material = "coal"
radius = 0.02
position = [0.0, 0.0, 0.021]
velocity = [0.0, 0.0, -1.0]
[[sensors]]
name = "S1"
position = [0.1, 0.1]
"""


def test_scene_key_forms_and_round_trip():
    s = loads_scene(SCENE + "noise = 0.05\n")
    assert s.sensors[0].noise == NoiseSpec(rms=0.05)
    table = "noise = { rms = 0.1, background = 1.5, band = [20.0, 800.0], seed = 9 }\n"
    s = loads_scene(SCENE + table)
    assert s.sensors[0].noise == NoiseSpec(0.1, 1.5, (20.0, 800.0), 9)
    assert loads_scene(dumps_scene(s)) == s
    assert loads_scene(SCENE).sensors[0].noise is None


@pytest.mark.parametrize(
    "line, field",
    [
        ("noise = -1", "sensors[1].noise"),
        ("noise = { rsm = 1.0 }", "sensors[1].noise.rsm"),
        ("noise = { band = [500.0, 20.0] }", "sensors[1].noise.band"),
        ("noise = { seed = -2 }", "sensors[1].noise.seed"),
        ("noise = { background = nan }", "sensors[1].noise.background"),
    ],
)
def test_bad_noise_names_the_field(line, field):
    with pytest.raises(InputError) as info:
        loads_scene(SCENE + line + "\n")
    assert info.value.field == field
    assert "\n" not in str(info.value)
