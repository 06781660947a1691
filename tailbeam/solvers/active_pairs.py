"""Compiled (numba) pair physics of the active-set integrator: the IMPACT law region by region,
pair kinematics, the right-hand side and the watched (event) functions.

Plate frame (``tailbeam.physics.incline``): x downhill, z the plate normal, plate surface
z = 0. State vector y (N,) = [x (n, 3) | v (n, 3) | q (m,) | q' (m,)] flattened (m, m/s, and
the optional modal block: m mass-normalised plate modes, q in m sqrt(kg), q' in m sqrt(kg)/s;
m = 0 for the rigid plate). A pair p is (pi[p], pj[p]); pj = -1 is the plate, seen as a
partner of radius 0 at the foot point (x, y, w) (``tailbeam.physics.pair``), w = phi[p] . q
the plate deflection under the ball (phi (P, m): mode shapes at each plate pair's contact
point, 1/sqrt(kg); rows of ball-ball pairs unused):

    ball-ball:  delta = r_i + r_j - |x_i - x_j|,  n = (x_i - x_j) / |x_i - x_j|
    ball-plate: delta = r_i - (z_i - w),          n = (0, 0, 1), rate with w' = phi[p] . q'

Modes: q'' + 2 zeta omega q' + omega^2 q = f_dead - sum over touching plate pairs phi[p] F_p
(F_p on the ball along +z, its reaction -F_p on the plate). No residual flexibility of the
truncated modes.
    rate = -(v_i - v_j) . n  (> 0 approaching); force F n on i, -F n on j (frictionless).

``law`` (P, 5) columns: stiffness k (N/m^e), exponent e, damping c (N s/m), penetration d (m),
clamp (0/1), built by ``contact_law.ball_ball_law`` / ``ball_plate_law``. The law itself
(``region_force``, ``clamp_indicator``, ``elastic_energy``) is ``tailbeam.physics.impact``'s,
the one definition every solver uses.

Watched functions ("rows"), as in ``stream_reference._Reference.rows``: value g = sign x f +
band, its event where g becomes negative:

    R_CONTACT  f = |x_i - x_j|^2 - (r_i + r_j)^2 (plate: (z - w)^2 - r^2), + (start) / - (end)
    R_FULL     f = |x_i - x_j|^2 - (r_i + r_j - d)^2, sign + in the ramp (delta -> d), else -
    R_CLAMP    f = clamp indicator (not polynomial), sign + unclamped, - clamped
    R_EDGE     f = edge distance of ball b (x + a/2, a/2 - x, y + b/2, b/2 - y), row 4 b + edge

bands 1e-12 (r_i + r_j)^2 (contacts, full damping), 1e-10 (clamp), 1e-13 m (edges): a
grazing touch does not start and end contacts over and over at round-off level.
"""

import math

from tailbeam.physics.impact import (
    clamp_indicator,
    elastic_energy,
    region_force,
)
from tailbeam.physics.impact import power as _pow  # noqa: F401  (the names callers use)
from tailbeam.physics.impact import region_damping as damping_in_region  # noqa: F401
from tailbeam.solvers.jit import helper_njit

L_K, L_E, L_C, L_D, L_CLAMP = range(5)
R_CONTACT, R_FULL, R_CLAMP, R_EDGE = range(4)
CLAMP_BAND = 1e-10
EDGE_BAND = 1e-13


@helper_njit
def plate_deflection(y, n, phi, p):
    """(w m, w' m/s) of the plate under plate pair p: phi[p] . q and phi[p] . q' (exactly 0.0
    without modes)."""
    nm = phi.shape[1]
    off = 6 * n
    w = 0.0
    wd = 0.0
    for k in range(nm):
        w += phi[p, k] * y[off + k]
        wd += phi[p, k] * y[off + nm + k]
    return w, wd


@helper_njit
def pair_state(y, n, i, j, rsum, phi, p):
    """(delta, rate, nx, ny, nz) of pair p = (i, j) at state y (j < 0: the plate, deflected by
    ``plate_deflection``)."""
    xi = 3 * i
    vi = 3 * n + 3 * i
    if j < 0:
        w, wd = plate_deflection(y, n, phi, p)
        return rsum - (y[xi + 2] - w), -(y[vi + 2] - wd), 0.0, 0.0, 1.0
    xj = 3 * j
    vj = 3 * n + 3 * j
    dx = y[xi] - y[xj]
    dy = y[xi + 1] - y[xj + 1]
    dz = y[xi + 2] - y[xj + 2]
    dist = math.sqrt(dx * dx + dy * dy + dz * dz)
    nx, ny, nz = dx / dist, dy / dist, dz / dist
    wn = (y[vi] - y[vj]) * nx + (y[vi + 1] - y[vj + 1]) * ny + (y[vi + 2] - y[vj + 2]) * nz
    return rsum - dist, -wn, nx, ny, nz


