"""Sparse load histories on the modal plate (tailbeam.solvers.plate_loads) against independent
truths: the dense exact replay (tailbeam.solvers.plate_loads.propagator), single-mode closed
forms, the Navier / Timoshenko static deflection, and the coupled result's own sensor path."""

import tracemalloc

import numpy as np
import pytest

from tailbeam.errors import InputError, WorkLimitError
from tailbeam.physics.bodies import Ball, Plate
from tailbeam.physics.materials import SANDSTONE
from tailbeam.plate import compute_modes
from tailbeam.plate.closed_forms import ssss_kirchhoff_basis
from tailbeam.results.result import Result
from tailbeam.signals.sensor import SensorSpec
from tailbeam.solvers.coupled.replay import ModalReplay
from tailbeam.solvers.plate_loads.forced import forced_response
from tailbeam.solvers.plate_loads.loads import PlateLoads
from tailbeam.solvers.plate_loads.response import (
    load_shapes,
    plate_response,
    sensor_outputs,
    sensor_signals,
)
from tailbeam.streams.generator import balls_as_particles

PLATE = Plate()
DT = 2.0**-17  # s; dyadic, so grid times and their differences are exact
POINTS = np.array([[0.0, 0.15], [-0.2, 0.1]])


@pytest.fixture(scope="module")
def basis():
    return ssss_kirchhoff_basis(PLATE, 10000.0)


@pytest.fixture(scope="module")
def one_mode():
    b = ssss_kirchhoff_basis(PLATE, 200.0)
    assert b.n_modes == 1
    return b


def half_sine(t_start, duration, peak, n=41):
    t = t_start + np.linspace(0.0, duration, n)
    return t, peak * np.sin(np.pi * np.linspace(0.0, 1.0, n))


def rel_err(x, ref):
    return float(np.max(np.abs(x - ref)) / np.max(np.abs(ref)))


def test_one_contact_equals_dense_replay(basis):
    times = np.arange(4000) * DT
    tn, f = half_sine(0.0011, 2.5e-4, 1500.0)
    loads = PlateLoads()
    loads.add_contact(0.11, -0.07, tn, f)
    ours = plate_response(basis, 0.01, loads, POINTS, times, quasi_static=False)
    dense_t = np.concatenate([[0.0], tn])
    dense_f = np.concatenate([[0.0], f])[:, None]
    ref = forced_response(basis, [[0.11, -0.07]], dense_t, dense_f, times, POINTS)
    for key in "wva":
        assert rel_err(ours[key], ref[key]) < 1e-12, key


@pytest.mark.parametrize("t_offset", [0.0, 5.3])
def test_many_nodes_per_sample_equal_dense_replay(basis, t_offset):
    # 400 nodes over 0.25 ms: ~12 per sample interval, chained with shared node steps. At
    # t ~ 5.3 s the rounded node times' steps differ by ~1 ulp (8.9e-16 s): node_time_ulps=0
    # places every node exactly; the default 2 ulps moves a node by <= 1.8e-15 s, a phase of
    # <= 1.1e-10 rad at the top mode (10 kHz)
    times = t_offset + np.arange(4000) * DT
    tn, f = half_sine(t_offset + 0.0011, 2.5e-4, 1500.0, n=400)
    loads = PlateLoads()
    loads.add_contact(0.11, -0.07, tn, f)
    dense_t = np.concatenate([[t_offset], tn])
    dense_f = np.concatenate([[0.0], f])[:, None]
    ref = forced_response(basis, [[0.11, -0.07]], dense_t, dense_f, times, POINTS)
    exact = plate_response(basis, 0.01, loads, POINTS, times, quasi_static=False, node_time_ulps=0)
    chained = plate_response(basis, 0.01, loads, POINTS, times, quasi_static=False)
    phase = 2 * np.pi * 1e4 * 2 * np.spacing(t_offset + 0.0011)
    for key in "wva":
        assert rel_err(exact[key], ref[key]) < 1e-12, key
        assert rel_err(chained[key], ref[key]) < max(1e-12, 2 * phase), key


