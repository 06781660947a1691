"""Compiled friction and rolling resistance of an active set's contacts: the numba twin of
``tailbeam.physics.friction`` (same formulas, checked against it by the tests) with the
contact point of the stream reference (``tailbeam.solvers.stream.reference.friction``).

A set with friction has a friction table ``fric`` (P, F_COLUMNS) per pair (no columns
without friction) and the balls' angular velocities after the modal block in its state:
y = [x (3 n) | v (3 n) | q (m) | q' (m) | w (3 n)] (rad/s, plate frame).

Each contact acts at one point on the line of centres: at the fraction ``share`` =
r_i / (r_i + r_j) of the centres' distance d from ball i (on the rigid plate: at the foot of
the centre, share 1, d the centre's height). Lever arms a_i = -d share n and
a_j = d (1 - share) n, slip = u - (u . n) n with u = (v_i + w_i x a_i) - (v_j + w_j x a_j);
the tangential force F_t (on i, -F_t on j) has the torques a_i x F_t on i and -a_j x F_t
on j; rolling resistance acts against w_roll, the part of w_i - w_j in the contact plane.
The power dissipated, -(F_t . slip) - (tau . w_roll), is >= 0.

On the modal plate (the reference's model, ``tailbeam.solvers.stream.reference.plate``) a
plate pair's table row goes on with F_LEVER, F_MOMENT and the gradients of the m mode
shapes at its contact point (d phi / dx for the m modes, then d phi / dy; 1/(m sqrt(kg))):
the plate's top surface, h/2 above its mid-surface, moves in-plane at -(h/2) grad phi . q'
(Kirchhoff), which the slip is taken against (lever F_LEVER = h/2), and the force -F_t it
takes there gives the modes the generalised force (h/2) F_t . grad phi (lever F_MOMENT =
h/2; 0 leaves the moment out). Rows of ball-ball pairs and the rigid plate have both levers 0.
"""

import math

from tailbeam.physics.impact import step
from tailbeam.solvers.numerics.jit import helper_njit

# friction table columns: mu_s, mu_d, v_s (m/s), v_d (m/s), mu_r, share, rolling radius (m)
F_STATIC, F_DYNAMIC, F_VS, F_VD, F_ROLL, F_SHARE, F_RADIUS = range(7)
F_COLUMNS = 7
# modal plate: surface and moment levers (m), then the shapes' gradients (2 m columns)
F_LEVER, F_MOMENT, F_GRAD = 7, 8, 9
# pair accumulators ``imp`` (P, IMP_COLUMNS): normal impulse (N s), tangential impulse on
# ball i (3, N s), energy dissipated by friction and rolling resistance (J)
IMP_N, IMP_T, IMP_WORK = 0, 1, 4
IMP_COLUMNS = 5


@helper_njit
def coefficient(v, static, dynamic, v_s, v_d):
    """mu(v) of ``tailbeam.physics.friction.coefficient`` at one slip speed v (m/s)."""
    if v < v_s:
        return step(v, 0.0, 0.0, v_s, static)
    return step(v, v_s, static, v_d, dynamic)


@helper_njit
def spin_offset(n, nm):
    """Index of the first angular velocity in the state of n balls and nm modes."""
    return 6 * n + 2 * nm