@helper_njit
def pair_force(y, n, p, pi, pj, law, rsum, ramp, clamped, phi):
    """(F, delta, nx, ny, nz) of pair p in its region at state y."""
    delta, rate, nx, ny, nz = pair_state(y, n, pi[p], pj[p], rsum[p], phi, p)
    f = region_force(
        delta, rate, law[p, L_K], law[p, L_E], law[p, L_C], law[p, L_D], ramp[p], clamped[p]
    )
    return f, delta, nx, ny, nz


@helper_njit
def plate_force(p, z, vz, w, wd, law, rsum, ramp, clamped):
    """(F N, delta m) of plate pair p in its region from the ball's height z (m) and speed vz
    (m/s) and the plate's deflection w (m) and velocity wd (m/s) under it."""
    delta = rsum[p] - (z - w)
    f = region_force(
        delta, -(vz - wd), law[p, L_K], law[p, L_E], law[p, L_C], law[p, L_D], ramp[p], clamped[p]
    )
    return f, delta


@helper_njit
def rhs_arrays(y, mass, g, pi, pj, law, rsum, touching, ramp, clamped, alive, omega, zeta,
               phi, fdead, out):  # fmt: skip
    """dy/dt of the active set: gravity on every present ball plus the touching pairs, and the
    modes (``_modal_rhs``). (Arrays passed one by one: unpacking the model tuple on every call
    costs more than the right-hand side of a small set.)"""
    n = mass.shape[0]
    for b in range(n):
        for k in range(3):
            out[3 * b + k] = y[3 * n + 3 * b + k] if alive[b] else 0.0
            out[3 * n + 3 * b + k] = g[k] if alive[b] else 0.0
    _modal_rhs(y, n, omega, zeta, fdead, out)
    for p in range(pi.shape[0]):
        if not touching[p]:
            continue
        f, _, nx, ny, nz = pair_force(y, n, p, pi, pj, law, rsum, ramp, clamped, phi)
        if f == 0.0:
            continue
        i, j = pi[p], pj[p]
        if j < 0:
            _plate_reaction(n, phi, p, f, out)
        a = f / mass[i]
        out[3 * n + 3 * i] += a * nx
        out[3 * n + 3 * i + 1] += a * ny
        out[3 * n + 3 * i + 2] += a * nz
        if j >= 0:
            a = f / mass[j]
            out[3 * n + 3 * j] -= a * nx
            out[3 * n + 3 * j + 1] -= a * ny
            out[3 * n + 3 * j + 2] -= a * nz


@helper_njit
def _modal_rhs(y, n, omega, zeta, fdead, out):
    """Free modes under the dead loads: q' and f_dead - 2 zeta omega q' - omega^2 q."""
    nm = omega.shape[0]
    off = 6 * n
    for k in range(nm):
        q, qd = y[off + k], y[off + nm + k]
        out[off + k] = qd
        out[off + nm + k] = fdead[k] - 2.0 * zeta[k] * omega[k] * qd - omega[k] * omega[k] * q


@helper_njit
def _plate_reaction(n, phi, p, f, out):
    """Modal forces of the reaction -f (N, along +z) of plate pair p: -phi[p] f."""
    nm = phi.shape[1]
    off = 6 * n + nm
    for k in range(nm):
        out[off + k] -= phi[p, k] * f


@helper_njit
def rhs(y, model, pstate, out):
    """``rhs_arrays`` with the model and pair-state tuples."""
    mass, radius, g, half, pi, pj, law, rsum, e_settle, alive, omega, zeta, phi, fdead = model
    rhs_arrays(y, mass, g, pi, pj, law, rsum, pstate[0], pstate[1], pstate[2], alive, omega,
               zeta, phi, fdead, out)  # fmt: skip


@helper_njit
def row_band(kind, idx, rsum):
    """Dead band of a row (see the module docstring)."""
    if kind == R_EDGE:
        return EDGE_BAND
    if kind == R_CLAMP:
        return CLAMP_BAND
    return 1e-12 * rsum[idx] * rsum[idx]


