"""Slow, independent reference for the coupled impact: the full finite-element plate.

One ball strikes the assembled FE plate (``tailbeam.plate.assemble_plate``: every DOF of the
mesh, no modes). The plate

    M u'' + C u' + K u = -f F(t),      C = alpha M + beta K (Rayleigh; 0 by default),

is integrated with Newmark's average-acceleration rule (trapezoidal, 2nd order, unconditionally
stable, no numerical damping) at a constant step dt; the ball with the same rule. f is the
contact's load vector (``PlateModel.load_vector``: a point load, or 1 N spread over a disc of
``load_radius``), so the plate under the ball is w_c = f.u. The IMPACT force at the step's end is
solved implicitly each step: F = law(delta(F), delta_dot(F)), both affine in F because the
plate's end-of-step state is u_hat - F K_eff^-1 f; the scalar equation is monotone in F and is
bracketed and solved by Brent's method.

Contact start and end are located inside their step (cubic Hermite interpolation of the
penetration from its values and rates at both step ends); the ball's speed there gives the
restitution. The peak force (and its time) and the maximum penetration are refined by a
parabola through the three nodes around the largest one; the contacts are ``Impact`` records
(``tailbeam.results.records``, as every solver's). Nothing is shared with the modal solver
(``tailbeam.solvers.coupled.solver``) but the mesh, the element assembly and the contact law's
formula.

``integrate`` is the same run on any FE model given its load vector and sensor operator
(a structure: ``tailbeam.solvers.coupled.fe_structure``).

Use ``fe_time_step_study`` to show the step's convergence (order ~2) and to estimate the error.
"""

import math
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse.linalg as spla
from scipy.optimize import brentq

from tailbeam.errors import InputError, WorkLimitError, require_positive
from tailbeam.physics.bodies import STANDARD_GRAVITY, Ball
from tailbeam.physics.contact_law import ImpactLaw, impact_force_scalar
from tailbeam.progress import task
from tailbeam.results.records import Impact

DEFAULT_MAX_WORK = 1e11  # steps x 10 x matrix nonzeros; 1e11 is ~1-2 min on one core


@dataclass
class FEReferenceResult:
    """Histories at every step (t (s), force (N), penetration (m)), sensor deflections (m) and
    accelerations (m/s^2) as (p, steps + 1) arrays, the located impacts, and the settings."""

    t: np.ndarray
    force: np.ndarray
    penetration: np.ndarray
    sensor_w: np.ndarray
    sensor_a: np.ndarray
    impacts: list
    dt: float
    n_dofs: int
    info: dict = field(default_factory=dict)


def check_inputs(ball, law, model, duration, dt, load_radius):
    """InputError (one line, naming the argument) for what the reference cannot run; ``model``
    needs ``plate`` (the impact face's rectangle)."""
    if not isinstance(ball, Ball):
        raise InputError("ball", "must be a Ball")
    if not isinstance(law, ImpactLaw):
        raise InputError("law", "must be an ImpactLaw")
    if ball.velocity[0] != 0.0 or ball.velocity[1] != 0.0:
        raise InputError("ball.velocity", "the FE reference takes vertical impacts only")
    if ball.position[2] - ball.radius <= 0.0:
        raise InputError("ball.position", "the ball must start above the plate")
    if not model.plate.contains(ball.position[0], ball.position[1]):
        raise InputError("ball.position", "must lie above the plate")
    require_positive("duration", duration)
    require_positive("dt", dt)
    if load_radius < 0:
        raise InputError("load_radius", f"must be >= 0, got {load_radius!r}")


