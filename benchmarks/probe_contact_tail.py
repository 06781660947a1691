"""Probe (issue 9): what limits the contact error at a 20 kHz band - the time step or the tail?

    python benchmarks/probe_contact_tail.py [--theory kirchhoff|mindlin]
        [--part steps|pseudo|tail|gauss|bins|ritz|cost|sensor] [--ks K ...]
        [--divisions N --ref-cache FILE.npz] [--rayleigh]

The case of tests/test_coupled_fe.py (Argyris 8x8 / Mindlin P4 6x6, SSSS, sandstone 30 mm at
1 m/s, plate damping 0) against the full-FE reference (tailbeam.solvers.coupled.fe_reference, 1e-7 s
Kirchhoff, 2e-7 s Mindlin). Each part prints a markdown table (seconds to a few minutes):

- steps: SIGNED relative errors of the four contact quantities at 14/20/28 kHz for 200, 400,
  800 and 1600 steps per contact (the 1600 row is converged in time to ~1e-6: the band error;
  the difference to it is the time-step error).
- pseudo: the truncated modes at the contact as k = 1..4 undamped pseudo-modes in the solver
  (the k-node Gauss quadrature of the tail's spectral measure in 1/omega^2, i.e. Lanczos /
  load-dependent Ritz vectors of the tail: k = 1 matches sum phi^2/omega^2 and
  sum phi^2/omega^4). A probe, not a feature: the exact tail is taken from every FE mode
  (the test meshes' full spectra, dense) and the pseudo-modes are appended to the basis with a
  shape that is non-zero only within 2 cm of the impact point (the sensor, 7 cm away, does
  not see them; its quasi-static correction is unchanged).
- gauss: the same with k = 4, 8, 16, 24, 32 nodes, 200 and 800 steps per contact (the label
  gives how many nodes lie within 5 kHz above the band edge and their largest gap).
- bins: the tail from the edge to +5/10/20 kHz kept mode by mode, or condensed into one
  pseudo-mode per frequency bin of 0.5-8 kHz (+20 kHz window): the node spacing a pseudo-mode
  tail needs (needs the spectrum; not an implementable method).
- ritz: the implementable version, load-dependent Ritz vectors from K, M and the load vector
  only (tailbeam.plate.ritz_tail), with their true shapes; on the test meshes checked against the
  exact-spectrum Gauss rule; ``--divisions 23`` runs the default Argyris mesh (reference of
  the first contact only, ~3-5 min, saved to / read from ``--ref-cache``). The label gives
  the a-posteriori change of the tail model from k to 2k pseudo-modes (RMS over a half-sine
  contact force, relative to the maximum penetration). ``--rayleigh``: the Rayleigh case.
- cost: speed against error at 20 kHz and 200 steps/contact, quasi-static baseline beside
  k Ritz pseudo-modes (construction time and solver run time).
- sensor: the in-band sensor error (fe_compare.modal_errors) with and without Ritz modes.
- tail: offline, the tail's deflection at the contact under the reference's own force history,
  exact (every tail mode, exact propagation) against models of it: quasi-static C1 F; one
  pseudo-mode; a constant-density continuum above the band edge; and the damped filter
  C1 (1 + b1 s) / (1 + b1 s + s^2 / wp^2) (wp^2 = C1/C2, b1 = 2 zeta / wp), which matches C1
  and C2 without a first-order (dissipative) term. Kirchhoff only (needs every mode).
"""

import argparse
import itertools
import math
import sys
import time
from pathlib import Path
from types import SimpleNamespace
from unittest import mock

import numpy as np
from scipy import signal
from scipy.linalg import eigh_tridiagonal
from scipy.special import sici

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from test_coupled_fe import IMPACT, MESHES, REF_DT, SENSOR, R, _basis, _case  # noqa: E402