@helper_njit
def pair_friction(y, n, off, i, j, p, nx, ny, nz, fn, fric):
    """Friction of pair p = (i, j) (j < 0: the rigid plate) with unit normal n (from j to i)
    and normal force fn (N) at state y (spins from index ``off``): (F_t (3) on i in N,
    torque on i (3) and on j (3) in N m, dissipated power W, slip speed m/s)."""
    share = fric[p, F_SHARE]
    xi, vi, wi = 3 * i, 3 * n + 3 * i, off + 3 * i
    if j >= 0:
        xj, vj, wj = 3 * j, 3 * n + 3 * j, off + 3 * j
        dx, dy, dz = y[xi] - y[xj], y[xi + 1] - y[xj + 1], y[xi + 2] - y[xj + 2]
        d = math.sqrt(dx * dx + dy * dy + dz * dz)
        vjx, vjy, vjz = y[vj], y[vj + 1], y[vj + 2]
        wjx, wjy, wjz = y[wj], y[wj + 1], y[wj + 2]
    else:
        d = abs(y[xi + 2])
        vjx, vjy, vjz, wjx, wjy, wjz = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        if fric.shape[1] > F_GRAD and fric[p, F_LEVER] != 0.0:
            vjx, vjy = surface_velocity(y, n, p, fric)
    ai, aj = -d * share, d * (1.0 - share)  # lever arms along n
    wix, wiy, wiz = y[wi], y[wi + 1], y[wi + 2]
    # u = v_i + w_i x (ai n) - v_j - w_j x (aj n)
    ux = y[vi] + ai * (wiy * nz - wiz * ny) - vjx - aj * (wjy * nz - wjz * ny)
    uy = y[vi + 1] + ai * (wiz * nx - wix * nz) - vjy - aj * (wjz * nx - wjx * nz)
    uz = y[vi + 2] + ai * (wix * ny - wiy * nx) - vjz - aj * (wjx * ny - wjy * nx)
    un = ux * nx + uy * ny + uz * nz
    sx, sy, sz = ux - un * nx, uy - un * ny, uz - un * nz
    speed = math.sqrt(sx * sx + sy * sy + sz * sz)
    mu = coefficient(speed, fric[p, F_STATIC], fric[p, F_DYNAMIC], fric[p, F_VS], fric[p, F_VD])
    scale = mu * abs(fn) / speed if speed > 0.0 else 0.0
    fx, fy, fz = -scale * sx, -scale * sy, -scale * sz
    rx, ry, rz = wix - wjx, wiy - wjy, wiz - wjz
    rn = rx * nx + ry * ny + rz * nz
    rx, ry, rz = rx - rn * nx, ry - rn * ny, rz - rn * nz
    rate = math.sqrt(rx * rx + ry * ry + rz * rz)
    radius = fric[p, F_RADIUS]
    size = fric[p, F_ROLL] * radius * abs(fn) * step(radius * rate, 0.0, 0.0, fric[p, F_VS], 1.0)
    tscale = size / rate if rate > 0.0 else 0.0
    tx, ty, tz = -tscale * rx, -tscale * ry, -tscale * rz
    # (a n) x F
    cx, cy, cz = ny * fz - nz * fy, nz * fx - nx * fz, nx * fy - ny * fx
    power = -(fx * sx + fy * sy + fz * sz) - (tx * rx + ty * ry + tz * rz)
    return (fx, fy, fz, ai * cx + tx, ai * cy + ty, ai * cz + tz, -aj * cx - tx, -aj * cy - ty,
            -aj * cz - tz, power, speed)  # fmt: skip


@helper_njit
def surface_velocity(y, n, p, fric):
    """In-plane velocity (m/s) of the plate's top surface at plate pair p's contact point:
    -lever grad phi . q' (modal table row, module docstring)."""
    nm = (fric.shape[1] - F_GRAD) // 2
    off = 6 * n + nm
    sx, sy = 0.0, 0.0
    for k in range(nm):
        sx += fric[p, F_GRAD + k] * y[off + k]
        sy += fric[p, F_GRAD + nm + k] * y[off + k]
    lever = fric[p, F_LEVER]
    return -lever * sx, -lever * sy


@helper_njit
def add_plate_moment(n, p, fx, fy, fric, out):
    """Modal forces (h/2) F_t . grad phi of the friction force (fx, fy) (N, on the ball) of
    plate pair p, reversed on the plate's top surface (modal table row), added to the modes'
    accelerations in ``out`` (unit modal mass)."""
    nm = (fric.shape[1] - F_GRAD) // 2
    off = 6 * n + nm
    lever = fric[p, F_MOMENT]
    for k in range(nm):
        out[off + k] += lever * (fx * fric[p, F_GRAD + k] + fy * fric[p, F_GRAD + nm + k])


@helper_njit
def add_friction(y, n, off, p, i, j, fn, nx, ny, nz, mass, radius, fric, fixed_i, fixed_j,
                 out):  # fmt: skip
    """Add pair p's friction force and torques to dy/dt ``out`` (accelerations, angular
    accelerations with the moment of inertia 2/5 m r^2; on the modal plate the modes'
    accelerations from the force's moment, ``add_plate_moment``). A ball ``fixed_i`` /
    ``fixed_j`` (an obstacle, ``pairs.FIXED``) takes none of it."""
    r = pair_friction(y, n, off, i, j, p, nx, ny, nz, fn, fric)
    vi, wi = 3 * n + 3 * i, off + 3 * i
    inertia = 0.4 * mass[i] * radius[i] * radius[i]
    if not fixed_i:
        for k in range(3):
            out[vi + k] += r[k] / mass[i]
        out[wi] += r[3] / inertia
        out[wi + 1] += r[4] / inertia
        out[wi + 2] += r[5] / inertia
    if j >= 0 and fixed_j:
        return
    if j >= 0:
        vj, wj = 3 * n + 3 * j, off + 3 * j
        inertia = 0.4 * mass[j] * radius[j] * radius[j]
        for k in range(3):
            out[vj + k] -= r[k] / mass[j]
        out[wj] += r[6] / inertia
        out[wj + 1] += r[7] / inertia
        out[wj + 2] += r[8] / inertia
    elif fric.shape[1] > F_GRAD and fric[p, F_MOMENT] != 0.0:
        add_plate_moment(n, p, r[0], r[1], fric, out)
