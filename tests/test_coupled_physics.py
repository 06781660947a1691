"""Two-way coupled ball / flexible-plate impacts against independent truths.

Plate: the exact closed-form simply supported Kirchhoff modes (tailbeam.plate.closed_forms), so
every discrepancy below is the coupled solver's, not the plate model's.
"""

import dataclasses

import numpy as np
import pytest

from tailbeam.physics.bodies import Ball, Plate
from tailbeam.physics.contact_law import ball_plate_law
from tailbeam.physics.materials import CARBON_STEEL, COAL, SANDSTONE
from tailbeam.plate.closed_forms import ssss_kirchhoff_basis
from tailbeam.scene import ContactSettings
from tailbeam.solvers.coupled import simulate_coupled
from tailbeam.solvers.coupled.zener import point_impedance, zener_impact
from tailbeam.solvers.rigid import simulate_rigid

R = 0.03


def _zener_errors(size, fmax, residual=True):
    plate = Plate(size_x=size, size_y=size)
    basis = ssss_kirchhoff_basis(plate, fmax)
    ball = Ball("s", SANDSTONE, R, (0.0, 0.0, R + 1e-5), (0.0, 0.0, -1.0))
    law = ball_plate_law(SANDSTONE, R, plate.material, damping=0.0)
    res = simulate_coupled(
        [ball], basis, [law], 1.5e-3, gravity=0.0, damping_ratio=0.0,
        residual_flexibility=residual,
    )  # fmt: skip
    imp = res.impacts[0]
    ref = zener_impact(ball.mass, 1.0, law.stiffness, point_impedance(plate))
    return (
        abs(imp.restitution / ref.restitution - 1),
        abs((imp.t_end - imp.t_start) / ref.duration - 1),
        ref,
    )


def test_zener_infinite_plate_limit_improves_with_plate_size():
    # c = 0, impact at the centre: the plate acts as the dashpot Z = 8 sqrt(D rho h) until bending
    # waves come back from the edges. Sandstone on the 10 mm steel plate: lambda ~ 0.34 and
    # restitution ~ 0.61 (39 % of the energy radiated); the rigid plate would give 1.
    e_small, t_small, ref = _zener_errors(0.3, 20000.0)
    e_big, t_big, _ = _zener_errors(0.8, 20000.0)
    assert 0.3 < ref.lam < 0.4 and 0.55 < ref.restitution < 0.65
    # few percent on the small plate (waves return from the edges 0.15 m away), much closer on
    # the larger one: the error is the edges', and falls as they move away
    assert e_small < 0.05 and t_small < 0.05
    assert e_big < 2e-3 and t_big < 2e-3
    assert e_big < e_small and t_big < t_small


def test_residual_flexibility_speeds_up_mode_convergence():
    # Truncating at 20 kHz, then 40 kHz: the error against Zener halves or better with mode count,
    # and the residual (static) compliance of the truncated modes cuts it by > 10x at each count.
    errs = {}
    for fmax in (20000.0, 40000.0):
        for residual in (False, True):
            e_err, t_err, _ = _zener_errors(0.6, fmax, residual)
            errs[fmax, residual] = max(e_err, t_err)
    assert errs[40000.0, False] < 0.7 * errs[20000.0, False]
    for fmax in (20000.0, 40000.0):
        assert errs[fmax, True] < 0.1 * errs[fmax, False]
    assert errs[20000.0, False] > 2e-3  # the comparison is not vacuous


def _drop_scene(material, xy, speed=1.0, gap=1e-4, damping=800.0, clamp=True):
    ball = Ball("b", material, R, (xy[0], xy[1], R + gap), (0.0, 0.0, -speed))
    return ball, ball_plate_law(material, R, CARBON_STEEL, damping=damping, clamp=clamp)


def test_energy_balance_ball_loss_equals_plate_energy_plus_dissipation():
    # d/dt(ball energy) = F vz; plate: d/dt(sum (q'^2 + w^2 q^2)/2) = -F w' - sum 2 zeta w q'^2;
    # contact: F (delta_c)' and the residual spring C F^2 / 2. Summed, they must cancel.
    plate = Plate()
    basis = ssss_kirchhoff_basis(plate, 10000.0)
    ball, law = _drop_scene(SANDSTONE, (0.07, -0.05))
    res = simulate_coupled([ball], basis, [law], 1e-3, damping_ratio=0.05)
    t = np.linspace(0.0, res.duration, 40001)
    s = res.sample(t)["b"]
    q, qd, _ = res.plate.modal_sample(t)
    om = basis.omega[:, None]
    m, g = ball.mass, 9.80665
    e_ball = 0.5 * m * s["vz"] ** 2 + m * g * s["z"]
    e_plate = 0.5 * np.sum(qd**2 + om**2 * q**2, axis=0)
    p_modal = np.sum(2 * res.plate.zeta[:, None] * om * qd**2, axis=0)

    def cumtrapz(y, x):
        return np.concatenate([[0.0], np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(x))])

    d_modal = cumtrapz(p_modal, t)
    phi = basis.deflection([ball.position[:2]])[0]
    comp = basis.residual_compliance([ball.position[:2]])[0]
    force = s["force"]
    delta_c = ball.radius - s["z"] + phi @ q - comp * force
    w_contact = np.concatenate(
        [[0.0], np.cumsum(0.5 * (force[1:] + force[:-1]) * np.diff(delta_c))]
    )
    imbalance = (e_ball[0] - e_ball) - (e_plate + d_modal + w_contact + 0.5 * comp * force**2)
    loss = e_ball[0] - e_ball[-1]
    # every term is a sizeable share of the loss (so the check is not vacuous) ...
    assert res.impacts[0].t_end < res.duration
    for part in (e_plate[-1], d_modal[-1], w_contact[-1]):
        assert part > 0.1 * loss
    # ... and the balance closes to the trapezoid rule's accuracy on the sampled histories
    assert np.max(np.abs(imbalance)) < 1e-7 * loss


