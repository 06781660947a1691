"""The automatic modal band (tailbeam.solvers.modal_setup.band): its estimates against independent
truths (the SSSS closed-form static compliance and exact SSSS modes), its choice, and its
refusals."""

import numpy as np
import pytest

from tailbeam.cli import main
from tailbeam.errors import InputError
from tailbeam.io.scene_file import loads_scene
from tailbeam.physics.bodies import Ball, Plate
from tailbeam.physics.contact_law import ball_plate_law
from tailbeam.physics.hertz import hertz_contact_duration, hertz_max_penetration, hertz_peak_force
from tailbeam.physics.materials import CARBON_STEEL, COAL, SANDSTONE
from tailbeam.plate.closed_forms import ssss_kirchhoff_basis, ssss_static_compliance
from tailbeam.solvers import single_ball
from tailbeam.solvers.coupled import simulate_coupled
from tailbeam.solvers.modal_setup import band as auto
from tailbeam.solvers.modal_setup import setup

PLATE = Plate()
SCENE = """
duration = 0.004
[plate]
model = "modal"
{plate}
[[balls]]
name = "small"
material = "sandstone"
radius = 0.01
position = [0.05, 0.07, 0.0105]
velocity = [0.0, 0.0, -3.0]
[[balls]]
name = "big"
material = "coal"
radius = 0.04
position = [-0.15, -0.1, 0.0405]
velocity = [0.0, 0.0, -3.0]
{sensors}
"""
SENSOR = '[[sensors]]\nname = "acc"\nposition = [0.2, 0.2]\nsample_rate = {fs}\n'


def scene(plate="", sensors=""):
    return loads_scene(SCENE.format(plate=plate, sensors=sensors))


@pytest.mark.parametrize("f_cut", [5e3, 1e4, 2e4])
def test_residual_compliance_estimate_matches_ssss_closed_form(f_cut):
    # Truth: the Navier-series static compliance minus the exact modes below f_cut.
    pts = np.array([[0.05, 0.07], [-0.12, 0.1], [0.2, -0.15]])
    basis = ssss_kirchhoff_basis(PLATE, f_cut)
    full = ssss_static_compliance(PLATE, pts, 0.0, "kirchhoff")
    truth = full - np.sum(basis.deflection(pts) ** 2 / basis.omega**2, axis=1)
    ratio = truth / auto.residual_compliance_estimate(PLATE, f_cut)
    np.testing.assert_allclose(ratio, 1.0, atol=0.1)


def test_undamped_pulse_matches_hertz_closed_forms():
    # Truth: Johnson's closed forms (tailbeam.physics.hertz) for an undamped impact on a rigid flat.
    law = ball_plate_law(SANDSTONE, 0.02, CARBON_STEEL)
    mass = Ball("b", SANDSTONE, 0.02, (0.0, 0.0, 0.03)).mass
    pulse = auto.impact_pulse(mass, 2.0, law)
    delta = hertz_max_penetration(mass, 2.0, law.stiffness, law.exponent)
    assert pulse["duration_s"] == pytest.approx(hertz_contact_duration(mass, 2.0, law.stiffness))
    assert pulse["compliance_m_n"] == pytest.approx(
        delta / hertz_peak_force(mass, 2.0, law.stiffness), rel=1e-4
    )


@pytest.mark.parametrize(
    ("material", "radius", "damping"),
    [(SANDSTONE, 0.01, 300.0), (COAL, 0.01, 300.0), (COAL, 0.04, 0.0), (SANDSTONE, 0.03, 300.0)],
)
def test_force_error_estimate_bounds_the_truncation_error_on_exact_modes(material, radius, damping):
    # Truth: the same impact on exact SSSS modes up to 16/T (converged: 8/T differs by
    # < 1e-5); the band's peak-force error is measured against it, residual flexibility on.
    ball = Ball("b", material, radius, (0.05, 0.07, radius + 1e-4), (0.0, 0.0, -3.0))
    law = ball_plate_law(material, radius, CARBON_STEEL, damping=damping)
    contact = auto.impact_pulse(ball.mass, 3.0, law)
    t_c = contact["duration_s"]
    full = ssss_kirchhoff_basis(PLATE, 16.0 / t_c)

    def peak(basis):
        res = simulate_coupled([ball], basis, [law], 2 * t_c, gravity=0.0, steps_per_contact=400)
        return res.impacts[0].peak_force

    truth = peak(full)
    for f_cut in (1.0 / t_c, 2.0 / t_c):
        measured = abs(peak(full.truncated(fmax_hz=f_cut)) / truth - 1.0)
        estimate = auto.force_error_estimate(PLATE, f_cut, contact)
        # an upper bound (BAND_SAFETY is calibrated on these), and not a vacuous one
        assert estimate / 20 < measured <= estimate, (f_cut, measured, estimate)


