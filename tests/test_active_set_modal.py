"""The active set's two-way modal plate block against independent truths.

Plate: the closed-form simply supported Kirchhoff modes below 5 kHz
(tailbeam.plate.closed_forms, 52 modes of the 0.6 x 0.6 x 0.01 m steel plate), so no FE solve is
involved. Truths: the two-way coupled single-ball solver
(tailbeam.solvers.coupled.simulate_coupled, an independent integrator: exact modal propagation
under piecewise-linear forces, 2nd order in its step) without residual flexibility; the exact
damped modal propagator (tailbeam.solvers.plate_loads.propagator); conservation of energy. The
rigid path (no modes) is checked bit for bit by the unchanged tests/test_active_set.py.
"""

import numpy as np
import pytest

from tailbeam.errors import InputError
from tailbeam.physics.bodies import Ball, Plate
from tailbeam.physics.contact_law import ball_plate_law, elastic_energy
from tailbeam.physics.materials import COAL, SANDSTONE
from tailbeam.plate.closed_forms import ssss_kirchhoff_basis
from tailbeam.results.records import EventCode
from tailbeam.solvers.coupled import simulate_coupled
from tailbeam.solvers.plate_loads import propagator
from tailbeam.solvers.stream.active.integrator.set import ActiveSet

R = 0.03
G = 9.81
PLATE = Plate()
BASIS = ssss_kirchhoff_basis(PLATE, 5000.0)
XY = (0.07, -0.05)  # off the centre and off the nodal lines: many modes take part
ZETA = 0.01


def _modal_set(ball, law, *, zeta, rtol=1e-12, g=G, **kwargs):
    m = BASIS.n_modes
    return ActiveSet(
        [ball.position], [ball.velocity], [ball.mass], [ball.radius], [(0, -1)], [law],
        (0.0, 0.0, -g), (0.3, 0.3), rtol=rtol, omega=BASIS.omega, zeta=np.full(m, zeta),
        phi=BASIS.deflection(np.array([ball.position[:2]])), **kwargs,
    )  # fmt: skip


def _coupled(ball, law, steps_per_contact):
    """(t_end, v_out, peak, max penetration), q and q' at t_end of the first contact."""
    res = simulate_coupled(
        [ball], BASIS, [law], 1e-3, gravity=G, damping_ratio=ZETA,
        residual_flexibility=False, steps_per_contact=steps_per_contact,
    )  # fmt: skip
    imp = res.impacts[0]
    q, qd, _ = res.plate.modal_sample([imp.t_end])
    return (np.array([imp.t_end, imp.v_out, imp.peak_force, imp.max_penetration]), q[:, 0],
            qd[:, 0])  # fmt: skip


@pytest.mark.parametrize("damping", [0.0, 800.0])
def test_single_ball_matches_the_coupled_solver(damping):
    # Sandstone at 2 m/s on the modal plate (c = 0, and c = 800 with the ramp and the clamp:
    # kinks inside the contact). The coupled solver is 2nd order in its step: its values at
    # 800 and 1600 steps per contact are Richardson-extrapolated; |x1600 - x800| measures how
    # far the coupled solver still is from its limit. Measured (c = 0 / c = 800, rtol 1e-12):
    # t_end, v_out, peak within 6.6e-10, 8.0e-10, 2.3e-9 / 4.1e-10, 1.8e-10, 2.8e-9 (relative)
    # of the extrapolation, 40-7000x closer than |x1600 - x800| (3.7e-8 ... 1.3e-6); modal
    # state q, q' within 1.7e-9, 4.2e-9 / 1.1e-9, 3.7e-9 (norm), 390-540x closer than
    # |x1600 - x800|; max penetration (the coupled solver's maximum over its nodes, not
    # extrapolable) within 1.5e-7 / 2.8e-8 of its 1600-step value.
    ball = Ball("s", SANDSTONE, R, (XY[0], XY[1], R + 1e-4), (0.0, 0.0, -2.0))
    law = ball_plate_law(SANDSTONE, R, PLATE.material, damping=damping)
    s = _modal_set(ball, law, zeta=ZETA)
    start = s.advance(0.0, 1e-3)
    end = s.advance(start.t, 1e-3)
    assert (start.code, end.code) == (EventCode.CONTACT_START, EventCode.CONTACT_END)
    if damping > 0:
        assert [k for _, k, _ in s.kink_log()][:1] == ["full_damping"]
    ours = np.array([end.t, s.v[0, 2], s.contacts.peak[0], s.contacts.pen[0]])
    a, qa, qda = _coupled(ball, law, 800)
    b, qb, qdb = _coupled(ball, law, 1600)
    extrap = b + (b - a) / 3.0
    rel = np.abs(ours - extrap)[:3] / np.abs(extrap[:3])
    spread = np.abs(b - a)[:3] / np.abs(extrap[:3])
    assert np.all(rel < 6e-9) and np.all(rel < 0.05 * spread)
    assert abs(ours[3] / b[3] - 1.0) < 1e-6
    for mine, xa, xb in ((s.q, qa, qb), (s.qd, qda, qdb)):
        x = xb + (xb - xa) / 3.0
        err, spread = np.linalg.norm(mine - x), np.linalg.norm(xb - xa)
        assert err < 1e-8 * np.linalg.norm(x) and err < 0.01 * spread