def test_overlapping_loads_equal_dense_replay_and_batches_do_not_matter(basis):
    # two contacts overlapping in time and a dead load across both, at three points; the
    # dense replay takes them as three force columns on the union of their node times
    times = np.arange(3000) * DT
    pieces = [
        ((0.11, -0.07), *half_sine(0.0041, 2.5e-4, 1500.0)),
        ((-0.2, 0.05), *half_sine(0.0042, 1.3e-4, 900.0, n=17)),
        ((0.05, 0.2), np.array([0.0037, 0.0061]), np.array([60.0, 60.0])),
    ]
    loads = PlateLoads()
    loads.add_contact(*pieces[0][0], pieces[0][1], pieces[0][2])
    loads.add_contact(*pieces[1][0], pieces[1][1], pieces[1][2])
    loads.add_dead_load(*pieces[2][0], 0.0037, 0.0061, 60.0)
    # the dead load's jumps: two nodes at the same time in the dense table (replay steps over
    # the zero-length segment)
    ta, tb = 0.0037, 0.0061
    tu = np.unique(np.concatenate([[0.0], pieces[0][1], pieces[1][1]]))
    tu = np.sort(np.concatenate([tu, [ta, ta, tb, tb]]))
    cols = [np.interp(tu, p[1], p[2], left=0.0, right=0.0) for p in pieces[:2]]
    dead = np.where((tu > ta) & (tu < tb), 60.0, 0.0)
    ia, ib = np.searchsorted(tu, ta), np.searchsorted(tu, tb)
    dead[[ia, ia + 1, ib, ib + 1]] = (0.0, 60.0, 60.0, 0.0)
    cols.append(dead)
    ref = forced_response(basis, [p[0] for p in pieces], tu, np.column_stack(cols), times, POINTS)
    ours = plate_response(basis, 0.01, loads, POINTS, times, quasi_static=False)
    small = plate_response(basis, 0.01, loads, POINTS, times, quasi_static=False, batch_nodes=3)
    for key in "wva":
        assert rel_err(ours[key], ref[key]) < 1e-12, key
        assert rel_err(small[key], ours[key]) < 1e-14, key


def _one_mode_parts(b, load, point, zeta):
    om = float(b.omega[0])
    mu = om * np.sqrt(1 - zeta**2)
    phi_l = b.deflection([load])[0, 0]
    phi_p = b.deflection([point])[0, 0]
    return om, mu, phi_l, phi_p


def test_single_mode_step_and_ramp_closed_forms(one_mode):
    zeta, load, point = 0.02, (0.07, -0.03), (-0.1, 0.12)
    om, mu, phi_l, phi_p = _one_mode_parts(one_mode, load, point, zeta)
    times = np.arange(6000) * DT
    ta, tb, force, slope = 0.0031, 0.0302, 80.0, 2.0e4

    def g(s):  # unit step response x omega^2, and its derivative
        e = np.exp(-zeta * om * s)
        val = 1 - e * (np.cos(mu * s) + zeta * om / mu * np.sin(mu * s))
        return np.where(s > 0, val, 0.0), np.where(s > 0, e * om**2 / mu * np.sin(mu * s), 0.0)

    def r(s):  # unit ramp response and its derivative (textbook closed form)
        a, b = 2 * zeta / om**3, (2 * zeta**2 - 1) / (om**2 * mu)
        e = np.exp(-zeta * om * s)
        val = s / om**2 - a + e * (a * np.cos(mu * s) + b * np.sin(mu * s))
        der = 1 / om**2 + e * ((-zeta * om * a + mu * b) * np.cos(mu * s)
                                - (zeta * om * b + mu * a) * np.sin(mu * s))  # fmt: skip
        return np.where(s > 0, val, 0.0), np.where(s > 0, der, 0.0)

    inside = (times >= ta) & (times < tb)
    # step: a dead load over [ta, tb]
    (g1, dg1), (g2, dg2) = g(times - ta), g(times - tb)
    q = -phi_l * force / om**2 * (g1 - g2)
    qd = -phi_l * force / om**2 * (dg1 - dg2)
    qdd = -phi_l * force * inside - 2 * zeta * om * qd - om**2 * q
    # ramp: a contact whose force rises linearly from 0 and drops to 0 at tb
    (r1, dr1), (r2, dr2) = r(times - ta), r(times - tb)
    jump = slope * (tb - ta)
    p = -phi_l * (slope * (r1 - r2) - jump * g2 / om**2)
    pd = -phi_l * (slope * (dr1 - dr2) - jump * dg2 / om**2)
    pdd = -phi_l * slope * (times - ta) * inside - 2 * zeta * om * pd - om**2 * p
    step, ramp = PlateLoads(), PlateLoads()
    step.add_dead_load(*load, ta, tb, force)
    ramp.add_contact(*load, [ta, tb], [0.0, jump])
    for loads, truth in ((step, (q, qd, qdd)), (ramp, (p, pd, pdd))):
        ours = plate_response(one_mode, zeta, loads, [point], times, quasi_static=False)
        for key, exact in zip("wva", truth, strict=True):
            assert rel_err(ours[key][0], phi_p * exact) < 1e-12, key