def test_band_is_the_larger_of_sensor_and_contact_needs_and_meets_the_accuracy():
    contact_only = auto.choose_band(scene())
    assert contact_only["fmax_sensors_hz"] == 0.0
    assert contact_only["hardest_contact"] == "small"  # the shortest, stiffest contact
    f_c = contact_only["fmax_contact_hz"]
    assert f_c <= contact_only["fmax_hz"] < f_c + auto.BAND_GRID_HZ  # rounded up to the grid
    assert contact_only["fmax_hz"] % auto.BAND_GRID_HZ == 0.0
    assert contact_only["truncation_force_error"] <= auto.BAND_ACCURACY
    # the smallest such band: 2 % lower misses the accuracy
    small = auto._contacts(scene())["small"]
    assert auto.force_error_estimate(PLATE, 0.98 * f_c, small) > auto.BAND_ACCURACY
    # a sensor with a wider band than the contacts need sets the band ...
    wide = auto.choose_band(scene(sensors=SENSOR.format(fs=2.56 * 2 * f_c)))
    assert 2 * f_c <= wide["fmax_hz"] < 2 * f_c + auto.BAND_GRID_HZ
    assert "sensor bandwidth" in wide["reason"]
    assert wide["truncation_force_error"] < auto.BAND_ACCURACY
    # ... and [plate] fmax overrides both, with its estimated error
    user = auto.choose_band(scene(plate="fmax = 5000.0"))
    assert user["fmax_hz"] == 5000.0 and user["truncation_force_error"] > auto.BAND_ACCURACY


def test_too_costly_band_is_refused_naming_plate_fmax_before_any_work(tmp_path, capsys):
    for fmax in ("72000.0", "1e6"):
        with pytest.raises(InputError) as info:
            setup.build_basis(scene(plate=f"fmax = {fmax}"), use_cache=False)
        assert info.value.field == "plate.fmax", info.value
    path = tmp_path / "scene.toml"
    path.write_text(SCENE.format(plate="fmax = 72000.0", sensors=""))
    out = tmp_path / "out"
    assert main(["simulate", str(path), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "plate.fmax" in err and "GB" in err
    assert not out.exists()


@pytest.mark.parametrize("ratio", ["1.0", "50.0"])
def test_overdamped_plate_is_refused_naming_damping_ratio(ratio):
    with pytest.raises(InputError) as info:
        scene(plate=f"damping_ratio = {ratio}")
    assert info.value.field == "plate.damping_ratio"


def test_describe_choices_is_one_line(tmp_path, monkeypatch):
    monkeypatch.setenv("TAILBEAM_CACHE_DIR", str(tmp_path))
    s = scene(plate="fmax = 3000.0\nmesh_divisions = 8")
    res = single_ball.simulate_scene_modal(s)
    line = setup.describe_choices(res.info)
    assert "\n" not in line
    assert line.startswith("band 0-3.0 kHz (plate.fmax set in the scene)")
    assert f"{res.plate.basis.n_modes} modes" in line and "8 divisions" in line


STREAM = """
duration = 0.5
[plate]
model = "modal"
boundary = "SSSS"
inclination = {incl}
fmax = 10000.0
[[streams]]
name = "s"
rate = 100.0
start = 0.0
stop = 0.4
gangue_fraction = 0.5
radius = [0.01, 0.04]
area = [[-0.2, 0.2], [-0.2, 0.2]]
height = [0.3, 0.8]
seed = 3
"""


def _normal_impact(scene, particle):
    """(normal speed m/s, Hertz contact duration s) of a particle's hardest plate impact."""
    g_n = scene.gravity * np.cos(np.radians(scene.inclination))
    law = scene.contacts().law(particle.name, "plate")
    v = float(
        np.sqrt(particle.velocity[2] ** 2 + 2 * g_n * (particle.position[2] - particle.radius))
    )
    return v, hertz_contact_duration(particle.mass, v, law.stiffness, law.exponent)


def _ball_at_plate(particle, speed) -> str:
    """The particle as a [[balls]] ball 1 nm above the plate, falling at ``speed`` m/s."""
    r = float(particle.radius)
    return (
        f'[[balls]]\nname = "b"\nmaterial = "{particle.material.name}"\nradius = {r!r}\n'
        f"position = [0.0, 0.0, {r + 1e-9!r}]\nvelocity = [0.0, 0.0, {-speed!r}]\n"
    )


def test_stream_band_estimates_the_shortest_contact_as_a_single_ball_would():
    """A stream's band carries the same estimate as choose_band's for the particle with the
    shortest contact (not a placeholder), and the run says when the band is too low."""
    from tailbeam.solvers.modal_setup.band import _band_warning, stream_band

    head = SCENE.split("[[balls]]")[0].format(plate="fmax = 10000.0")
    for incl in (0.0, 30.0):
        sc = loads_scene(STREAM.format(incl=incl))
        band = stream_band(sc)
        band.update(auto.stream_band_estimate(sc, band["fmax_hz"]))
        # the hardest contact is the shortest Hertz contact over every particle
        shortest = min(sc.particles, key=lambda p: _normal_impact(sc, p)[1])
        assert band["contact_duration_min_s"] == pytest.approx(
            _normal_impact(sc, shortest)[1], rel=1e-12
        )
        # the same particle as a [[balls]] ball on a horizontal plate: choose_band's estimate
        # (same pulse, same estimator); rel 1e-7: its 1 nm gap adds 2 g 1e-9 to v^2
        p = next(q for q in sc.particles if q.name == band["hardest_contact"])
        single = auto.choose_band(loads_scene(head + _ball_at_plate(p, _normal_impact(sc, p)[0])))
        for key in ("truncation_force_error", "fmax_contact_hz"):
            assert band[key] == pytest.approx(single[key], rel=1e-7)
        assert band["truncation_force_error"] > auto.BAND_ACCURACY  # 10 mm lumps at 10 kHz
    line = _band_warning(band)
    assert "\n" not in line and "would need" in line and band["hardest_contact"] in line
    # a band below the pulse's own frequency has no estimate (inf), and says so, not "inf%"
    line = _band_warning(dict(band, truncation_force_error=float("inf")))
    assert "inf" not in line and "no error estimate" in line
