"""Compiled loops of ``tailbeam.solvers.plate_loads.response`` (numba).

The modal state is split into a particular and a homogeneous part. While the total force on
mode i is linear in time, f_i(t) = f + s t, the particular solution of
q'' + 2 zeta omega q' + omega^2 q = f_i is q_p = f/omega^2 - 2 zeta s/omega^3 (+ s t/omega^2),
q_p' = s/omega^2, q_p'' = 0. At a node of a load its value jumps by dF and its slope by dS;
q and q' are continuous, so the homogeneous part h = q - q_p jumps by
(dq, dv) = phi_load (dF/omega^2 - 2 zeta dS/omega^3, dS/omega^2) (the load presses down:
f = -phi_load F). Between jumps h is a free damped oscillation, propagated exactly by the
transition matrix P(tau) (closed form, zeta < 1). So:

- ``march``: h at every output sample (one P(dt) per sample and mode), each load node's jump
  propagated from the node to the next sample: a load's nodes within one sample interval are
  chained (acc <- P(gap) acc + J, P(gap) shared while the node steps are equal), then one
  P(delta) per load, sample and mode; the plate at the points from h alone, and its
  acceleration exactly: q'' = h'' (q_p'' = 0).
- ``add_particular``: per load, the particular part at the points over the samples the load
  acts on (its static-like part through the precomputed G = sum phi(P) phi_load/omega^2 and
  H = sum phi(P) phi_load 2 zeta/omega^3), and the truncated modes' quasi-static response
  -R F(t) with the central differences of the sampled force (as ``ModalReplay`` does).

A node belongs to the first sample at or after it (``target``); the particular part of a
segment is used from its first node's target up to (not including) its last node's target,
so the two parts are split at the same samples and their sum is exact.
"""

import math

import numpy as np

from tailbeam.jit import njit

EPS = 2.220446049250313e-16  # float64 machine epsilon


@njit(cache=True)
def transition(mu, zw, w2, tau, out):
    """Fill ``out`` (4, n) with the free damped transition matrix P(tau) of every mode:
    (q, q')(t + tau) = [[p11, p12], [p21, p22]] (q, q')(t); mu the damped frequencies,
    zw = zeta omega, w2 = omega^2 (rad/s units)."""
    for i in range(mu.shape[0]):
        e = math.exp(-zw[i] * tau)
        c = math.cos(mu[i] * tau)
        s = math.sin(mu[i] * tau) / mu[i]
        out[0, i] = e * (c + zw[i] * s)
        out[1, i] = e * s
        out[2, i] = -e * w2[i] * s
        out[3, i] = e * (c - zw[i] * s)


@njit(cache=True)
def march(
    j_from, j_to, t0, dt, pdt, mu, zw, w2, qh, vh, phi_pts, k_target, k_time, k_row, k_df, k_ds,
    phi_tab, ulps, out_w, out_v, out_a,
):  # fmt: skip
    """Advance the homogeneous state (qh, vh) (n,), given at sample j_from - 1, through samples
    j_from..j_to (inclusive) of the grid t0 + j dt (s), adding the jumps of the load nodes
    targeted there (sorted by k_target, a load's nodes in time order; k_time the node time s,
    k_row the node's row of phi_tab (rows, n), k_df, k_ds the jumps of the load's value (N)
    and slope (N/s) there; ``ulps``: see _run_jumps), and write the points' homogeneous
    deflection, velocity and (exact) acceleration into out_* (p, samples). Returns the number
    of nodes consumed."""
    n = mu.shape[0]
    acc = np.empty((2, n))
    pg = np.empty((4, n))
    kp = 0
    nk = k_target.shape[0]
    for j in range(j_from, j_to + 1):
        if j > 0:
            for i in range(n):
                q = qh[i]
                v = vh[i]
                qh[i] = pdt[0, i] * q + pdt[1, i] * v
                vh[i] = pdt[2, i] * q + pdt[3, i] * v
        while kp < nk and k_target[kp] == j:
            ke = kp + 1  # the run of this load's nodes in this sample
            while ke < nk and k_target[ke] == j and k_row[ke] == k_row[kp]:
                ke += 1
            if ke - kp > 1 or k_df[kp] != 0.0 or k_ds[kp] != 0.0:
                phi_load = phi_tab[k_row[kp]]
                tau = _run_jumps(mu, zw, w2, k_time, k_df, k_ds, kp, ke, phi_load, ulps, acc, pg)
                _add_propagated(mu, zw, w2, qh, vh, (t0 + j * dt) - tau, acc)
            kp = ke
        for p in range(phi_pts.shape[0]):
            w = 0.0
            v = 0.0
            a = 0.0
            for i in range(n):
                ph = phi_pts[p, i]
                w += ph * qh[i]
                v += ph * vh[i]
                a -= ph * (2.0 * zw[i] * vh[i] + w2[i] * qh[i])
            out_w[p, j] = w
            out_v[p, j] = v
            out_a[p, j] = a
    return kp