class _Plate:
    """The Newmark plate: K_eff factorised once; predictor and correction per step."""

    def __init__(self, model, dt, rayleigh, load, factorize=None):
        alpha, beta = rayleigh
        self.K, self.M = model.stiffness, model.mass
        self.C = alpha * self.M + beta * self.K if (alpha, beta) != (0.0, 0.0) else None
        self.c0, self.c1 = 4.0 / dt**2, 2.0 / dt
        keff = (1.0 + self.c1 * beta) * self.K + (self.c0 + self.c1 * alpha) * self.M
        if factorize is None:
            self.lu = spla.splu(keff.tocsc(), permc_spec="MMD_AT_PLUS_A")
        else:
            self.lu = factorize(keff)
        self.f = load
        self.g = self.lu.solve(load)  # end-of-step plate answer to a unit contact force
        self.s_w = float(load @ self.g)
        self.dt = dt

    def predict(self, u, v, a):
        """End-of-step displacement with no force at the step's end (N u_hat = rhs)."""
        rhs = self.M @ (self.c0 * u + 4.0 / self.dt * v + a)
        if self.C is not None:
            rhs += self.C @ (self.c1 * u + v)
        return self.lu.solve(rhs)

    def correct(self, u, v, a, u_hat, force):
        u1 = u_hat - force * self.g
        a1 = self.c0 * (u1 - u - self.dt * v) - a
        v1 = v + 0.5 * self.dt * (a + a1)
        return u1, v1, a1


def _contact_force(law, delta0, ddot0, s_d, s_v):
    """F solving F = law(delta0 - s_d F, ddot0 - s_v F) (monotone: law falls as F rises)."""
    args = (law.stiffness, law.exponent, law.damping, law.penetration, law.clamp)
    f0 = impact_force_scalar(delta0, ddot0, *args)
    if f0 == 0.0:
        return 0.0

    def residual(force):
        return force - impact_force_scalar(delta0 - s_d * force, ddot0 - s_v * force, *args)

    lo, hi = min(0.0, f0), max(0.0, f0)
    return brentq(residual, lo, hi, xtol=1e-14 * abs(f0), rtol=4 * np.finfo(float).eps)


def _hermite_root(d0, r0, d1, r1, dt):
    """Fraction s in [0, 1] of a step where the cubic Hermite of (d, d') crosses zero."""
    grid = np.linspace(0.0, 1.0, 33)

    def cubic(s):
        h00 = 2 * s**3 - 3 * s**2 + 1
        h10 = s**3 - 2 * s**2 + s
        h01 = -2 * s**3 + 3 * s**2
        h11 = s**3 - s**2
        return h00 * d0 + h10 * dt * r0 + h01 * d1 + h11 * dt * r1

    vals = cubic(grid)
    k = int(np.argmax(np.sign(vals[1:]) != np.sign(vals[0])))
    if np.sign(vals[k + 1]) == np.sign(vals[0]):
        return d0 / (d0 - d1)  # no sign change seen on the grid: linear fallback
    return brentq(cubic, grid[k], grid[k + 1], xtol=1e-15)


def _parabola_peak(t, y, j):
    """(value, time) of the vertex of the parabola through nodes j-1, j, j+1 (uniform
    steps), or of the node."""
    if j <= 0 or j >= len(y) - 1:
        return float(y[j]), float(t[j])
    y0, y1, y2 = y[j - 1], y[j], y[j + 1]
    curv = y0 - 2 * y1 + y2
    if curv >= 0:
        return float(y1), float(t[j])
    s = 0.5 * (y0 - y2) / curv
    return float(y1 - 0.25 * (y0 - y2) * s), float(t[j] + s * (t[j + 1] - t[j]))


def fe_reference(
    model,
    ball: Ball,
    law: ImpactLaw,
    duration: float,
    *,
    dt: float,
    load_radius: float = 0.0,
    sensors=(),
    rayleigh=(0.0, 0.0),
    gravity: float = STANDARD_GRAVITY,
    max_work: float = DEFAULT_MAX_WORK,
) -> FEReferenceResult:
    """One ball on the FE plate ``model`` (a tailbeam.plate.PlateModel) over [0, duration] s.

    dt: Newmark step (s); load_radius: radius (m) of the disc the contact force is spread over
    (0: point load); sensors: points (p, 2) m where deflection and acceleration are recorded;
    rayleigh: (alpha 1/s, beta s). Raises WorkLimitError (before any work) if the estimated
    cost, steps x (factor + matrix nonzeros), exceeds max_work.
    """
    check_inputs(ball, law, model, duration, dt, load_radius)
    load = model.load_vector(ball.position[:2], load_radius)
    probe = model.deflection_operator(np.reshape(sensors, (-1, 2))) if len(sensors) else None
    return integrate(model, ball, law, duration, dt=dt, load=load, probe=probe,
                     rayleigh=rayleigh, gravity=gravity, max_work=max_work,
                     info={"load_radius": load_radius})  # fmt: skip


