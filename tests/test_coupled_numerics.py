"""Numerics of the coupled solver: exact modal propagation vs independent integrators,
convergence orders, stability, bad input."""

import dataclasses

import numpy as np
import pytest
from scipy import signal
from scipy.integrate import solve_ivp
from scipy.sparse.linalg import splu

from tailbeam.errors import InputError, WorkLimitError
from tailbeam.physics.bodies import Ball, Plate
from tailbeam.physics.contact_law import ball_plate_law
from tailbeam.physics.materials import CARBON_STEEL, COAL, SANDSTONE
from tailbeam.plate import assemble_plate, compute_modes
from tailbeam.plate.basis import modal_damping
from tailbeam.plate.closed_forms import ssss_kirchhoff_basis
from tailbeam.signals.sensor import SensorSpec
from tailbeam.solvers.coupled import simulate_coupled
from tailbeam.solvers.plate_loads.forced import forced_response

R = 0.03
LOAD, SENSOR = (0.07, -0.04), (-0.12, 0.15)


def _half_sine(t, t0=1e-4, width=2.5e-4, peak=1000.0):
    s = (t - t0) / width
    return np.where((s > 0) & (s < 1), peak * np.sin(np.pi * np.clip(s, 0, 1)), 0.0)


def test_forced_modal_response_matches_solve_ivp_on_the_modal_odes():
    # Exact propagation under a piecewise-linear force vs DOP853 at rtol 1e-11 on the same
    # modal ODEs (with the same piecewise-linear force): 1e-13 measured, 1e-8 asked.
    basis = ssss_kirchhoff_basis(Plate(), 6000.0)
    zeta = 0.02
    tn = np.linspace(0.0, 6e-3, 6001)
    fn = _half_sine(tn)
    times = np.linspace(0.0, 6e-3, 1201)
    ours = forced_response(basis, [LOAD], tn, fn, times, [SENSOR], damping_ratio=zeta)["a"][0]
    om = basis.omega
    phi_l = basis.deflection([LOAD])[0]
    phi_s = basis.deflection([SENSOR])[0]
    n = basis.n_modes

    def rhs(t, y):
        f = -phi_l * np.interp(t, tn, fn)
        q, qd = y[:n], y[n:]
        return np.concatenate([qd, f - 2 * zeta * om * qd - om**2 * q])

    sol = solve_ivp(rhs, (0, 6e-3), np.zeros(2 * n), method="DOP853", rtol=1e-11, atol=1e-16,
                    t_eval=times, max_step=1e-6)  # fmt: skip
    acc = np.array([phi_s @ rhs(t, y)[n:] for t, y in zip(sol.t, sol.y.T, strict=True)])
    err = np.sqrt(np.mean((ours - acc) ** 2)) / np.sqrt(np.mean(acc**2))
    assert err < 1e-8


@pytest.mark.parametrize(
    "band_hz, fmax_hz, dt",
    [(2000.0, 8000.0, 2e-6), (20000.0, 80000.0, 2.5e-7)],  # 20 kHz: the default sensor's band
)
def test_forced_modal_response_matches_newmark_on_the_fe_model(band_hz, fmax_hz, dt):
    # The FE modal basis (Argyris Kirchhoff, coarse 8x8 mesh) vs Newmark average acceleration
    # on the assembled K, M of the same mesh, undamped: the sensor's acceleration in its band
    # (zero-phase low-pass) agrees within 1 %. Modes to 4x the band; Newmark's period error
    # (omega dt)^2/12 stays < 1e-4 at the band edge.
    plate = Plate()
    basis = compute_modes(plate, "SSSS", theory="kirchhoff", divisions=8,
                          fmax_hz=fmax_hz, use_cache=False)  # fmt: skip
    model = assemble_plate(plate, "SSSS", theory="kirchhoff", divisions=8)
    t_end = 8e-3
    times = np.arange(int(round(t_end / dt)) + 1) * dt
    K, M = model.stiffness.tocsc(), model.mass.tocsc()
    load = -np.asarray(model.load_vector(LOAD, 0.0))  # pressing down (-z)
    out_op = model.deflection_operator([SENSOR])
    lu = splu((M + 0.25 * dt**2 * K).tocsc())
    u = np.zeros(K.shape[0])
    v = np.zeros_like(u)
    a = np.zeros_like(u)
    acc_fe = np.zeros(len(times))
    force = _half_sine(times)
    for i in range(1, len(times)):
        u_pred = u + dt * v + 0.25 * dt**2 * a
        a_new = lu.solve(load * force[i] - K @ u_pred)
        v = v + 0.5 * dt * (a + a_new)
        u = u_pred + 0.25 * dt**2 * a_new
        a = a_new
        acc_fe[i] = (out_op @ a)[0]
    ours = forced_response(basis, [LOAD], times, force, times, [SENSOR], damping_ratio=0.0)["a"][0]
    sos = signal.butter(6, band_hz, fs=1 / dt, output="sos")
    fe_band = signal.sosfiltfilt(sos, acc_fe)
    our_band = signal.sosfiltfilt(sos, ours)
    err = np.sqrt(np.mean((our_band - fe_band) ** 2)) / np.sqrt(np.mean(fe_band**2))
    assert err < 0.01