def _records(s, t_stop):
    """{ball: [t_start, t_end, v_out, peak, max penetration]} of the first contact of each."""
    out, t = {}, 0.0
    while True:
        o = s.advance(t, t_stop)
        t = o.t
        if o.code == EventCode.NONE:
            return out
        assert o.code in (EventCode.CONTACT_START, EventCode.CONTACT_END)
        b = int(s.model.pi[o.index])
        if o.code == EventCode.CONTACT_START:
            out[b] = [o.t]
        else:
            out[b] += [o.t, s.v[b, 2], s.contacts.peak[o.index], s.contacts.pen[o.index]]


def test_two_balls_share_the_modes_as_in_the_coupled_solver():
    # A sandstone and a coal ball strike at two points; the second lands 83 us after the first,
    # on a plate already moved by it (its start is 7.6e-8 s earlier than over the rigid plate).
    # Every record of both against the coupled solver (Richardson, as above). Measured: start
    # times within 7e-15 s (the start dead band); end, v_out, peak within 6.3e-10, 4.6e-9,
    # 2.8e-9 (relative) of the (800, 1600) extrapolation, 99-800x closer than |x1600 - x800|;
    # the (1600, 3200) extrapolation (not run here) comes within 2.8e-10, 7.2e-10: what is
    # left is the reference's. Max penetration within 4.7e-7 of the 1600-step value.
    balls = [
        Ball("A", SANDSTONE, R, (XY[0], XY[1], R + 1e-4), (0.0, 0.0, -2.0)),
        Ball("B", COAL, 0.025, (-0.1, 0.12, 0.025 + 2e-4), (0.0, 0.0, -1.5)),
    ]
    laws = [ball_plate_law(b.material, b.radius, PLATE.material, damping=0.0) for b in balls]
    m = BASIS.n_modes
    s = ActiveSet(
        [b.position for b in balls], [b.velocity for b in balls], [b.mass for b in balls],
        [b.radius for b in balls], [(0, -1), (1, -1)], laws, (0.0, 0.0, -G), (0.3, 0.3),
        rtol=1e-12, omega=BASIS.omega, zeta=np.full(m, ZETA),
        phi=BASIS.deflection(np.array([b.position[:2] for b in balls])),
    )  # fmt: skip
    ours = _records(s, 6e-4)
    ref = []
    for spc in (800, 1600):
        res = simulate_coupled(
            balls, BASIS, laws, 6e-4, gravity=G, damping_ratio=ZETA,
            residual_flexibility=False, steps_per_contact=spc,
        )  # fmt: skip
        ref.append({imp.ball: [imp.t_start, imp.t_end, imp.v_out, imp.peak_force,
                               imp.max_penetration] for imp in res.impacts})  # fmt: skip
    t_rigid = (-1.5 + np.sqrt(1.5**2 + 2 * G * 2e-4)) / G
    assert t_rigid - ours[1][0] > 5e-8  # B touched a plate moving up towards it
    for b, ball in enumerate(balls):
        a, c = np.array(ref[0][ball.name]), np.array(ref[1][ball.name])
        extrap = c + (c - a) / 3.0
        mine = np.array(ours[b])
        rel = np.abs(mine - extrap)[1:4] / np.abs(extrap[1:4])
        assert abs(mine[0] - extrap[0]) < 2e-14  # (the start dead band: delta ~ 1.5e-14 m)
        assert np.all(rel < 5e-9) and np.all(rel < 0.05 * np.abs(c - a)[1:4] / np.abs(c[1:4]))
        assert abs(mine[4] / c[4] - 1.0) < 1e-6