def integrate(model, ball, law, duration, *, dt, load, probe, rayleigh=(0.0, 0.0),
              gravity=STANDARD_GRAVITY, max_work=DEFAULT_MAX_WORK, info=None,
              factorize=None) -> FEReferenceResult:  # fmt: skip
    """The Newmark run of ``fe_reference`` on any FE model (``stiffness``, ``mass`` on its
    DOFs, ``n_dofs``): ``load`` (n,) the contact's unit load vector (the deflection under the
    ball is load . u), ``probe`` a (p, n) sparse operator of the sensor readings (or None),
    ``factorize`` a factoriser of the effective stiffness (an object with ``solve``; None:
    SuperLU with minimum degree). Inputs checked by the caller (``check_inputs``)."""
    n_steps = int(math.ceil(duration / dt - 1e-9))
    nnz = model.stiffness.nnz + model.mass.nnz
    if n_steps * 10 * nnz > max_work:
        raise WorkLimitError(
            f"the FE reference needs ~{n_steps * 10 * nnz:.2g} operations ({n_steps} steps of "
            f"{model.n_dofs} DOFs) > max_work={max_work:.2g}; raise dt or max_work, or use a "
            "coarser mesh"
        )
    plate = _Plate(model, dt, rayleigh, load, factorize)
    with task("FE reference (Newmark)", total=n_steps, unit="steps") as bar:
        hist, vz_hist, sw, sa = _integrate(plate, probe, ball, law, n_steps, gravity, bar)
    t_hist = dt * np.arange(n_steps + 1)
    return FEReferenceResult(
        t=t_hist,
        force=hist[0],
        penetration=hist[1],
        sensor_w=sw,
        sensor_a=sa,
        impacts=_impacts(ball, t_hist, hist, vz_hist, dt),
        dt=dt,
        n_dofs=model.n_dofs,
        info={**(info or {}), "rayleigh": tuple(rayleigh), "steps": n_steps},
    )


