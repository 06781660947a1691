"""One-way coupling (rigid-plate forces applied to the plate) against two-way, and what it
gets wrong; the scene runner and its band choice."""

import numpy as np
import pytest

from tailbeam.physics.bodies import Ball, Plate
from tailbeam.physics.contact_law import ball_plate_law
from tailbeam.physics.hertz import hertz_contact_duration
from tailbeam.physics.materials import CARBON_STEEL, COAL, SANDSTONE
from tailbeam.plate.closed_forms import ssss_kirchhoff_basis
from tailbeam.scene import ContactSettings, ModalPlateSettings, Scene
from tailbeam.signals.sensor import SensorSpec
from tailbeam.solvers.coupled import simulate_coupled
from tailbeam.solvers.coupled.zener import point_impedance, zener_impact
from tailbeam.solvers.modal_setup.band import BAND_ACCURACY, choose_band
from tailbeam.solvers.rigid import simulate_rigid
from tailbeam.solvers.single_ball import simulate_scene_modal

R = 0.03


def test_one_way_ignores_the_energy_the_plate_takes():
    # c = 0: the rigid-plate ball keeps all its energy (restitution 1), yet the one-way plate
    # vibrates: energy is created. Two-way conserves it and follows Zener (independent ODE).
    plate = Plate()
    basis = ssss_kirchhoff_basis(plate, 20000.0)
    ball = Ball("s", SANDSTONE, R, (0.0, 0.0, R + 1e-4), (0.0, 0.0, -1.0))
    law = ball_plate_law(SANDSTONE, R, CARBON_STEEL, damping=0.0)
    kw = {"gravity": 0.0, "damping_ratio": 0.0}
    one = simulate_coupled([ball], basis, [law], 1e-3, coupling="one-way", **kw)
    two = simulate_coupled([ball], basis, [law], 1e-3, **kw)
    zen = zener_impact(ball.mass, 1.0, law.stiffness, point_impedance(plate))
    assert one.impacts[0].restitution == pytest.approx(1.0, abs=1e-6)
    assert two.impacts[0].restitution == pytest.approx(zen.restitution, rel=2e-3)
    ke = 0.5 * ball.mass
    e_one = one.plate.energy([1e-3])[0]
    e_two = two.plate.energy([1e-3])[0]
    assert e_one > 0.3 * ke  # created from nothing: the ball lost none of it
    # c = 0: all the ball's loss is in the plate, up to the O(h^2) time-step error (2e-5 at the
    # default 200 steps per contact, see test_time_step_convergence_is_second_order)
    assert e_two == pytest.approx(ke * (1 - two.impacts[0].restitution ** 2), rel=1e-4)


def test_one_way_vs_two_way_restitution_peak_force_duration():
    # With the default c: one-way reproduces the rigid plate exactly; two-way (the plate yields
    # and radiates) gives lower restitution and peak force and a longer contact.
    plate = Plate()
    basis = ssss_kirchhoff_basis(plate, 15000.0)
    contact = ContactSettings()
    balls = [
        Ball("coal", COAL, R, (-0.15, 0.0, R + 0.01), (0.0, 0.0, -1.0)),
        Ball("sandstone", SANDSTONE, R, (0.15, 0.0, R + 0.01), (0.0, 0.0, -1.0)),
    ]
    laws = [contact.law_for(b, CARBON_STEEL) for b in balls]
    one = simulate_coupled(balls, basis, laws, 0.05, coupling="one-way")
    two = simulate_coupled(balls, basis, laws, 0.05)
    rigid = simulate_rigid(balls, plate, laws, 0.05)
    for name in ("coal", "sandstone"):
        a, b, r = two.impacts_of(name)[0], one.impacts_of(name)[0], rigid.impacts_of(name)[0]
        assert b.restitution == r.restitution and b.peak_force == r.peak_force
        assert a.restitution < 0.9 * b.restitution
        assert a.peak_force < 0.95 * b.peak_force
        assert a.t_end - a.t_start > 1.02 * (b.t_end - b.t_start)
    # the one-way plate still answers the rigid forces: its sensor signal is not zero
    acc = one.plate.sample(np.linspace(0.0, 0.05, 501), [(0.0, 0.1)])["a"][0]
    assert np.max(np.abs(acc)) > 1.0


def test_band_choice_from_contact_duration_and_sensors():
    contact = ContactSettings()
    ball = Ball("c", COAL, R, (0.0, 0.0, R + 0.05), (0.0, 0.0, -1.0))
    plain = Scene((ball,), Plate(), contact, 0.1, plate_model="modal")
    band = choose_band(plain)
    law = contact.law_for(ball, CARBON_STEEL)
    speed = np.sqrt(1.0 + 2 * 9.80665 * 0.05)
    t_c = hertz_contact_duration(ball.mass, speed, law.stiffness)
    # the damped pulse (default contact damping) lasts a little longer than Hertz's
    assert t_c <= band["contact_duration_min_s"] < 1.1 * t_c
    # the band: the contacts' accuracy-driven need (tests/test_band.py checks its estimate)
    assert band["fmax_contact_hz"] >= 1.0 / band["contact_duration_min_s"]
    assert band["fmax_contact_hz"] <= band["fmax_hz"] < band["fmax_contact_hz"] + 500.0
    assert band["truncation_force_error"] <= BAND_ACCURACY * (1 + 1e-6)
    fast = SensorSpec("s", (0.1, 0.1), sample_rate=102400.0)
    with_sensor = Scene((ball,), Plate(), contact, 0.1, plate_model="modal", sensors=(fast,))
    assert choose_band(with_sensor)["fmax_hz"] == pytest.approx(102400.0 / 2.56)
    user = Scene((ball,), Plate(), contact, 0.1, plate_model="modal",
                 modal=ModalPlateSettings(fmax_hz=3000.0))  # fmt: skip
    assert choose_band(user)["fmax_hz"] == 3000.0


def test_scene_runner_builds_the_fe_basis_and_the_sensors():
    # small band on a coarse Kirchhoff FE mesh (fast); the runner must honour the settings
    settings = ModalPlateSettings(theory="kirchhoff", fmax_hz=3000.0, mesh_divisions=6,
                                  damping_ratio=0.02)  # fmt: skip
    ball = Ball("c", COAL, R, (0.05, 0.0, R + 0.002), (0.0, 0.0, -1.0))
    sensor = SensorSpec("s1", (-0.1, 0.1), sample_rate=25600.0)
    scene = Scene((ball,), Plate(), ContactSettings(), 0.02, plate_model="modal",
                  modal=settings, sensors=(sensor,))  # fmt: skip
    res = simulate_scene_modal(scene, use_cache=False)
    assert res.info["basis"]["theory"] == "kirchhoff"
    assert res.info["basis"]["top_frequency_hz"] <= 3000.0
    assert np.all(res.plate.zeta == 0.02)
    t, a = res.sensor_signals["s1"]
    assert len(t) == int(0.02 * 25600) + 1 and np.all(np.isfinite(a))
    assert np.max(np.abs(a)) > 0.0
    assert len(res.impacts) >= 1