def _free_modes(rtol, q0, qd0, zeta, f_dead):
    ball = Ball("far", COAL, R, (0.0, 0.0, 0.5), (0.0, 0.0, 0.0))
    s = ActiveSet(
        [ball.position], [ball.velocity], [ball.mass], [R], [(0, -1)],
        [ball_plate_law(COAL, R, PLATE.material)], (0.0, 0.0, 0.0), (0.3, 0.3), rtol=rtol,
        omega=BASIS.omega, zeta=zeta, q=q0, qd=qd0, phi=BASIS.deflection(np.zeros((1, 2))),
        f_dead=f_dead,
    )  # fmt: skip
    out = s.advance(0.0, 0.02)
    assert out.code == EventCode.NONE and out.t == 0.02
    return s


def test_free_modes_follow_the_exact_propagator():
    # No contact (ball far above, no gravity): the modes under a constant dead load, damped,
    # from a non-zero state, over 20 ms (100 periods of the top mode) against the exact damped
    # propagation. Measured relative errors (norm) of q / q': 7.6e-8 / 4.5e-7 at rtol 1e-10
    # (449 steps), 7.8e-9 / 4.5e-8 at 1e-11 (597 steps): order 1 in rtol.
    m = BASIS.n_modes
    rng = np.random.default_rng(7)
    q0, qd0 = rng.normal(0, 1e-5, m), rng.normal(0, 1e-2, m)
    f_dead = rng.normal(0, 1.0, m)
    zeta = np.linspace(0.005, 0.05, m)
    coef = np.zeros((8, m))
    propagator.coefficients(BASIS.omega, zeta, 0.02, coef)
    q, qd = np.zeros(m), np.zeros(m)
    propagator.advance(coef, q0, qd0, f_dead, f_dead, q, qd)
    errors = []
    for rtol in (1e-10, 1e-11):
        s = _free_modes(rtol, q0, qd0, zeta, f_dead)
        assert s.stats["steps"] > 400
        errors.append([np.linalg.norm(s.q - q) / np.linalg.norm(q),
                       np.linalg.norm(s.qd - qd) / np.linalg.norm(qd)])  # fmt: skip
    errors = np.array(errors)
    assert np.all(errors[1] < [3e-8, 2e-7])
    assert np.all(errors[1] < errors[0] / 5.0)  # converges with rtol


def _energy(s, ball, law, g):
    """Ball kinetic + potential + contact elastic + modal (kinetic + strain - dead-load work)."""
    delta, _ = s.penetration(0)
    elastic = elastic_energy(max(delta, 0.0), law) if s.contacts.touching[0] else 0.0
    return (0.5 * ball.mass * s.v[0] @ s.v[0] + ball.mass * g * s.x[0, 2] + elastic
            + s.modal_energy() - s.model.f_dead @ s.q)  # fmt: skip