@helper_njit
def row_value_arrays(kind, idx, y, n, half, pi, pj, law, rsum, touching, ramp, clamped, phi):
    """g = sign x f + band of row (kind, idx) at state y: > 0 on the row's side."""
    if kind == R_EDGE:
        b, e = idx // 4, idx % 4
        c = y[3 * b + e // 2]
        h = half[e // 2]
        f = c + h if e % 2 == 0 else h - c
        return f + EDGE_BAND
    i, j, rs = pi[idx], pj[idx], rsum[idx]
    if j < 0:
        w, wd = plate_deflection(y, n, phi, idx)
        return plate_row_value(kind, idx, y[3 * i + 2], y[3 * n + 3 * i + 2], w, wd, law, rsum,
                               touching, ramp, clamped)  # fmt: skip
    if kind == R_CLAMP:
        delta, rate, _, _, _ = pair_state(y, n, i, j, rs, phi, idx)
        return _clamp_row(idx, delta, rate, law, ramp, clamped)
    dx = y[3 * i] - y[3 * j]
    dy = y[3 * i + 1] - y[3 * j + 1]
    dz = y[3 * i + 2] - y[3 * j + 2]
    return _distance_row(kind, idx, dx * dx + dy * dy + dz * dz, rs, law, touching, ramp)


@helper_njit
def plate_row_value(kind, p, z, vz, w, wd, law, rsum, touching, ramp, clamped):
    """``row_value_arrays`` of plate pair p (not an edge row) from the ball's z, vz and the
    plate's w, wd under it."""
    if kind == R_CLAMP:
        return _clamp_row(p, rsum[p] - (z - w), -(vz - wd), law, ramp, clamped)
    gap = z - w
    return _distance_row(kind, p, gap * gap, rsum[p], law, touching, ramp)


@helper_njit
def _clamp_row(idx, delta, rate, law, ramp, clamped):
    ind = clamp_indicator(
        delta, rate, law[idx, L_K], law[idx, L_E], law[idx, L_C], law[idx, L_D], ramp[idx]
    )
    return (-ind if clamped[idx] else ind) + CLAMP_BAND


@helper_njit
def _distance_row(kind, idx, d2, rs, law, touching, ramp):
    """Contact / full-damping row from the squared centre distance d2 (the gap^2 on the plate)."""
    band = 1e-12 * rs * rs
    if kind == R_CONTACT:
        f = d2 - rs * rs
        return (-f if touching[idx] else f) + band
    r_full = rs - law[idx, L_D]
    f = d2 - r_full * r_full
    return (f if ramp[idx] else -f) + band


@helper_njit
def row_value(kind, idx, y, model, pstate):
    """``row_value_arrays`` with the model and pair-state tuples."""
    mass, radius, g, half, pi, pj, law, rsum, e_settle, alive, omega, zeta, phi, fdead = model
    touching, ramp, clamped = pstate[0], pstate[1], pstate[2]
    n = mass.shape[0]
    return row_value_arrays(kind, idx, y, n, half, pi, pj, law, rsum, touching, ramp, clamped,
                            phi)  # fmt: skip


@helper_njit
def first_contact_step(y, model, p, rtol):
    """First step after a contact start (s): where the tau^(e+2) term of the penetration
    reaches rtol, t_s rtol^(1/(e+2)), and within half the ramp (as tailbeam.rigid)."""
    mass, radius, g, half, pi, pj, law, rsum, e_settle, alive, omega, zeta, phi, fdead = model
    n = mass.shape[0]
    i, j = pi[p], pj[p]
    m = mass[i] if j < 0 else mass[i] * mass[j] / (mass[i] + mass[j])
    _, rate, _, _, _ = pair_state(y, n, i, j, rsum[p], phi, p)
    speed = max(rate, 1e-3)
    k, e = law[p, L_K], law[p, L_E]
    delta_m = ((e + 1.0) * m * speed * speed / (2.0 * k)) ** (1.0 / (e + 1.0))
    return min(delta_m / speed * rtol ** (1.0 / (e + 2.0)), 0.5 * law[p, L_D] / speed)


@helper_njit
def settle_excess(y, model, p, b):
    """Normal excess energy (J) of ball b on the plate pair p over its static state:
    1/2 m vz^2 + U(delta) - U(delta_s) - m g_n (delta - delta_s), delta_s = (m g_n / k)^(1/e)
    (on the modal plate: delta and vz relative to the plate under the ball)."""
    mass, radius, g, half, pi, pj, law, rsum, e_settle, alive, omega, zeta, phi, fdead = model
    n = mass.shape[0]
    m = mass[b]
    k, e = law[p, L_K], law[p, L_E]
    gn = -g[2]
    delta, vz, _, _, _ = pair_state(y, n, b, pj[p], rsum[p], phi, p)  # (vz: minus the rate)
    delta_s = (m * gn / k) ** (1.0 / e) if gn > 0.0 else 0.0
    u = elastic_energy(delta, k, e) - elastic_energy(delta_s, k, e)
    return 0.5 * m * vz * vz + u - m * gn * (delta - delta_s)