def test_superposition_with_quasi_static_part(basis):
    times = np.arange(2500) * DT
    a = PlateLoads()
    a.add_contact(0.11, -0.07, *half_sine(0.004, 2.5e-4, 1500.0))
    b = PlateLoads()
    b.add_dead_load(-0.15, 0.05, 0.0045, 0.009, 40.0)
    both = PlateLoads()
    both.add_contact(0.11, -0.07, *half_sine(0.004, 2.5e-4, 1500.0))
    both.add_dead_load(-0.15, 0.05, 0.0045, 0.009, 40.0)
    ra, rb, rab = (plate_response(basis, 0.01, x, POINTS, times) for x in (a, b, both))
    for key in "wva":
        # rounding only; the residual (full static minus the kept modes' 99.5 %) amplifies it
        assert rel_err(rab[key], ra[key] + rb[key]) < 1e-12, key


def test_dead_load_settles_to_the_static_deflection(basis):
    # centre load, centre point, SSSS square plate: w = alpha F a^2 / D, alpha = 0.01160
    # (Timoshenko & Woinowsky-Krieger, Table 8); the kept modes alone settle to their static
    # part sum phi^2/omega^2, the residual adds the rest (Navier series, 1e-6)
    force, zeta = 100.0, 0.3  # slowest decay 1/(zeta omega_1) = 4 ms: gone after 0.12 s
    times = np.arange(0, 0.12, 1e-5)
    loads = PlateLoads()
    loads.add_dead_load(0.0, 0.0, 0.001, 1.0, force)
    full = plate_response(basis, zeta, loads, [[0.0, 0.0]], times)
    kept = plate_response(basis, zeta, loads, [[0.0, 0.0]], times, quasi_static=False)
    d, a = PLATE.bending_stiffness, PLATE.size_x
    assert full["w"][0, -1] == pytest.approx(-0.01160 * force * a**2 / d, rel=5e-4)
    navier = basis.static_deflection_at(np.zeros(2), np.zeros((1, 2)))[0]
    assert full["w"][0, -1] == pytest.approx(-force * navier, rel=1e-9)
    phi = basis.deflection([[0.0, 0.0]])[0]
    assert kept["w"][0, -1] == pytest.approx(-force * np.sum(phi**2 / basis.omega**2), rel=1e-9)
    assert abs(full["a"][0, -1]) < 1e-8 * np.max(np.abs(full["a"]))


def coupled_result(basis, contact, t_nodes, forces, duration, sensors=()):
    """A single-ball result holding one ball's force nodes at ``contact`` (x, y) m, residual
    flexibility on: its plate's replay and sensor outputs are the existing dense exact path."""
    tn = np.concatenate([[0.0], t_nodes, [duration]])
    fn = np.concatenate([[0.0], forces, [0.0]])[:, None]
    zeros = np.zeros_like(fn)
    phis = basis.deflection([contact])[None]
    nodes = (tn, zeros, zeros, fn, zeros)
    plate = ModalReplay(
        basis, np.full(basis.n_modes, 0.01), nodes, np.zeros(len(tn), dtype=np.int64), phis,
        ((t_nodes[0], 0, *contact, 0.0),), residual_flexibility=True,
    )  # fmt: skip
    ball = Ball("s", SANDSTONE, 0.03, (*contact, 0.1), (0.0, 0.0, 0.0))
    return Result(duration, balls_as_particles([ball]), [], [], sensors=tuple(sensors),
                  plate=plate)  # fmt: skip