from tailbeam.physics.bodies import Ball, Plate  # noqa: E402
from tailbeam.physics.contact_law import ball_plate_law  # noqa: E402
from tailbeam.physics.materials import CARBON_STEEL, SANDSTONE  # noqa: E402
from tailbeam.plate import assemble_plate, compute_modes, sparse_solve  # noqa: E402
from tailbeam.plate.basis import ModalBasis  # noqa: E402
from tailbeam.plate.ritz_tail import choose_ritz_k, ritz_tail_modes, with_ritz_tail  # noqa: E402
from tailbeam.results.records import Impact  # noqa: E402
from tailbeam.solvers.coupled.fe_compare import Case, modal_errors  # noqa: E402
from tailbeam.solvers.coupled.fe_reference import impact_quantities  # noqa: E402
from tailbeam.solvers.coupled.solver import simulate_coupled  # noqa: E402
from tailbeam.solvers.plate_loads.propagator import advance, coefficients  # noqa: E402

BANDS_HZ = (14e3, 20e3, 28e3)
SHORT = {"restitution": "e", "peak_force": "F_max", "duration": "T", "max_penetration": "d_max"}


def signed_errors(case, ref, basis, steps_per_contact):
    """Signed relative errors of the first impact's four quantities (modal - FE) / FE."""
    damping = {"rayleigh": case.rayleigh} if case.rayleigh != (0.0, 0.0) else {}
    res = simulate_coupled([case.ball], basis, [case.law], float(ref.t[-1]),
                           gravity=case.gravity, damping_ratio=0.0,
                           steps_per_contact=steps_per_contact, **damping)  # fmt: skip
    q, q_ref = impact_quantities(res.impacts[0]), impact_quantities(ref.impacts[0])
    return {k: q[k] / q_ref[k] - 1.0 for k in q}


def _row(label, err):
    cells = " | ".join(f"{v:+.2e}" for v in err.values())
    return f"| {label} | {max(abs(v) for v in err.values()):.2e} | {cells} |"


def _header(first):
    names = " | ".join(SHORT.values())
    print(f"| {first} | max | {names} |\n|---|---|" + "---|" * len(SHORT))


def part_steps(theory, case, ref):
    _header("band, steps/contact")
    for f in BANDS_HZ:
        basis = _basis(theory, fmax_hz=f)
        for spc in (200, 400, 800, 1600):
            err = signed_errors(case, ref, basis, spc)
            print(_row(f"{f / 1e3:.0f} kHz ({basis.n_modes} modes), {spc}", err), flush=True)


def tail_gauss(phi2, lam, k):
    """k pseudo-modes (omega, phi) of the tail measure sum phi2 delta(lam): Gauss quadrature in
    s = 1/lam of the weights phi2/lam (Lanczos), so sum phi^2/omega^(2m+2), m < 2k, match."""
    w, s = phi2 / lam, 1.0 / lam
    alpha, beta = _lanczos(s, np.sqrt(w / w.sum()), k)
    nodes, vecs = eigh_tridiagonal(alpha, beta)
    lam_p = 1.0 / nodes
    return np.sqrt(lam_p), np.sqrt(w.sum() * vecs[0] ** 2 * lam_p)


def _lanczos(s, v0, k):
    """Jacobi matrix (alpha (k,), beta (k-1,)) of diag(s) from the unit vector v0, fully
    re-orthogonalised twice per step (stable for k up to a good fraction of len(s))."""
    vs, alpha, beta = [v0], [], []
    for j in range(k):
        u = s * vs[-1]
        alpha.append(vs[-1] @ u)
        for _ in range(2):
            basis = np.array(vs)
            u -= basis.T @ (basis @ u)
        if j < k - 1:
            beta.append(np.linalg.norm(u))
            vs.append(u / beta[-1])
    return np.array(alpha), np.array(beta)