def test_rigid_limit_reproduces_rigid_plate_impacts():
    # Young's modulus x 1e4 (frequencies x 100, impedance x 100: lambda / 100), same contact law:
    # the impacts must match the rigid-plate solver's. Two balls, different points and speeds.
    plate = Plate()
    stiff_steel = dataclasses.replace(
        CARBON_STEEL, youngs_modulus=CARBON_STEEL.youngs_modulus * 1e4
    )
    stiff = Plate(material=stiff_steel)
    contact = ContactSettings()
    balls = [
        Ball("A", COAL, R, (-0.15, 0.0, 0.04), (0.0, 0.0, -1.0)),
        Ball("B", SANDSTONE, R, (0.1, 0.05, 0.04), (0.0, 0.0, -2.0)),
    ]
    laws = [contact.law_for(b, plate.material) for b in balls]
    flex = simulate_coupled(balls, ssss_kirchhoff_basis(stiff, 3e5), laws, 0.45)
    rigid = simulate_rigid(balls, plate, laws, 0.45)
    for name in "AB":
        pairs = list(zip(flex.impacts_of(name), rigid.impacts_of(name), strict=False))
        assert len(pairs) >= 2
        for a, b in pairs[:3]:
            # residual plate losses ~ lambda/100 ~ 3e-3 of the energy: 2e-3 in restitution
            assert a.restitution == pytest.approx(b.restitution, rel=2e-3)
            assert a.peak_force == pytest.approx(b.peak_force, rel=2e-3)
            assert a.t_end - a.t_start == pytest.approx(b.t_end - b.t_start, rel=2e-3)


def test_reciprocity_force_to_acceleration_transfer():
    # Ball dropped at P, acceleration at S, versus ball at S, acceleration at P. The forces differ
    # (different drive-point mobility) but the transfer accel(f) / force(f) must be the same.
    plate = Plate()
    basis = ssss_kirchhoff_basis(plate, 8000.0)
    p, s = (0.04, -0.03), (-0.22, 0.25)  # near the centre / near a corner: mobilities differ
    fs = 200000.0
    t = np.arange(int(0.2 * fs)) / fs
    transfer = []
    for src, rcv in ((p, s), (s, p)):
        ball, law = _drop_scene(SANDSTONE, src, speed=1.5)
        # no gravity: one impact, then the ball leaves for good
        res = simulate_coupled([ball], basis, [law], 0.2, damping_ratio=0.05, gravity=0.0)
        assert len(res.impacts) == 1
        force = res.sample(t)["b"]["force"]
        acc = res.plate.sample(t, [rcv])["a"][0]
        transfer.append((np.fft.rfft(acc), np.fft.rfft(force)))
    freq = np.fft.rfftfreq(len(t), 1 / fs)
    f_mag = np.minimum(np.abs(transfer[0][1]), np.abs(transfer[1][1]))
    band = (freq > 50) & (freq < 5000) & (f_mag > 0.05 * f_mag.max())
    h1 = transfer[0][0][band] / transfer[0][1][band]
    h2 = transfer[1][0][band] / transfer[1][1][band]
    assert band.sum() > 500
    # the force spectra differ by several percent, the transfers agree to the error of sampling
    # the piecewise-linear force at 200 kHz (~1e-5 measured)
    assert np.max(np.abs(transfer[0][1] - transfer[1][1])[band]) > 0.03 * f_mag.max()
    assert np.max(np.abs(h1 - h2) / np.abs(h2)) < 5e-4


def test_two_balls_at_once_at_different_points():
    # Mirror-symmetric drops at the same time: identical impacts (the plate couples them, so any
    # asymmetry in the multi-contact Newton solve would show); and an asymmetric pair whose
    # contacts overlap conserves energy as in the single-ball test (checked on the ball side).
    plate = Plate()
    basis = ssss_kirchhoff_basis(plate, 10000.0)
    law = ball_plate_law(COAL, R, CARBON_STEEL, damping=800.0)
    balls = [
        Ball("L", COAL, R, (-0.1, 0.05, R + 1e-4), (0.0, 0.0, -1.0)),
        Ball("R", COAL, R, (0.1, 0.05, R + 1e-4), (0.0, 0.0, -1.0)),
    ]
    res = simulate_coupled(balls, basis, [law, law], 0.2)
    # (each ball's events are located on its own, which splits the steps slightly differently:
    # 1e-9 measured, far below the 1e-5 time-step error; 1e-6 asked)
    for a, b in zip(res.impacts_of("L"), res.impacts_of("R"), strict=True):
        assert a.t_start == pytest.approx(b.t_start, abs=1e-9)
        assert a.restitution == pytest.approx(b.restitution, rel=1e-6)
        assert a.peak_force == pytest.approx(b.peak_force, rel=1e-6)
    # coupling through the plate: each ball's first impact differs from the lone-ball impact
    alone = simulate_coupled(balls[:1], basis, [law], 2e-3)
    both = res.impacts_of("L")[0]
    assert both.peak_force != pytest.approx(alone.impacts[0].peak_force, rel=1e-6)