def test_quasi_static_equals_the_coupled_result():
    # the same force nodes as a single-ball result (dense replay + its residual correction) and as
    # a PlateLoads piece: the same kept-mode response and the same correction at the points
    basis = ssss_kirchhoff_basis(PLATE, 5000.0)
    tn, f = half_sine(2.1e-4, 3.1e-4, 2500.0, n=60)
    res = coupled_result(basis, (0.1, -0.05), tn, f, 1e-3)
    assert res.plate.has_quasi_static
    loads = PlateLoads()
    loads.add_contact(0.1, -0.05, tn, f)
    times = np.arange(0, 1e-3, 1.0 / 102400)
    ours = plate_response(basis, res.plate.zeta, loads, POINTS, times)
    ref = res.plate.sample(times, POINTS)
    qs = res.plate.quasi_static_sample(times, POINTS)
    for key in "wva":
        assert rel_err(ours[key], ref[key]) < 1e-12, key
        assert np.max(np.abs(qs[key])) > 1e-4 * np.max(np.abs(ref[key]))  # not negligible


def test_sensor_outputs_equal_the_coupled_result_chain():
    basis = ssss_kirchhoff_basis(PLATE, 5000.0)
    sensors = (SensorSpec("a", (0.0, 0.15)), SensorSpec("b", (-0.2, 0.1), sample_rate=25600.0))
    tn, f = half_sine(2.1e-4, 3.1e-4, 2500.0, n=60)
    res = coupled_result(basis, (0.1, -0.05), tn, f, 2e-3, sensors)
    loads = PlateLoads()
    loads.add_contact(0.1, -0.05, tn, f)
    ours = sensor_outputs(basis, res.plate.zeta, loads, sensors, 2e-3)
    for name, (t, acc) in sensor_signals(ours).items():
        t_ref, acc_ref = res.sensor_signals[name]
        assert np.array_equal(t, t_ref)
        assert rel_err(acc, acc_ref) < 1e-12, name


def test_load_shapes_of_a_disc_equal_the_basis_load_deflection(basis):
    xyr = np.array([[0.1, 0.2, 0.002], [0.1, 0.2, 0.0], [0.299, -0.1, 0.003], [0.1, 0.2, 0.002]])
    ours = load_shapes(basis, xyr)
    for row, (x, y, rad) in zip(ours, xyr, strict=True):
        ref = basis.load_deflection([[x, y]], rad)[0]
        assert np.max(np.abs(row - ref)) <= 1e-13 * np.max(np.abs(ref))


def test_memory_stays_at_samples_times_points(basis):
    # 300k samples, 10k contacts: a (modes x samples) array alone would be 254 MB
    rng = np.random.default_rng(3)
    times = np.arange(300_000) / 102400.0
    loads = PlateLoads()
    for t0 in np.sort(rng.uniform(0.0, 2.9, 10_000)):
        x, y = rng.uniform(-0.28, 0.28, 2)
        loads.add_contact(x, y, *half_sine(t0, rng.uniform(1e-4, 3e-4), 1000.0, n=9))
    plate_response(basis, 0.01, loads, POINTS, times[:10], quasi_static=False)  # compile
    tracemalloc.start()
    out = plate_response(basis, 0.01, loads, POINTS, times, quasi_static=False)
    _size, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    outputs = 3 * POINTS.shape[0] * times.size * 8  # 14.4 MB
    node_tables = 40 * loads.n_nodes  # df, ds, target, sort order (+ scratch): 3.6 MB
    assert out["a"].shape == (2, 300_000)
    # + the batch's shape table (<= 4096 pieces x 106 modes: 3.5 MB). Measured 19.7 MB
    assert peak < outputs + node_tables + 4e6, peak / 1e6