def stieltjes_gauss(phi2, lam, k):
    """The same Gauss rule as ``tail_gauss`` by an independent route (check only): the
    discretised Stieltjes procedure (three-term recurrence of the monic orthogonal polynomials
    evaluated on the support, no re-orthogonalisation) in extended precision."""
    w, s = (np.asarray(x, dtype=np.longdouble) for x in (phi2 / lam, 1.0 / lam))
    p_prev, p = np.zeros_like(s), np.ones_like(s)
    norm_prev, alpha, beta = None, [], []
    for _ in range(k):
        norm = np.sum(w * p * p)
        alpha.append(np.sum(w * s * p * p) / norm)
        b = 0.0 if norm_prev is None else norm / norm_prev
        if norm_prev is not None:
            beta.append(np.sqrt(b))
        p_prev, p = p, (s - alpha[-1]) * p - b * p_prev
        norm_prev = norm
    nodes, vecs = eigh_tridiagonal(np.array(alpha, float), np.array(beta, float))
    lam_p = 1.0 / nodes
    return np.sqrt(lam_p), np.sqrt(float(w.sum()) * vecs[0] ** 2 * lam_p)


def with_pseudo_modes(basis, omega_p, phi_p):
    """``basis`` plus pseudo-modes seen only within 2 cm of the impact point (probe only)."""
    parent = basis.deflection_at

    def deflection_at(points):
        near = np.all(np.abs(points - np.asarray(IMPACT)) < 0.02, axis=1).astype(float)
        return np.column_stack([np.asarray(parent(points)), near[:, None] * phi_p[None, :]])

    freqs = np.append(basis.frequencies_hz, omega_p / (2.0 * np.pi))
    return ModalBasis(basis.plate, freqs, deflection_at, basis.theory, basis.boundary,
                      basis.static_compliance_at, basis.static_deflection_at)  # fmt: skip


def every_mode(theory, case):
    """(phibar^2, omega^2) of every FE mode at the impact point (dense eigensolver: the test
    meshes have 590 / 1679 DOFs, a few seconds)."""
    with mock.patch.object(sparse_solve, "DENSE_LIMIT", max(case.model.n_dofs, 800)):
        full = _basis(theory, count=case.model.n_dofs)
    return full.load_deflection([IMPACT], case.load_radius)[0] ** 2, full.omega**2


def part_pseudo(theory, case, ref):
    def at(om_p, _f):
        return "at " + ", ".join(f"{x / 2e3 / np.pi:.1f}" for x in np.sort(om_p)) + " kHz"

    _gauss_table(theory, case, ref, (1, 2, 3, 4), (800,), at)


KS = (4, 8, 16, 24, 32)


def _near_edge(omega_p, f_edge, width=5e3):
    """'m nodes, max gap g kHz' of the pseudo-mode frequencies within ``width`` Hz of the edge."""
    f = np.sort(np.append(omega_p / (2.0 * np.pi), f_edge))
    f = f[f <= f_edge + width]
    gap = np.max(np.diff(f)) / 1e3 if len(f) > 1 else np.nan
    return f"{len(f) - 1} in +5 kHz, gap {gap:.1f} kHz"


def part_gauss(theory, case, ref):
    """k = 4..32 Gauss pseudo-modes of the exact tail, 200 and 800 steps per contact."""
    _gauss_table(theory, case, ref, KS, (200, 800), _near_edge)


def _gauss_table(theory, case, ref, ks, steps, describe):
    """Rows of the quasi-static residual and of k-node Gauss tails (``describe(omega, band)``
    labels the nodes) at each band and number of steps per contact."""
    phi2, lam = every_mode(theory, case)
    _header("band, tail model, steps/contact")
    for f in BANDS_HZ:
        basis = _basis(theory, fmax_hz=f)
        n = basis.n_modes
        for spc in steps:
            err = signed_errors(case, ref, basis, spc)
            print(_row(f"{f / 1e3:.0f} kHz ({n} modes), quasi-static, {spc}", err), flush=True)
        for k in ks:
            om_p, phi_p = tail_gauss(phi2[n:], lam[n:], k)
            pseudo = with_pseudo_modes(basis, om_p, phi_p)
            for spc in steps:
                err = signed_errors(case, ref, pseudo, spc)
                label = f"{f / 1e3:.0f} kHz, k = {k} ({describe(om_p, f)}), {spc}"
                print(_row(label, err), flush=True)