def _impact(steps, residual=True, fmax=10000.0, damping=800.0):
    basis = ssss_kirchhoff_basis(Plate(), fmax)
    ball = Ball("b", COAL, R, (0.05, 0.02, R + 1e-4), (0.0, 0.0, -1.0))
    law = ball_plate_law(COAL, R, CARBON_STEEL, damping=damping)
    res = simulate_coupled([ball], basis, [law], 1e-3, steps_per_contact=steps,
                           residual_flexibility=residual)  # fmt: skip
    imp = res.impacts[0]
    # the integrator's order is measured on the kept modes: the truncated modes' quasi-static
    # term is a post-processing of the same forces whose full-band 1 us samples resolve the
    # kinks of the piecewise-linear force (its in-band convergence: tests/test_coupled_fe.py)
    times = np.linspace(0, 1e-3, 1001)
    acc = res.plate.sample(times, [SENSOR], quasi_static=False)["a"][0]
    return np.array([imp.restitution, imp.peak_force, imp.t_end - imp.t_start]), acc


def test_time_step_convergence_is_second_order():
    ref, acc_ref = _impact(3200)
    errs = []
    for steps in (25, 50, 100):
        val, acc = _impact(steps)
        e_acc = np.sqrt(np.mean((acc - acc_ref) ** 2) / np.mean(acc_ref**2))
        errs.append(max(np.max(np.abs(val / ref - 1)), e_acc))
    orders = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(orders > 1.8), orders
    assert errs[-1] < 2e-3  # 100 steps per contact: < 0.2 % in every measure


def test_stability_with_modes_to_50khz_and_near_zero_damping():
    # 500+ modes up to 50 kHz, damping ratio 1e-7: exact propagation stays bounded and after the
    # impact the plate's vibration energy is conserved (it may only decay by zeta*omega*t).
    plate = Plate()
    basis = ssss_kirchhoff_basis(plate, 50000.0)
    assert basis.n_modes > 500 and basis.frequencies_hz[-1] > 45000.0
    ball = Ball("b", SANDSTONE, R, (0.05, 0.02, R + 1e-4), (0.0, 0.0, -2.0))
    law = ball_plate_law(SANDSTONE, R, CARBON_STEEL)
    res = simulate_coupled([ball], basis, [law], 0.02, damping_ratio=1e-7, gravity=0.0)
    assert len(res.impacts) == 1
    t_after = res.impacts[0].t_end
    energy = res.plate.energy(np.linspace(t_after, 0.02, 50))
    assert np.all(np.isfinite(energy))
    assert np.max(np.abs(energy / energy[0] - 1)) < 1e-4
    loss = 0.5 * ball.mass * (2.0**2 - res.impacts[0].v_out ** 2)
    assert energy[0] == pytest.approx(loss, rel=1e-3)  # c = 800 N s/m takes the rest


def test_bad_input_is_named():
    basis = ssss_kirchhoff_basis(Plate(), 2000.0)
    ball = Ball("b", COAL, R, (0.0, 0.0, 0.05))
    law = ball_plate_law(COAL, R, CARBON_STEEL)
    with pytest.raises(InputError, match="laws"):
        simulate_coupled([ball], basis, [], 0.1)
    with pytest.raises(InputError, match="duration"):
        simulate_coupled([ball], basis, [law], -1.0)
    with pytest.raises(InputError, match="plate.coupling"):
        simulate_coupled([ball], basis, [law], 0.1, coupling="both")
    with pytest.raises(InputError, match="plate.damping_ratio"):
        simulate_coupled([ball], basis, [law], 0.1, damping_ratio=-0.1)
    with pytest.raises(InputError, match=r"sensors\[far\].position"):
        simulate_coupled([ball], basis, [law], 0.1, sensors=(SensorSpec("far", (1.0, 0.0)),))
    free = dataclasses.replace(basis, static_compliance_at=None)
    with pytest.raises(InputError, match="plate.residual_flexibility"):
        simulate_coupled([ball], free, [law], 0.1)
    with pytest.raises(WorkLimitError, match="max_steps"):
        simulate_coupled([ball], basis, [law], 0.1, max_steps=10)


