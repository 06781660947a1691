"""Probe (issue 9): what limits the contact error at a 20 kHz band - the time step or the tail?

    python benchmarks/probe_contact_tail.py [--theory kirchhoff|mindlin] [--part steps|pseudo|tail]

The case of tests/test_coupled_fe.py (Argyris 8x8 / Mindlin P4 6x6, SSSS, sandstone 30 mm at
1 m/s, plate damping 0) against the full-FE reference (tailbeam.coupled.fe_reference, 1e-7 s
Kirchhoff, 2e-7 s Mindlin). Three parts, each prints a markdown table (a few minutes each):

- steps: SIGNED relative errors of the four contact quantities at 14/20/28 kHz for 200, 400,
  800 and 1600 steps per contact (the 1600 row is converged in time to ~1e-6: the band error;
  the difference to it is the time-step error).
- pseudo: the truncated modes at the contact as k = 1..4 undamped pseudo-modes in the solver
  (the k-node Gauss quadrature of the tail's spectral measure in 1/omega^2, i.e. Lanczos /
  load-dependent Ritz vectors of the tail: k = 1 matches sum phi^2/omega^2 and
  sum phi^2/omega^4). A probe, not a feature: the exact tail is taken from every FE mode
  (Kirchhoff only: the 8x8 model's full spectrum) and the pseudo-modes are appended to the
  basis with a shape that is non-zero only within 2 cm of the impact point (the sensor, 7 cm
  away, does not see them; its quasi-static correction is unchanged).
- tail: offline, the tail's deflection at the contact under the reference's own force history,
  exact (every tail mode, exact propagation) against models of it: quasi-static C1 F; one
  pseudo-mode; a constant-density continuum above the band edge; and the damped filter
  C1 (1 + b1 s) / (1 + b1 s + s^2 / wp^2) (wp^2 = C1/C2, b1 = 2 zeta / wp), which matches C1
  and C2 without a first-order (dissipative) term. Kirchhoff only (needs every mode).
"""

import argparse
import sys
from pathlib import Path

import numpy as np
from scipy import signal
from scipy.linalg import eigh_tridiagonal
from scipy.special import sici

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from test_coupled_fe import IMPACT, REF_DT, _basis, _case  # noqa: E402

from tailbeam.coupled.fe_reference import impact_quantities  # noqa: E402
from tailbeam.coupled.propagator import advance, coefficients  # noqa: E402
from tailbeam.coupled.solver import simulate_coupled  # noqa: E402
from tailbeam.modal import ModalBasis  # noqa: E402

BANDS_HZ = (14e3, 20e3, 28e3)
SHORT = {"restitution": "e", "peak_force": "F_max", "duration": "T", "max_penetration": "d_max"}


def signed_errors(case, ref, basis, steps_per_contact):
    """Signed relative errors of the first impact's four quantities (modal - FE) / FE."""
    res = simulate_coupled([case.ball], basis, [case.law], float(ref.t[-1]),
                           gravity=case.gravity, damping_ratio=0.0,
                           steps_per_contact=steps_per_contact)  # fmt: skip
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
    vs, alpha, beta = [np.sqrt(w / w.sum())], [], []
    for j in range(k):
        u = s * vs[-1]
        for v in vs:  # full re-orthogonalisation (k is tiny)
            u -= (v @ u) * v
        alpha.append(vs[-1] @ (s * vs[-1]))
        if j < k - 1:
            beta.append(np.linalg.norm(u))
            vs.append(u / beta[-1])
    nodes, vecs = eigh_tridiagonal(np.array(alpha), np.array(beta))
    lam_p = 1.0 / nodes
    return np.sqrt(lam_p), np.sqrt(w.sum() * vecs[0] ** 2 * lam_p)


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
    full = _basis(theory, count=case.model.n_dofs)
    return full.load_deflection([IMPACT], case.load_radius)[0] ** 2, full.omega**2


def part_pseudo(theory, case, ref):
    phi2, lam = every_mode(theory, case)
    _header("band, tail model (800 steps/contact)")
    for f in BANDS_HZ:
        basis = _basis(theory, fmax_hz=f)
        n = basis.n_modes
        print(_row(f"{f / 1e3:.0f} kHz, quasi-static", signed_errors(case, ref, basis, 800)))
        for k in (1, 2, 3, 4):
            om_p, phi_p = tail_gauss(phi2[n:], lam[n:], k)
            err = signed_errors(case, ref, with_pseudo_modes(basis, om_p, phi_p), 800)
            fp = ", ".join(f"{x / 2e3 / np.pi:.1f}" for x in np.sort(om_p))
            print(_row(f"{f / 1e3:.0f} kHz, {k} pseudo-mode(s) at {fp} kHz", err), flush=True)


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


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--theory", default="kirchhoff", choices=["kirchhoff", "mindlin"])
    ap.add_argument("--part", default="steps", choices=["steps", "pseudo", "tail"])
    args = ap.parse_args()
    case = _case(args.theory)
    ref = case.reference(REF_DT[args.theory])
    {"steps": part_steps, "pseudo": part_pseudo, "tail": part_tail}[args.part](
        args.theory, case, ref
    )


if __name__ == "__main__":
    main()