def bin_modes(phi2, lam, f_edge, bin_hz, window_hz):
    """One pseudo-mode per frequency bin of width ``bin_hz`` from the band edge to
    ``f_edge + window_hz`` (the bin's 1-node Gauss rule: its C1 and C2), or, for
    ``bin_hz`` 0, every tail mode of the window itself. Modes above the window are left to
    the quasi-static residual."""
    f = np.sqrt(lam) / (2.0 * np.pi)
    inside = f <= f_edge + window_hz
    if bin_hz == 0:
        return np.sqrt(lam[inside]), np.sqrt(phi2[inside])
    which = np.floor((f[inside] - f_edge) / bin_hz).astype(int)
    om, ph = [], []
    for b in np.unique(which):
        o, p = tail_gauss(phi2[inside][which == b], lam[inside][which == b], 1)
        om.append(o[0])
        ph.append(p[0])
    return np.array(om), np.array(ph)


def part_bins(theory, case, ref):
    """The tail near the edge condensed into frequency bins (needs the spectrum: a probe of
    the node spacing a pseudo-mode tail needs, not an implementable method)."""
    phi2, lam = every_mode(theory, case)
    _header("band, bins (width / window above the edge), steps/contact")
    for f in BANDS_HZ:
        basis = _basis(theory, fmax_hz=f)
        n = basis.n_modes
        for window, width in [(5e3, 0), (10e3, 0), (20e3, 0)] + [
            (20e3, b) for b in (0.5e3, 1e3, 2e3, 4e3, 8e3)
        ]:
            om_p, phi_p = bin_modes(phi2[n:], lam[n:], f, width, window)
            pseudo = with_pseudo_modes(basis, om_p, phi_p)
            what = "every mode" if width == 0 else f"bins {width / 1e3:g} kHz"
            for spc in (200, 800):
                err = signed_errors(case, ref, pseudo, spc)
                label = f"{f / 1e3:.0f} kHz, {what} to +{window / 1e3:g} kHz ({len(om_p)}), {spc}"
                print(_row(label, err), flush=True)


RAYLEIGH = (60.0, 2e-7)  # tests/test_coupled_fe.py's Rayleigh case (alpha 1/s, beta s)
CONTACT_RECORD_S = 6e-4  # the --divisions reference: the first contact (ends at ~0.35 ms) only


def mesh_case(theory, divisions, rayleigh=(0.0, 0.0), ball=None):
    """The test case on a ``divisions`` mesh (None: the test mesh), Rayleigh (alpha 1/s,
    beta s) plate damping, and ``ball`` (radius m, speed m/s; None: the test's sandstone ball,
    30 mm at 1 m/s), always at the test's impact point."""
    if divisions is None and ball is None:
        return _case(theory, rayleigh=rayleigh)
    div = MESHES[theory] if divisions is None else divisions
    model = assemble_plate(Plate(), "SSSS", theory=theory, divisions=div)
    radius, speed = (R, 1.0) if ball is None else ball
    b = Ball("b", SANDSTONE, radius, (*IMPACT, radius + 1e-5), (0.0, 0.0, -speed))
    law = ball_plate_law(SANDSTONE, radius, CARBON_STEEL)
    return Case(model, b, law, SENSOR, rayleigh=rayleigh)


def band_basis(theory, divisions, fmax_hz):
    if divisions is None:
        return _basis(theory, fmax_hz=fmax_hz)
    return compute_modes(Plate(), "SSSS", theory=theory, divisions=divisions, fmax_hz=fmax_hz)


# the FE reference's first contact as the .npz cache keeps it
CACHED_FIELDS = ("t_start", "t_end", "v_in", "v_out", "peak_force", "max_penetration")