def test_energy_is_conserved_without_damping():
    # c = 0, zeta = 0, a dead load on the modes and a strong field g = 200 m/s^2 (any constant
    # field is conservative; it makes the flights short): the ball bounces 7 times in 30 ms on
    # the vibrating plate, which ends with about as much energy as the ball had. Total energy
    # at every return and every 0.5 ms: measured drift of the initial kinetic energy 2.4e-8 /
    # 1.8e-9 / 1.4e-10 at rtol 1e-10 / 1e-11 / 1e-12 (falls with rtol).
    g = 200.0
    ball = Ball("s", SANDSTONE, R, (XY[0], XY[1], R + 1e-3), (0.0, 0.0, -1.5))
    law = ball_plate_law(SANDSTONE, R, PLATE.material, damping=0.0)
    f_dead = np.full(BASIS.n_modes, 0.3)
    s = _modal_set(ball, law, zeta=0.0, rtol=1e-12, g=g, f_dead=f_dead)
    e0 = _energy(s, ball, law, g)
    scale = 0.5 * ball.mass * 1.5**2
    t, kinds, drift, modal_max = 0.0, [], 0.0, 0.0
    while t < 0.03:
        out = s.advance(t, min(t + 5e-4, 0.03))
        t = out.t
        kinds.append(out.code)
        drift = max(drift, abs(_energy(s, ball, law, g) - e0) / scale)
        modal_max = max(modal_max, s.modal_energy() / scale)
    assert kinds.count(EventCode.CONTACT_END) >= 5
    assert modal_max > 0.5  # the plate really takes part
    assert drift < 1e-9


def _modes_from_rows(s, zeta):
    """q, q' after driving the modes (from rest) with the set's plate force rows, linear in
    time between rows, by the exact propagator."""
    rows = s.force_rows()
    order = np.argsort(rows[:, 0], kind="stable")
    t, f = rows[order, 0], rows[order, 2]
    m = BASIS.n_modes
    q, qd, q1, qd1, coef = np.zeros(m), np.zeros(m), np.zeros(m), np.zeros(m), np.zeros((8, m))
    for k in range(len(t) - 1):
        if t[k + 1] > t[k]:
            propagator.coefficients(BASIS.omega, zeta, t[k + 1] - t[k], coef)
            propagator.advance(
                coef, q, qd, -s.model.phi[0] * f[k], -s.model.phi[0] * f[k + 1], q1, qd1
            )
            q, qd = q1.copy(), qd1.copy()
    return q, qd


def test_force_rows_drive_the_modes_as_inside_the_set():
    # The plate force rows (for the sensors) replayed through the exact propagator give the
    # set's own modal state after the contact, up to their linear interpolation: measured
    # 1.05e-5 / 7.6e-7 (q, relative norm) with 10 / 40 nodes per step, a ratio of 13.9 =
    # (41 / 11)^2: second order in the row spacing (c = 800: ramp and clamp kinks included).
    ball = Ball("s", SANDSTONE, R, (XY[0], XY[1], R + 1e-4), (0.0, 0.0, -2.0))
    law = ball_plate_law(SANDSTONE, R, PLATE.material, damping=800.0)
    zeta = np.full(BASIS.n_modes, ZETA)
    errors = []
    for nodes in (10, 40):
        s = _modal_set(ball, law, zeta=ZETA, nodes_per_step=nodes)
        start = s.advance(0.0, 1e-3)
        assert s.advance(start.t, 1e-3).code == EventCode.CONTACT_END
        q, qd = _modes_from_rows(s, zeta)
        errors.append([np.linalg.norm(q - s.q) / np.linalg.norm(s.q),
                       np.linalg.norm(qd - s.qd) / np.linalg.norm(s.qd)])  # fmt: skip
    errors = np.array(errors)
    assert np.all(errors[1] < 3e-6)
    assert np.all(errors[0] / errors[1] > 10.0)  # (41 / 11)^2 = 13.9


def test_bad_modal_input_names_the_argument():
    law = ball_plate_law(COAL, R, PLATE.material)
    args = ([[0, 0, 0.1]], [[0, 0, 0]], [1.0], [R], [(0, -1)], [law], (0, 0, -G), (0.3, 0.3))
    with pytest.raises(InputError, match="phi"):
        ActiveSet(*args, omega=[100.0, 200.0], phi=np.zeros((1, 3)))
    with pytest.raises(InputError, match="zeta"):
        ActiveSet(*args, omega=[100.0], zeta=[1.5])
    with pytest.raises(InputError, match="omega"):
        ActiveSet(*args, omega=[0.0])
    with pytest.raises(InputError, match="f_dead"):
        ActiveSet(*args, f_dead=[1.0])