def _integrate(plate, probe, ball, law, n_steps, gravity, bar):
    """The Newmark steps: histories (force, penetration, its rate), ball speeds, sensors."""
    dt, load = plate.dt, plate.f
    n = plate.K.shape[0]
    u, v, a = np.zeros(n), np.zeros(n), np.zeros(n)
    m, radius = ball.mass, ball.radius
    z, vz, az = ball.position[2], ball.velocity[2], -gravity
    hist = np.zeros((3, n_steps + 1))  # force, penetration, penetration rate
    hist[1, 0], hist[2, 0] = radius - z, -vz
    p = 0 if probe is None else probe.shape[0]
    sw, sa = np.zeros((p, n_steps + 1)), np.zeros((p, n_steps + 1))
    s_d = plate.s_w + dt**2 / (4.0 * m)
    s_v = 2.0 * plate.s_w / dt + dt / (2.0 * m)
    vz_hist = np.empty(n_steps + 1)
    vz_hist[0] = vz
    chunk = max(1, min(1000, n_steps // 100))  # progress: about every 1 % of the steps
    for k in range(1, n_steps + 1):
        u_hat = plate.predict(u, v, a)
        zb = z + dt * vz + 0.25 * dt**2 * (az - gravity)  # ball with no force at the end
        vb = vz + 0.5 * dt * (az - gravity)
        w0 = float(load @ u_hat)
        wd0 = 2.0 / dt * (w0 - float(load @ u)) - float(load @ v)
        force = _contact_force(law, radius - zb + w0, -vb + wd0, s_d, s_v)
        u, v, a = plate.correct(u, v, a, u_hat, force)
        az = -gravity + force / m
        z = zb + 0.25 * dt**2 * force / m
        vz = vb + 0.5 * dt * force / m
        hist[:, k] = force, radius - z + float(load @ u), -vz + float(load @ v)
        vz_hist[k] = vz
        if probe is not None:
            sw[:, k] = probe @ u
            sa[:, k] = probe @ a
        if k % chunk == 0:
            bar.update(chunk)
    return hist, vz_hist, sw, sa


def _impacts(ball, t, hist, vz, dt):
    """Located contacts of ``ball`` from the step histories (see the module docstring)."""
    force, delta, rate = hist
    inside = delta > 0.0
    starts = np.flatnonzero(~inside[:-1] & inside[1:])
    ends = np.flatnonzero(inside[:-1] & ~inside[1:])
    out = []
    for k0 in starts:
        later = ends[ends > k0]
        if not len(later):
            break
        k1 = int(later[0])
        s0 = _hermite_root(delta[k0], rate[k0], delta[k0 + 1], rate[k0 + 1], dt)
        s1 = _hermite_root(delta[k1], rate[k1], delta[k1 + 1], rate[k1 + 1], dt)
        v_in = float(-(vz[k0] + s0 * (vz[k0 + 1] - vz[k0])))
        v_out = float(vz[k1] + s1 * (vz[k1 + 1] - vz[k1]))
        seg = slice(k0, k1 + 2)
        peak, t_peak = _parabola_peak(t[seg], force[seg], int(np.argmax(force[seg])))
        out.append(
            Impact.single_ball(
                ball,
                index=len(out) + 1,
                t_start=float(t[k0] + s0 * dt),
                t_end=float(t[k1] + s1 * dt),
                v_in=v_in,
                v_out=v_out,
                peak_force=peak,
                t_peak=t_peak,
                max_penetration=_parabola_peak(t[seg], delta[seg], int(np.argmax(delta[seg])))[0],
                at_rest=False,
            )
        )
    return out


QUANTITIES = ("restitution", "peak_force", "duration", "max_penetration")


def impact_quantities(impact) -> dict:
    """The four compared contact quantities of an ``Impact`` (any solver's)."""
    return {
        "restitution": impact.restitution,
        "peak_force": impact.peak_force,
        "duration": impact.duration,
        "max_penetration": impact.max_penetration,
    }


def fe_time_step_study(model, ball, law, duration, dts, *, reference=None, **options) -> dict:
    """Run ``fe_reference`` (or ``reference``, a function of the same arguments, e.g.
    ``tailbeam.solvers.coupled.fe_structure.structure_fe_reference``) at each step of ``dts``
    (decreasing, each half the previous) and measure the convergence of the first impact's
    quantities.

    Returns {"runs": [results], "differences": {quantity: [|Q(dt_i) - Q(dt_i+1)| / |Q|]},
    "orders": {quantity: [log2 of successive difference ratios]}, "extrapolated": {quantity:
    Richardson value from the two finest steps (order 2)}, "error_estimate": {quantity:
    relative distance of the finest run from the extrapolated value}}.
    """
    dts = [float(d) for d in dts]
    if len(dts) < 2 or any(b >= a for a, b in zip(dts, dts[1:], strict=False)):
        raise InputError("dts", "need at least two decreasing time steps")
    reference = reference or fe_reference
    runs = [reference(model, ball, law, duration, dt=d, **options) for d in dts]
    qs = [impact_quantities(r.impacts[0]) for r in runs]
    diffs, orders, extra, est = {}, {}, {}, {}
    for name in QUANTITIES:
        vals = np.array([q[name] for q in qs])
        d = np.abs(np.diff(vals)) / abs(vals[-1])
        diffs[name] = d.tolist()
        orders[name] = [math.log2(d[i] / d[i + 1]) if d[i + 1] > 0 else math.inf
                        for i in range(len(d) - 1)]  # fmt: skip
        extra[name] = float(vals[-1] + (vals[-1] - vals[-2]) / 3.0)
        est[name] = abs(vals[-1] - extra[name]) / abs(extra[name])
    return {
        "runs": runs,
        "differences": diffs,
        "orders": orders,
        "extrapolated": extra,
        "error_estimate": est,
    }


def in_band(t, signal_values, band_hz: float, order: int = 8) -> np.ndarray:
    """Zero-phase low-pass (Butterworth, ``order``, sosfiltfilt) of a signal on the uniform
    times t (s): its content in 0-band_hz. Compare records over a window well before their end
    (the filter's end transient)."""
    from scipy import signal

    fs = 1.0 / (t[1] - t[0])
    sos = signal.butter(order, band_hz, fs=fs, output="sos")
    return signal.sosfiltfilt(sos, signal_values, axis=-1)


def relative_l2(test, ref) -> float:
    """||test - ref|| / ||ref|| (2-norms)."""
    return float(np.linalg.norm(np.asarray(test) - ref) / np.linalg.norm(ref))