def cached_reference(case, theory, custom, cache):
    """The FE reference: the test one (3.5 ms) for the test case, else (``custom``) the first
    contact only (CONTACT_RECORD_S), read from / saved to the .npz ``cache`` when given."""
    if not custom:
        return case.reference(REF_DT[theory])
    if cache is not None and Path(cache).exists():
        data = np.load(cache)
        print(f"reference read from {cache}", flush=True)
        fields = {k: float(data[k]) for k in CACHED_FIELDS}
        imp = Impact(ball="cached", x=math.nan, y=math.nan, approach_in=fields["v_in"],
                     approach_out=fields["v_out"], end="separated", **fields)  # fmt: skip
        return SimpleNamespace(t=data["t"], force=data["force"], impacts=[imp])
    ref = case.reference(REF_DT[theory], duration=CONTACT_RECORD_S, max_work=1e14)
    if not ref.impacts:
        raise SystemExit(f"the first contact does not end within {CONTACT_RECORD_S} s")
    if cache is not None:
        imp = ref.impacts[0]
        fields = {k: getattr(imp, k) for k in CACHED_FIELDS}
        np.savez(cache, t=ref.t, force=ref.force, **fields)
    return ref


def ritz_at_impact(basis, case, k):
    """(omega (k,), f.z (k,)) of k Ritz pseudo-modes for the impact's load."""
    load = case.model.load_vector(IMPACT, case.load_radius)
    omega, Z = ritz_tail_modes(basis, load[:, None], k)
    return omega, load @ Z


def part_ritz(theory, case, ref, divisions=None, ks=KS):
    """Ritz pseudo-modes from K, M and the load vector only (no spectrum), in the solver; on the
    test meshes also checked against the Gauss rule of the exact spectrum."""
    model = case.model
    full = every_mode(theory, case) if model.n_dofs <= 2000 else None
    _header("band, tail model, steps/contact")
    for f in BANDS_HZ:
        basis = band_basis(theory, divisions, f)
        for spc in (200, 800):
            err = signed_errors(case, ref, basis, spc)
            label = f"{f / 1e3:.0f} kHz ({basis.n_modes} modes), quasi-static, {spc}"
            print(_row(label, err), flush=True)
        for k in ks:
            _ritz_rows(case, ref, basis, f, k, full)


def _ritz_rows(case, ref, basis, f, k, full):
    """The solver with k Ritz pseudo-modes, 200 and 800 steps per contact; the label gives the
    nodes near the edge and the a-posteriori change of the tail model from k to 2k."""
    om_p, phibar = ritz_at_impact(basis, case, k)
    om_2, phibar_2 = ritz_at_impact(basis, case, 2 * k)
    if full is not None:
        print(_gauss_check(full, basis.n_modes, k, om_p, phibar))
    imp = ref.impacts[0]
    change = tail_change((om_p, phibar), (om_2, phibar_2), imp.duration, imp.peak_force)
    change /= imp.max_penetration
    pseudo = with_ritz_tail(basis, [IMPACT], case.load_radius, k)
    for spc in (200, 800):
        err = signed_errors(case, ref, pseudo, spc)
        label = (
            f"{f / 1e3:.0f} kHz, Ritz k = {k} ({_near_edge(om_p, f)}; k->2k {change:.1e}), {spc}"
        )
        print(_row(label, err), flush=True)


def tail_change(model_a, model_b, duration, peak, steps=2000):
    """RMS difference (m) of two pseudo-mode tails (omega (k,), f.z (k,)) over a half-sine
    contact force of ``duration`` s and ``peak`` N."""
    t = np.linspace(0.0, duration, steps + 1)
    force = peak * np.sin(np.pi * t / duration)
    wa, wb = (tail_response(t, force, om, ph**2) for om, ph in (model_a, model_b))
    return float(np.sqrt(np.mean((wa - wb) ** 2)))


def _best_time(fn, repeat=3):
    """(result, best wall time s of ``repeat`` calls)."""
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return out, best