def test_bad_input_is_named(basis):
    loads = PlateLoads()
    with pytest.raises(InputError, match="t_nodes"):
        loads.add_contact(0.0, 0.0, [1.0, 0.5], [1.0, 2.0])
    with pytest.raises(InputError, match="t_to"):
        loads.add_dead_load(0.0, 0.0, 1.0, 1.0, 5.0)
    loads.add_dead_load(0.0, 0.0, 0.0, 1e-3, 5.0)
    loads.add_dead_load(0.4, 0.0, 0.0, 1e-3, 5.0)
    times = np.arange(100) * DT
    with pytest.raises(InputError, match=r"loads\[1\]"):
        plate_response(basis, 0.01, loads, POINTS, times)
    good = PlateLoads()
    good.add_dead_load(0.0, 0.0, 0.0, 1e-3, 5.0)
    with pytest.raises(InputError, match="times"):
        plate_response(basis, 0.01, good, POINTS, np.array([0.0, 1e-5, 3e-5]))
    with pytest.raises(InputError, match="zeta"):
        plate_response(basis, 1.0, good, POINTS, times)
    with pytest.raises(WorkLimitError, match="max_bytes"):
        plate_response(basis, 0.01, good, POINTS, times, max_bytes=1e3)


def test_no_loads_leave_the_plate_at_rest(basis):
    out = plate_response(basis, 0.01, PlateLoads(), POINTS, np.arange(100) * DT)
    assert all(np.all(out[key] == 0.0) for key in "wva")


def test_container_grows_and_keeps_pieces():
    loads = PlateLoads()
    for k in range(200):
        loads.add_contact(0.01 * (k % 7), 0.0, [k, k + 0.5, k + 1.0], [0.0, k, 0.0], radius=1e-3)
    loads.add_dead_load(0.1, 0.2, 3.0, 4.0, 9.0)
    assert (len(loads), loads.n_nodes) == (201, 602)
    assert loads.first[-1] == 600 and loads.force[601] == 9.0 and np.isnan(loads.radius[-1])
    assert np.array_equal(loads.piece_of_node()[[0, 2, 3, 601]], [0, 0, 1, 200])
    assert loads.nbytes < 20 * 8 * 1024  # capacity doubled, not per piece


def test_quasi_static_on_an_fe_mindlin_basis_with_load_discs():
    # Mindlin FE basis (coarse mesh), loads spread over Hertz discs: the residual taken by
    # reciprocity (static solutions for unit loads at the points, disc-averaged at the loads)
    # equals the direct one (a static solution per load, ModalBasis.residual_cross_compliance)
    from tailbeam.solvers.plate_loads.response import _residual

    basis = compute_modes(PLATE, "SSSS", theory="mindlin", divisions=3, fmax_hz=3000.0)
    xyr = np.array([[0.1, -0.05, 0.002], [-0.2, 0.1, 0.0015], [0.1, -0.05, 0.002]])
    phi = load_shapes(basis, xyr)
    g = phi @ (basis.deflection(POINTS) / basis.omega**2).T
    ours = _residual(basis, xyr, POINTS, np.ones(3, dtype=bool), g)
    for row, (x, y, rad) in zip(ours, xyr, strict=True):
        ref = basis.residual_cross_compliance((x, y), POINTS, rad)
        assert np.max(np.abs(row - ref)) < 1e-9 * np.max(np.abs(ref))
        assert np.all(np.abs(ref) > 0.0)


def test_a_window_of_the_grid_equals_the_same_samples_of_the_whole_grid(basis):
    # loads that start before the first sample (propagated to it) or end after the last
    # (cut): any window of the grid gives the samples of the whole grid, correction included
    times = np.arange(3000) * DT
    loads = PlateLoads()
    loads.add_contact(0.11, -0.07, *half_sine(0.0081, 2.5e-4, 1500.0))
    loads.add_contact(-0.2, 0.05, *half_sine(0.0175, 3e-4, 900.0))
    loads.add_dead_load(0.05, 0.2, 0.004, 0.02, 60.0)
    whole = plate_response(basis, 0.01, loads, POINTS, times)
    cut = slice(1070, 2310)  # inside the first contact ... inside the second
    window = plate_response(basis, 0.01, loads, POINTS, times[cut])
    for key in "wva":
        assert rel_err(window[key], whole[key][:, cut]) < 1e-12, key
