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
(F_p on the ball along +z, its reaction -F_p on the plate);
    rate = -(v_i - v_j) . n  (> 0 approaching); force F n on i, -F n on j (frictionless).

Residual flexibility (optional, per plate pair: ``law[p, L_CRES]`` = C m/N, the static
compliance of the truncated modes at the contact point, 0 = none): the law acts on the
penetration left after the residual spring in series, F = IMPACT(delta, delta'),
delta = delta0 - C F (delta0 = r - (z - w) as above), solved per evaluation by
``plate_force_with_residual``. Contact start and end stay the crossings of delta0 = 0 (F = 0
there); the full-damping and clamp rows use delta and F.

``law`` (P, 6) columns: stiffness k (N/m^e), exponent e, damping c (N s/m), penetration d (m),
clamp (0/1), residual compliance C (m/N, plate pairs; 0 otherwise), built by
``contact_law.ball_ball_law`` / ``ball_plate_law``. The law itself (``region_force``,
``clamp_indicator``, ``elastic_energy``, ``elastic_stiffness``, the damping slope) is
``tailbeam.physics.impact``'s, the one definition every solver uses.

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

from tailbeam.physics.contact_law import LAW_C, LAW_COLUMNS, LAW_D, LAW_E, LAW_K
from tailbeam.physics.impact import (
    clamp_indicator,
    elastic_energy,
    elastic_stiffness,
    region_damping,
    region_damping_slope,
    region_force,
)
from tailbeam.solvers.numerics.jit import helper_njit
from tailbeam.solvers.stream.active.compiled.friction import add_friction, spin_offset

L_CRES = LAW_COLUMNS  # the residual compliance C (m/N), after the law's own columns
RESIDUAL_RTOL = 1e-14  # relative convergence of the residual-flexibility force solve
RESIDUAL_ITERATIONS = 60  # its bound (bisection safeguard: ~1 bit per iteration at worst)
R_CONTACT, R_FULL, R_CLAMP, R_EDGE = range(4)
# a ball's ``alive`` code: gone (no longer integrated), integrated, or a FIXED obstacle (held
# where it is: no motion, no gravity, feels no force; its pairs act on the other ball only)
GONE, INTEGRATED, FIXED = 0, 1, 2
CLAMP_BAND = 1e-10
EDGE_BAND = 1e-13


# --- residual flexibility at plate contacts: the law's call sites with a spring in series ---


@helper_njit
def residual_rate(delta, rate0, acc0, k, e, c, d, ramp, cres):
    """delta' (m/s) of a plate contact with the residual spring cres (m/N) in series, from
    delta0' = rate0 and delta0'' = acc0 (m/s^2): delta' = delta0' - C F' with F' = (k e
    delta^(e-1) + c s'(delta) delta') delta' + c s(delta) delta'', delta'' taken as delta0''
    (drops C F'' there): the root of C c s' delta'^2 + (1 + C k e delta^(e-1)) delta' -
    (delta0' - C c s delta0'') = 0 that tends to delta0' as C -> 0."""
    pos = delta if delta > 0.0 else 0.0
    r = rate0 - cres * region_damping(pos, c, d, ramp) * acc0
    a = cres * region_damping_slope(pos, c, d, ramp)
    b = 1.0 + cres * elastic_stiffness(pos, k, e)
    disc = b * b + 4.0 * a * r
    return 2.0 * r / (b + math.sqrt(max(disc, 0.25 * b * b)))


@helper_njit
def plate_force_with_residual(delta0, rate0, acc0, kappa, k, e, c, d, ramp, clamped, cres):
    """(F N, delta m, delta' m/s) of a plate contact in its region with the residual
    compliance cres (m/N) in series: F = region_force(delta, delta') with delta = delta0 -
    cres F and delta' = ``residual_rate``. delta0, rate0: the ball's penetration into the
    plate's modal deflection and its rate (m, m/s); its second derivative is acc0 - kappa F
    (acc0 m/s^2 without this contact's force, kappa = 1/m + phi . phi in 1/kg: the ball and
    the modes under it; other contacts' forces are left out). cres = 0 or clamped: exactly
    ``region_force(delta0, rate0)``. F - region_force(...) increases with F, so Newton's
    method (slope 1 + cres k e delta^(e-1)) inside the bracket of the signs seen so far
    (bisection when a step leaves it) converges; to RESIDUAL_RTOL relative."""
    if clamped or cres <= 0.0:
        return region_force(delta0, rate0, k, e, c, d, ramp, clamped), delta0, rate0
    f = region_force(delta0, rate0, k, e, c, d, ramp, False)
    lo, hi = -math.inf, math.inf
    for _ in range(RESIDUAL_ITERATIONS):
        delta = delta0 - cres * f
        rate = residual_rate(delta, rate0, acc0 - kappa * f, k, e, c, d, ramp, cres)
        g = f - region_force(delta, rate, k, e, c, d, ramp, False)
        if g == 0.0:
            break
        if g > 0.0:
            hi = f
        else:
            lo = f
        fn = f - g / (1.0 + cres * elastic_stiffness(delta, k, e))
        if abs(fn - f) <= RESIDUAL_RTOL * abs(fn):
            f = fn
            break
        f = fn if lo < fn < hi else 0.5 * (lo + hi)
    delta = delta0 - cres * f
    return f, delta, residual_rate(delta, rate0, acc0 - kappa * f, k, e, c, d, ramp, cres)


@helper_njit
def plate_contact_energy(delta0, k, e, cres):
    """Elastic energy (J) of a plate contact at penetration delta0 (m) with the residual
    spring cres (m/N) in series: k delta^(e+1)/(e+1) + cres F^2 / 2 with F = k delta^e,
    delta + cres F = delta0 (its derivative in delta0 is F: the pair is conservative)."""
    f, delta, _ = plate_force_with_residual(delta0, 0.0, 0.0, 0.0, k, e, 0.0, 1.0, True, False,
                                            cres)  # fmt: skip
    return elastic_energy(delta, k, e) + 0.5 * cres * f * f


@helper_njit
def contact_energies(y, n, pi, pj, rsum, phi, law, touching, out):
    """Elastic energy (J) of every pair at state y into ``out`` (P,): ``plate_contact_energy``
    of a touching plate pair (its residual spring included), that of the law for two balls,
    0 for a pair not touching (``ActiveSet.contact_energy`` for all pairs in one call)."""
    for p in range(pi.shape[0]):
        out[p] = 0.0
        if not touching[p]:
            continue
        delta, _, _, _, _ = pair_state(y, n, pi[p], pj[p], rsum[p], phi, p)
        cres = law[p, L_CRES] if pj[p] < 0 else 0.0
        out[p] = plate_contact_energy(delta, law[p, LAW_K], law[p, LAW_E], cres)


@helper_njit
def plate_free_acceleration(y, n, p, i, phi, mass, g, omega, zeta, fdead):
    """(acc0 m/s^2, kappa 1/kg) of plate pair p of ball i at state y: delta0'' = acc0 -
    kappa F without the other contacts, acc0 = -g_z + phi[p] . (f_dead - 2 zeta omega q' -
    omega^2 q), kappa = 1/m_i + phi[p] . phi[p] (see ``plate_force_with_residual``)."""
    nm = phi.shape[1]
    off = 6 * n
    acc = -g[2]
    kappa = 1.0 / mass[i]
    for k in range(nm):
        c = phi[p, k]
        q, qd = y[off + k], y[off + nm + k]
        acc += c * (fdead[k] - 2.0 * zeta[k] * omega[k] * qd - omega[k] * omega[k] * q)
        kappa += c * c
    return acc, kappa


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
def pair_force(y, n, p, pi, pj, law, rsum, ramp, clamped, phi, mass, g, omega, zeta, fdead):
    """(F, delta, nx, ny, nz) of pair p in its region at state y (a plate pair's delta: what
    the law sees, after the residual spring)."""
    delta, rate, nx, ny, nz = pair_state(y, n, pi[p], pj[p], rsum[p], phi, p)
    if pj[p] < 0:
        acc, kappa = 0.0, 0.0
        if law[p, L_CRES] > 0.0 and law[p, LAW_C] > 0.0:  # (delta0'' enters through damping)
            acc, kappa = plate_free_acceleration(y, n, p, pi[p], phi, mass, g, omega, zeta, fdead)
        f, delta, _ = plate_force_with_residual(delta, rate, acc, kappa, law[p, LAW_K],
                                                law[p, LAW_E], law[p, LAW_C], law[p, LAW_D],
                                                ramp[p], clamped[p], law[p, L_CRES])  # fmt: skip
        return f, delta, nx, ny, nz
    f = region_force(
        delta, rate, law[p, LAW_K], law[p, LAW_E], law[p, LAW_C], law[p, LAW_D], ramp[p], clamped[p]
    )
    return f, delta, nx, ny, nz


@helper_njit
def plate_force(p, z, vz, w, wd, acc, kappa, law, rsum, ramp, clamped):
    """(F N, delta m) of plate pair p in its region from the ball's height z (m) and speed vz
    (m/s) and the plate's deflection w (m) and velocity wd (m/s) under it (delta: after the
    residual spring; acc, kappa: ``plate_free_acceleration``)."""
    f, delta, _ = plate_force_with_residual(
        rsum[p] - (z - w), -(vz - wd), acc, kappa, law[p, LAW_K], law[p, LAW_E], law[p, LAW_C],
        law[p, LAW_D], ramp[p], clamped[p], law[p, L_CRES],
    )  # fmt: skip
    return f, delta


@helper_njit
def rhs_arrays(y, mass, g, pi, pj, law, rsum, touching, ramp, clamped, alive, omega, zeta,
               phi, fdead, radius, fric, out):  # fmt: skip
    """dy/dt of the active set: gravity on every integrated ball plus the touching pairs (a
    FIXED ball's derivatives stay 0: it acts on its partners and feels nothing), and the
    modes (``_modal_rhs``); with friction (``fric`` has columns) the angular velocities'
    rates and each touching pair's friction (``friction.add_friction``). (Arrays passed one
    by one: unpacking the model tuple on every call costs more than the right-hand side of a
    small set.)"""
    n = mass.shape[0]
    for b in range(n):
        for k in range(3):
            out[3 * b + k] = y[3 * n + 3 * b + k] if alive[b] == INTEGRATED else 0.0
            out[3 * n + 3 * b + k] = g[k] if alive[b] == INTEGRATED else 0.0
    _modal_rhs(y, n, omega, zeta, fdead, out)
    with_friction = fric.shape[1] > 0
    off = spin_offset(n, omega.shape[0])
    if with_friction:
        for q in range(off, off + 3 * n):
            out[q] = 0.0
    for p in range(pi.shape[0]):
        if not touching[p]:
            continue
        f, _, nx, ny, nz = pair_force(y, n, p, pi, pj, law, rsum, ramp, clamped, phi, mass, g,
                                      omega, zeta, fdead)  # fmt: skip
        if f == 0.0:
            continue
        i, j = pi[p], pj[p]
        if j < 0:
            _plate_reaction(n, phi, p, f, out)
        if alive[i] != FIXED:
            a = f / mass[i]
            out[3 * n + 3 * i] += a * nx
            out[3 * n + 3 * i + 1] += a * ny
            out[3 * n + 3 * i + 2] += a * nz
        if j >= 0 and alive[j] != FIXED:
            a = f / mass[j]
            out[3 * n + 3 * j] -= a * nx
            out[3 * n + 3 * j + 1] -= a * ny
            out[3 * n + 3 * j + 2] -= a * nz
        if with_friction:
            add_friction(y, n, off, p, i, j, f, nx, ny, nz, mass, radius, fric, alive[i] == FIXED,
                         j >= 0 and alive[j] == FIXED, out)  # fmt: skip


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
    mass, radius, g, half, pi, pj, law, rsum, e_settle, alive, omega, zeta, phi, fdead, fric = model
    rhs_arrays(y, mass, g, pi, pj, law, rsum, pstate[0], pstate[1], pstate[2], alive, omega,
               zeta, phi, fdead, radius, fric, out)  # fmt: skip


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
    """g = sign x f + band of row (kind, idx) at state y: > 0 on the row's side (edge and
    ball-ball rows; plate rows: ``row_value``)."""
    if kind == R_EDGE:
        b, e = idx // 4, idx % 4
        c = y[3 * b + e // 2]
        h = half[e // 2]
        f = c + h if e % 2 == 0 else h - c
        return f + EDGE_BAND
    i, j, rs = pi[idx], pj[idx], rsum[idx]
    if kind == R_CLAMP:
        delta, rate, _, _, _ = pair_state(y, n, i, j, rs, phi, idx)
        return _clamp_row(idx, delta, rate, law, ramp, clamped)
    dx = y[3 * i] - y[3 * j]
    dy = y[3 * i + 1] - y[3 * j + 1]
    dz = y[3 * i + 2] - y[3 * j + 2]
    return _distance_row(kind, idx, dx * dx + dy * dy + dz * dz, rs, law, touching, ramp)


@helper_njit
def plate_row_value(kind, p, z, vz, w, wd, acc, kappa, law, rsum, touching, ramp, clamped):
    """Row value of plate pair p (not an edge row) from the ball's z, vz and the plate's w, wd
    under it (acc, kappa: ``plate_free_acceleration``). With residual flexibility the clamp
    and full-damping rows see the law's delta, delta' (``plate_force_with_residual``); the
    contact row the gap z - w."""
    gap = z - w
    if kind == R_CLAMP or (kind == R_FULL and law[p, L_CRES] > 0.0):
        f, delta, rate = plate_force_with_residual(
            rsum[p] - gap, -(vz - wd), acc, kappa, law[p, LAW_K], law[p, LAW_E], law[p, LAW_C],
            law[p, LAW_D], ramp[p], clamped[p], law[p, L_CRES],
        )  # fmt: skip
        if kind == R_CLAMP:
            return _clamp_row(p, delta, rate, law, ramp, clamped)
        gap = rsum[p] - delta
    return _distance_row(kind, p, gap * gap, rsum[p], law, touching, ramp)


@helper_njit
def _clamp_row(idx, delta, rate, law, ramp, clamped):
    ind = clamp_indicator(
        delta, rate, law[idx, LAW_K], law[idx, LAW_E], law[idx, LAW_C], law[idx, LAW_D], ramp[idx]
    )
    return (-ind if clamped[idx] else ind) + CLAMP_BAND


@helper_njit
def _distance_row(kind, idx, d2, rs, law, touching, ramp):
    """Contact / full-damping row from the squared centre distance d2 (the gap^2 on the plate)."""
    band = 1e-12 * rs * rs
    if kind == R_CONTACT:
        f = d2 - rs * rs
        return (-f if touching[idx] else f) + band
    r_full = rs - law[idx, LAW_D]
    f = d2 - r_full * r_full
    return (f if ramp[idx] else -f) + band


@helper_njit
def row_value(kind, idx, y, model, pstate):
    """g = sign x f + band of row (kind, idx) at state y (``row_value_arrays``, plate rows
    with ``plate_row_value``) with the model and pair-state tuples."""
    mass, radius, g, half, pi, pj, law, rsum, e_settle, alive, omega, zeta, phi, fdead, fric = model
    touching, ramp, clamped = pstate[0], pstate[1], pstate[2]
    n = mass.shape[0]
    if kind != R_EDGE and pj[idx] < 0:
        i = pi[idx]
        w, wd = plate_deflection(y, n, phi, idx)
        acc, kappa = plate_free_acceleration(y, n, idx, i, phi, mass, g, omega, zeta, fdead)
        return plate_row_value(kind, idx, y[3 * i + 2], y[3 * n + 3 * i + 2], w, wd, acc, kappa,
                               law, rsum, touching, ramp, clamped)  # fmt: skip
    return row_value_arrays(kind, idx, y, n, half, pi, pj, law, rsum, touching, ramp, clamped,
                            phi)  # fmt: skip


@helper_njit
def first_contact_step(y, model, p, rtol):
    """First step after a contact start (s): where the tau^(e+2) term of the penetration
    reaches rtol, t_s rtol^(1/(e+2)), and within half the ramp (as tailbeam.solvers.rigid)."""
    mass, radius, g, half, pi, pj, law, rsum, e_settle, alive, omega, zeta, phi, fdead, fric = model
    n = mass.shape[0]
    i, j = pi[p], pj[p]
    m = mass[i] if j < 0 else mass[i] * mass[j] / (mass[i] + mass[j])
    if j >= 0 and alive[j] == FIXED:  # (an obstacle: the other ball's mass alone)
        m = mass[i]
    elif alive[i] == FIXED:
        m = mass[j]
    _, rate, _, _, _ = pair_state(y, n, i, j, rsum[p], phi, p)
    speed = max(rate, 1e-3)
    k, e = law[p, LAW_K], law[p, LAW_E]
    delta_m = ((e + 1.0) * m * speed * speed / (2.0 * k)) ** (1.0 / (e + 1.0))
    return min(delta_m / speed * rtol ** (1.0 / (e + 2.0)), 0.5 * law[p, LAW_D] / speed)


@helper_njit
def settle_excess(y, model, p, b):
    """Normal excess energy (J) of ball b on the plate pair p over its static state:
    1/2 m vz^2 + U(delta) - U(delta_s) - m g_n (delta - delta_s), delta_s = (m g_n / k)^(1/e)
    (on the modal plate: delta and vz relative to the plate under the ball; with residual
    flexibility U is ``plate_contact_energy`` and delta_s grows by C m g_n)."""
    mass, radius, g, half, pi, pj, law, rsum, e_settle, alive, omega, zeta, phi, fdead, fric = model
    n = mass.shape[0]
    m = mass[b]
    k, e, cres = law[p, LAW_K], law[p, LAW_E], law[p, L_CRES]
    gn = -g[2]
    delta, vz, _, _, _ = pair_state(y, n, b, pj[p], rsum[p], phi, p)  # (vz: minus the rate)
    delta_s = (m * gn / k) ** (1.0 / e) + cres * m * gn if gn > 0.0 else 0.0
    u = plate_contact_energy(delta, k, e, cres) - plate_contact_energy(delta_s, k, e, cres)
    return 0.5 * m * vz * vz + u - m * gn * (delta - delta_s)