@njit(cache=True)
def _run_jumps(mu, zw, w2, k_time, k_df, k_ds, a, b, phi_load, ulps, acc, pg):
    """acc (2, n) = the homogeneous jumps of one load's nodes a..b-1 (time order), chained:
    acc <- P(gap) acc + J at each node; returns the time (s) acc refers to. P(gap) is reused
    while the step from that time to the next node is within ``ulps`` ulps (of the node time)
    of the last computed one (equal node steps whose times were rounded): each node's jump is
    then placed within ``ulps`` ulps of its time, never drifting along the run; ulps = 0
    places every node exactly (a transition matrix per node whose step differs)."""
    n = mu.shape[0]
    last_gap = -1.0
    tau = k_time[a]
    for k in range(a, b):
        if k > a:
            gap = k_time[k] - tau
            if abs(gap - last_gap) > ulps * EPS * abs(k_time[k]):
                transition(mu, zw, w2, gap, pg)
                last_gap = gap
                tau = k_time[k]
            else:
                tau += last_gap
            for i in range(n):
                q = acc[0, i]
                v = acc[1, i]
                acc[0, i] = pg[0, i] * q + pg[1, i] * v
                acc[1, i] = pg[2, i] * q + pg[3, i] * v
        d_f = k_df[k]
        d_s = k_ds[k]
        for i in range(n):
            inv_w2 = 1.0 / w2[i]
            dq = phi_load[i] * (d_f - 2.0 * zw[i] * inv_w2 * d_s) * inv_w2
            dv = phi_load[i] * d_s * inv_w2
            if k == a:
                acc[0, i] = dq
                acc[1, i] = dv
            else:
                acc[0, i] += dq
                acc[1, i] += dv
    return tau


@njit(cache=True)
def _add_propagated(mu, zw, w2, qh, vh, delta, acc):
    """(qh, vh) += P(delta) acc: jumps at a node time, propagated over ``delta`` s to the
    sample."""
    for i in range(mu.shape[0]):
        dq = acc[0, i]
        dv = acc[1, i]
        if delta == 0.0:
            qh[i] += dq
            vh[i] += dv
            continue
        e = math.exp(-zw[i] * delta)
        c = math.cos(mu[i] * delta)
        s = math.sin(mu[i] * delta) / mu[i]
        qh[i] += e * ((c + zw[i] * s) * dq + s * dv)
        vh[i] += e * (-w2[i] * s * dq + (c - zw[i] * s) * dv)


@njit(cache=True)
def add_particular(t0, dt, t, force, first, last, target, G, H, R, buf, out_w, out_v, out_a):
    """Add every load's particular part (through G, H (loads, p)) and its quasi-static
    residual response (R (loads, p), m/N; zeros for none) at the points. Loads are the node
    ranges first[l]..last[l] (inclusive) of t (s) and force (N); target (nodes,) the sample of
    each node; buf a scratch array of at least any load's span in samples + 4."""
    n_samples = out_w.shape[1]
    n_pts = out_w.shape[0]
    for ld in range(first.shape[0]):
        ja = target[first[ld]]
        jb = min(target[last[ld]], n_samples)
        if ja >= n_samples:
            continue
        # the force at samples ja-1..jb in buf[2 + j - ja] (zero beyond, buf[0] = 0)
        buf[0] = 0.0
        buf[1] = _force_at(t0 - dt, t, force, first[ld], last[ld]) if ja == 0 else 0.0
        for k in range(first[ld], last[ld]):
            lo = max(target[k], 0)
            hi = min(target[k + 1], n_samples)
            if hi <= lo:
                continue
            span = t[k + 1] - t[k]
            slope = (force[k + 1] - force[k]) / span
            for j in range(lo, hi):
                f = force[k] + slope * (t0 + j * dt - t[k])
                buf[2 + j - ja] = f
                for p in range(n_pts):
                    out_w[p, j] -= f * G[ld, p] - slope * H[ld, p]
                    out_v[p, j] -= slope * G[ld, p]
        buf[2 + jb - ja] = _force_at(t0 + jb * dt, t, force, first[ld], last[ld])
        buf[3 + jb - ja] = 0.0
        for j in range(max(ja - 1, 0), min(jb + 1, n_samples)):
            fm, f0, fp = buf[1 + j - ja], buf[2 + j - ja], buf[3 + j - ja]
            for p in range(n_pts):
                r = R[ld, p]
                if r != 0.0:
                    out_w[p, j] -= r * f0
                    out_v[p, j] -= r * (fp - fm) / (2.0 * dt)
                    out_a[p, j] -= r * (fp - 2.0 * f0 + fm) / (dt * dt)
    return 0


@njit(cache=True)
def jumps_kernel(t, force, first, last, t0, dt, n_samples, df, ds, target):
    """Fill df (N), ds (N/s): the jumps of each node's load value and slope (the load is zero
    outside its nodes, linear between them), and target: the first sample at or after the
    node (clipped to 0..n_samples)."""
    for ld in range(first.shape[0]):
        slope_before = 0.0
        for k in range(first[ld], last[ld] + 1):
            left = force[k] if k > first[ld] else 0.0
            right = force[k] if k < last[ld] else 0.0
            slope = 0.0
            if k < last[ld] and t[k + 1] > t[k]:
                slope = (force[k + 1] - force[k]) / (t[k + 1] - t[k])
            df[k] = right - left
            ds[k] = slope - slope_before
            slope_before = slope
            u = math.ceil((t[k] - t0) / dt)
            target[k] = int(min(max(u, 0.0), float(n_samples)))
    return 0


@njit(cache=True)
def _force_at(time, t, force, first, last):
    """The force (N) of the load with nodes first..last at ``time`` s (right-continuous, zero
    outside [t[first], t[last]))."""
    if time < t[first] or time >= t[last]:
        return 0.0
    k = first
    while t[k + 1] <= time:
        k += 1
    return force[k] + (force[k + 1] - force[k]) * (time - t[k]) / (t[k + 1] - t[k])


def empty_outputs(n_points, n_samples):
    """Three zeroed (p, samples) arrays for march/add_particular."""
    return tuple(np.zeros((n_points, n_samples)) for _ in range(3))