def part_cost(theory, case, ref, divisions=None, ks=KS, band=20e3, spc=200):
    """Speed against error at a 20 kHz band, default 200 steps/contact: the quasi-static
    residual (baseline) and k Ritz pseudo-modes (their construction and the solver run;
    best of 3 wall times, one core)."""
    basis = band_basis(theory, divisions, band)
    print(f"| {theory}, {case.model.n_dofs} DOFs, {band / 1e3:.0f} kHz, {spc} steps/contact "
          "| modes | Ritz build (s) | solver run (s) | max contact error |")  # fmt: skip
    print("|---|---|---|---|---|")
    err, run = _best_time(lambda: signed_errors(case, ref, basis, spc))
    worst = max(abs(v) for v in err.values())
    print(f"| quasi-static | {basis.n_modes} | - | {run:.2f} | {worst:.2e} |", flush=True)
    for k in ks:
        pseudo, build = _best_time(lambda k=k: with_ritz_tail(basis, [IMPACT], case.load_radius, k))
        err, run = _best_time(lambda pseudo=pseudo: signed_errors(case, ref, pseudo, spc))
        worst = max(abs(v) for v in err.values())
        print(f"| Ritz k = {k} | {basis.n_modes + k} | {build:.3f} | {run:.2f} | {worst:.2e} |",
              flush=True)  # fmt: skip
    imp = ref.impacts[0]
    contact = (imp.duration, imp.peak_force, imp.max_penetration)
    (k, change), took = _best_time(
        lambda: choose_ritz_k(basis, IMPACT, case.load_radius, *contact), repeat=1
    )
    print(f"choose_ritz_k (tol 1e-5, the reference's contact): k = {k}, change {change:.1e}, "
          f"{took:.1f} s")  # fmt: skip


def part_sensor(theory, case, ref, divisions=None, ks=KS):
    """The in-band sensor error (0-10 kHz, fe_compare.modal_errors, with its quasi-static
    correction) and the contact error, quasi-static against k Ritz pseudo-modes with their
    true shapes (seen at the sensor; the correction then subtracts their statics too).
    Test meshes only (the reference records the sensor), 200 and 800 steps per contact."""
    print("| band, tail model, steps/contact | contact | sensor | sensor without QS |")
    print("|---|---|---|---|")
    for f in BANDS_HZ:
        basis = band_basis(theory, divisions, f)
        models = {"quasi-static": basis}
        for k in ks:
            models[f"Ritz k = {k}"] = with_ritz_tail(basis, [IMPACT], case.load_radius, k)
        for (name, b), spc in itertools.product(models.items(), (200, 800)):
            err = modal_errors(case, b, ref, steps_per_contact=spc)
            print(f"| {f / 1e3:.0f} kHz, {name}, {spc} | {err['contact']:.2e} | "
                  f"{err['sensor']:.2e} | {err['sensor_no_qs']:.2e} |", flush=True)  # fmt: skip


def _gauss_check(full, n, k, om_p, phibar):
    """Largest relative difference of the Ritz pseudo-modes to the exact-spectrum Gauss rule."""
    phi2, lam = full
    om_g, ph_g = tail_gauss(phi2[n:], lam[n:], k)
    i, j = np.argsort(om_p), np.argsort(om_g)
    d_om = np.max(np.abs(om_p[i] / om_g[j] - 1.0))
    d_ph = np.max(np.abs(np.abs(phibar[i]) / ph_g[j] - 1.0))
    return f"  (k = {k}: Ritz vs exact-spectrum Gauss: omega {d_om:.1e}, |f.z| {d_ph:.1e})"


def tail_response(t, force, omega, amp2):
    """sum amp2_i q_i(t), q_i'' + omega_i^2 q_i = force(t), exact for piecewise-linear force."""
    n = len(omega)
    coef = np.zeros((8, n))
    coefficients(omega, np.zeros(n), t[1] - t[0], coef)
    q, qd, q1, qd1 = (np.zeros(n) for _ in range(4))
    out = np.zeros(len(t))
    for j in range(len(t) - 1):
        advance(coef, q, qd, np.full(n, force[j]), np.full(n, force[j + 1]), q1, qd1)
        q, q1, qd, qd1 = q1, q, qd1, qd
        out[j + 1] = amp2 @ q
    return out