def test_mesh_convergence_of_the_fe_basis_towards_the_exact_modes():
    # The same impact on FE Kirchhoff bases (plate helper, Argyris) of 4, 6, 8 divisions versus
    # the exact closed-form modes; the first 39 modes each (39 ends a degenerate pair, so both
    # bases span the same modes) and no residual, so only the mode shapes/frequencies differ.
    # Measured restitution errors 6.2e-3, 1.2e-3, 5.1e-4 (order ~3-4).
    plate = Plate()
    ball = Ball("b", SANDSTONE, R, (0.05, 0.02, R + 1e-4), (0.0, 0.0, -1.0))
    law = ball_plate_law(SANDSTONE, R, CARBON_STEEL)
    kw = {"gravity": 0.0, "damping_ratio": 0.0, "residual_flexibility": False}
    exact_basis = ssss_kirchhoff_basis(plate, 8000.0).truncated(count=39)
    exact = simulate_coupled([ball], exact_basis, [law], 1e-3, **kw).impacts[0]
    errs = []
    for div in (4, 6, 8):
        basis = compute_modes(plate, "SSSS", theory="kirchhoff", divisions=div, count=39,
                              use_cache=False)  # fmt: skip
        imp = simulate_coupled([ball], basis, [law], 1e-3, **kw).impacts[0]
        errs.append(abs(imp.restitution / exact.restitution - 1))
    order = np.log(errs[0] / errs[1]) / np.log(6 / 4)
    assert errs[2] < errs[1] < errs[0]
    assert order > 2.0
    assert errs[2] < 1e-3


def test_lateral_motion_and_leaving_the_plate():
    # A ball moving sideways hits where it is at contact time; one starting beyond the edge and
    # one that leaves the plate before landing never touch it (they fall past).
    basis = ssss_kirchhoff_basis(Plate(), 3000.0)
    law = ball_plate_law(COAL, R, CARBON_STEEL)
    moving = Ball("m", COAL, R, (0.0, 0.0, R + 0.01), (0.5, 0.0, -1.0))
    outside = Ball("o", COAL, R, (0.4, 0.0, R + 0.01), (0.0, 0.0, -1.0))
    leaving = Ball("l", COAL, R, (0.29, 0.0, R + 0.01), (1.0, 0.0, 0.0))
    res = simulate_coupled([moving, outside, leaving], basis, [law] * 3, 0.06)
    first = res.impacts_of("m")[0]
    x_hit = 0.5 * first.t_start
    # the contact point's plate deflection is what the ball saw: delta = 0 at contact start
    w = res.plate.sample([first.t_start], [(x_hit, 0.0)])["w"][0, 0]
    z = res.sample([first.t_start])["m"]["z"][0]
    assert z - R - w == pytest.approx(0.0, abs=1e-12)
    assert res.impacts_of("o") == [] and res.impacts_of("l") == []
    assert res.sample([0.06])["o"]["z"][0] < 0.0  # fell past the plate


def test_slow_chatter_comes_to_rest():
    # A ball dropped from 1 mm bounces a few times and is declared at rest (rebound < 1 cm/s);
    # from then on it loads the plate with its weight: the plate settles at the static deflection
    # m g C_static (Navier series), the independent truth.
    plate = Plate()
    basis = ssss_kirchhoff_basis(plate, 4000.0)
    law = ball_plate_law(COAL, R, CARBON_STEEL, damping=800.0)
    ball = Ball("b", COAL, R, (0.1, 0.05, R + 1e-3), (0.0, 0.0, 0.0))
    res = simulate_coupled([ball], basis, [law], 1.0, damping_ratio=0.05)
    t_rest = res.states.rest_time["b"]
    assert 0.0 < t_rest < 0.9 and res.impacts_of("b")[-1].ends_at_rest
    # no contact was missed: outside the located contacts the ball never overlaps the plate
    t = np.linspace(0.0, t_rest, 200001)
    inside = np.zeros(t.shape, dtype=bool)
    for imp in res.impacts_of("b"):
        inside |= (t >= imp.t_start) & (t <= imp.t_end)
    gap = res.sample(t)["b"]["z"] - R - res.plate.sample(t, [(0.1, 0.05)])["w"][0]
    assert len(res.impacts_of("b")) > 5 and np.min(gap[~inside]) > -1e-12
    # the kept modes carry m g sum phi^2/omega^2; the truncated modes' quasi-static part adds
    # the rest of the full static deflection (residual flexibility is on)
    w_end = res.plate.sample([1.0], [(0.1, 0.05)])
    phi = basis.deflection([(0.1, 0.05)])[0]
    static_modal = -ball.mass * 9.80665 * np.sum(phi**2 / basis.omega**2)
    kept = res.plate.sample([1.0], [(0.1, 0.05)], quasi_static=False)["w"][0, 0]
    assert kept == pytest.approx(static_modal, rel=1e-3)
    static_full = -ball.mass * 9.80665 * basis.static_compliance_at([(0.1, 0.05)])[0]
    assert w_end["w"][0, 0] == pytest.approx(static_full, rel=1e-3)


def test_rayleigh_damping_ratios():
    omega = np.array([100.0, 1000.0, 10000.0])
    zeta = modal_damping(omega, rayleigh=(20.0, 1e-6))
    np.testing.assert_allclose(zeta, 20.0 / (2 * omega) + 0.5e-6 * omega, rtol=1e-15)
    np.testing.assert_array_equal(modal_damping(omega, 0.02), [0.02] * 3)
    with pytest.raises(InputError, match="plate.rayleigh"):
        modal_damping(omega, rayleigh=(-1.0, 0.0))