def tail_models(t, force, c1, c2, omega_edge):
    """Models of the tail deflection at the contact (m) for the force history (N)."""
    wp = np.sqrt(c1 / c2)
    out = {"quasi-static C1 F": c1 * force}
    out["1 pseudo-mode"] = tail_response(t, force, np.array([wp]), np.array([c1 * wp**2]))
    kernel = c1 * omega_edge * (0.5 * np.pi - sici(omega_edge * (t - t[0]))[0])
    out["continuum above the band"] = np.convolve(kernel, force)[: len(t)] * (t[1] - t[0])
    for zeta in (0.3, 0.7, 1.5):
        b1 = 2.0 * zeta / wp
        lti = signal.lti([c1 * b1, c1], [1.0 / wp**2, b1, 1.0])
        out[f"damped filter, zeta {zeta}"] = signal.lsim(lti, force, t - t[0])[1]
    return out


def part_tail(theory, case, ref):
    phi2, lam = every_mode(theory, case)
    t, force, imp = ref.t, ref.force, ref.impacts[0]
    k_peak = int(np.argmax(force))
    contact = (t >= imp.t_start) & (t <= imp.t_end)
    print(f"contact {imp.duration * 1e6:.0f} us, max penetration {imp.max_penetration:.3e} m")
    print("| band | model | error at the force peak (m) | RMS error over the contact (m) |")
    print("|---|---|---|---|")
    for f in BANDS_HZ:
        n = _basis(theory, fmax_hz=f).n_modes
        c1, c2 = np.sum(phi2[n:] / lam[n:]), np.sum(phi2[n:] / lam[n:] ** 2)
        exact = tail_response(t, force, np.sqrt(lam[n:]), phi2[n:])
        for name, w in tail_models(t, force, c1, c2, 2.0 * np.pi * f).items():
            e = w - exact
            rms = np.sqrt(np.mean(e[contact] ** 2))
            print(f"| {f / 1e3:.0f} kHz | {name} | {e[k_peak]:+.2e} | {rms:.2e} |", flush=True)


def _arguments(parts):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--theory", default="kirchhoff", choices=["kirchhoff", "mindlin"])
    ap.add_argument("--part", default="steps", choices=list(parts))
    ap.add_argument("--divisions", type=int, help="ritz/cost: this mesh (e.g. 23)")
    ap.add_argument(
        "--ball",
        type=float,
        nargs=2,
        metavar=("RADIUS", "SPEED"),
        help="ritz/cost: another sandstone ball (m, m/s)",
    )
    ap.add_argument(
        "--ks",
        type=int,
        nargs="+",
        default=list(KS),
        help="ritz/cost/sensor: the numbers of Ritz pseudo-modes",
    )
    ap.add_argument(
        "--rayleigh",
        action="store_true",
        help="ritz/cost: Rayleigh plate damping alpha 60 1/s, beta 2e-7 s",
    )
    ap.add_argument("--ref-cache", help="with --divisions/--ball: .npz to read/save the FE "
                    "reference")  # fmt: skip
    args = ap.parse_args()
    args.custom = args.divisions is not None or args.ball is not None
    if (args.custom or args.rayleigh) and args.part not in ("ritz", "cost"):
        ap.error("--divisions, --ball, --rayleigh: --part ritz or cost only")
    return args


def main():
    parts = {"steps": part_steps, "pseudo": part_pseudo, "tail": part_tail, "gauss": part_gauss,
             "bins": part_bins, "ritz": part_ritz, "cost": part_cost,
             "sensor": part_sensor}  # fmt: skip
    args = _arguments(parts)
    rayleigh = RAYLEIGH if args.rayleigh else (0.0, 0.0)
    case = mesh_case(args.theory, args.divisions, rayleigh, args.ball)
    ref = cached_reference(case, args.theory, args.custom, args.ref_cache)
    if args.part in ("ritz", "cost", "sensor"):
        parts[args.part](args.theory, case, ref, args.divisions, args.ks)
    else:
        parts[args.part](args.theory, case, ref)


if __name__ == "__main__":
    main()
