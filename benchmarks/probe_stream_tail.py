"""Probe of a design not built yet: a dynamic tail of a few oscillators per stream contact.

    python benchmarks/probe_stream_tail.py [--out DIR] [--speed M_S] [--oscillators 0 1 2 3 4]

At the stream's 10 kHz band, contacts of 10-15 mm lumps read 1.1-1.8 % too stiff
(bench_stream_band_size.py): the residual spring holds the modes above the band static,
while a contact of ~100 us drives those near the band edge dynamically. This probe measures
what a dynamic tail would give before it is built into the compiled active set: the modes
of a wider basis (``--top``, default 40 kHz) above the band, seen at the contact point,
replaced by J oscillators (the J-node Gauss rule of their spectral measure in 1/omega^2,
from J Lanczos steps: the J pseudo-modes that keep the first 2J moments, as the single-ball
solver's Ritz tail does on the FE model), the modes above ``--top`` as the usual static
residual in series. Rows J = 0 are the quasi-static residual of today.

One ball lands at ``--speed`` (default 3 m/s) on the reference plate (SSSS, 30 degrees,
contact damping 300 N s/m; bench_stream_band_size.SCENE) at rest, at (0.05, 0.07) m. Every
variant runs through the same small integrator here (scipy DOP853, rtol 1e-9, steps <= 0.2
us; the IMPACT law from tailbeam.physics.impact; the damping term at the rate before the
residual spring), the truth included: all modes to ``--top`` plus its static residual. So
the table isolates the tail model; the solver itself is checked elsewhere. Writes
DIR/tail.csv and DIR/table.md.
"""

import argparse
import csv
import math
from pathlib import Path

import numpy as np
from bench_stream_band_size import SCENE
from scipy.integrate import solve_ivp

from tailbeam.io.scene_file import loads_scene
from tailbeam.physics.contact_patch import load_radius
from tailbeam.physics.impact import force
from tailbeam.simulation import _stream_plate

POINT = (0.05, 0.07)
SIZES = (0.010, 0.015, 0.020, 0.030, 0.040)


def contact_point(material: str, radius: float, speed: float, fmax: float) -> dict:
    """The ball, its plate law and the plate's modes, damping and residual compliance at
    POINT for a basis to ``fmax`` Hz."""
    text = SCENE.format(fmax=fmax, material=material, radius=radius, z=radius + 1e-4, vz=-speed,
                        extra="")  # fmt: skip
    scene = loads_scene(text)
    plate = _stream_plate(scene, {"fmax_hz": fmax})
    ball = scene.balls[0]
    law = scene.contacts().law(ball.name, "plate")
    g = float(scene.gravity)
    rl = load_radius(plate.basis.theory, ball, law, g)
    return {
        "ball": ball, "law": law, "g_n": g * math.cos(math.radians(scene.inclination)),
        "omega": plate.omega, "zeta": plate.zeta, "phi": plate.shapes([POINT])[0],
        "cres": float(plate.compliance([POINT], [rl])[0]),
    }  # fmt: skip


def gauss_tail(phi, omega, j: int) -> tuple[np.ndarray, np.ndarray]:
    """(frequencies nu (j,) rad/s, shape values b (j,)) of j oscillators that keep the
    moments sum phi^2 / omega^(2m+2), m < 2j, of the modes (phi, omega) at a point."""
    lam = 1.0 / omega**2
    v = phi / omega
    beta0 = float(np.linalg.norm(v))
    basis, alpha, beta = [v / beta0], [], []
    for _ in range(j):
        u = lam * basis[-1]
        for w in basis:  # full reorthogonalisation (j is tiny)
            u = u - (w @ u) * w
        alpha.append(float(basis[-1] @ (lam * basis[-1])))
        beta.append(float(np.linalg.norm(u)))
        basis.append(u / beta[-1])
    theta, vec = np.linalg.eigh(np.diag(alpha) + np.diag(beta[:-1], 1) + np.diag(beta[:-1], -1))
    nu = 1.0 / np.sqrt(theta)
    return nu, np.sqrt(beta0**2 * vec[0] ** 2) * nu


def peak_force(c: dict, modes: tuple, cres: float, radius: float, speed: float) -> float:
    """Peak force (N) of the ball's first contact with the modes (omega, zeta, phi) and the
    static compliance cres (m/N) in series."""
    omega, zeta, phi = modes
    m, law, n = c["ball"].mass, c["law"], len(omega)
    k, e, damp, d = law.stiffness, law.exponent, law.damping, law.penetration

    def contact_force(y):
        w, wd = phi @ y[2 : 2 + n], phi @ y[2 + n :]
        delta0, rate = radius - (y[0] - w), -(y[1] - wd)
        f = 0.0
        for _ in range(200):  # F = IMPACT(delta0 - cres F, rate): a contraction here
            fn = force(delta0 - cres * f, rate, k, e, damp, d, True)
            if abs(fn - f) <= 1e-13 * max(abs(fn), 1e-30):
                return fn
            f = 0.5 * (f + fn)
        return f

    def rhs(_t, y):
        f = contact_force(y)
        q, qd = y[2 : 2 + n], y[2 + n :]
        acc = -2.0 * zeta * omega * qd - omega**2 * q - phi * f
        return np.concatenate([[y[1], -c["g_n"] + f / m], qd, acc])

    y0 = np.zeros(2 + 2 * n)
    y0[0], y0[1] = radius + 1e-4, -speed
    sol = solve_ivp(rhs, (0.0, 0.0015), y0, method="DOP853", rtol=1e-9, atol=1e-13,
                    max_step=2e-7)  # fmt: skip
    return max(contact_force(sol.y[:, i]) for i in range(sol.y.shape[1]))


def row(material: str, radius: float, speed: float, band: float, top: float, js) -> dict:
    low = contact_point(material, radius, speed, band)
    high = contact_point(material, radius, speed, top)
    truth = peak_force(high, (high["omega"], high["zeta"], high["phi"]), high["cres"], radius,
                       speed)  # fmt: skip
    above = high["omega"] > low["omega"].max() * (1.0 + 1e-7)
    out = {"material": material, "radius_mm": 1e3 * radius}
    for j in js:
        if j == 0:
            modes, cres = (low["omega"], low["zeta"], low["phi"]), low["cres"]
        else:
            nu, b = gauss_tail(high["phi"][above], high["omega"][above], j)
            zeta_t = np.interp(nu, high["omega"], high["zeta"])
            modes = tuple(
                np.concatenate(p)
                for p in zip((low["omega"], low["zeta"], low["phi"]), (nu, zeta_t, b), strict=True)
            )
            cres = high["cres"]
        out[f"J{j}"] = peak_force(low, modes, cres, radius, speed) / truth - 1.0
    return out


def main(out_dir: Path, speed: float, band: float, top: float, js) -> None:
    out_dir.mkdir(parents=True, exist_ok=True)
    rows = []
    for material in ("coal", "sandstone"):
        for radius in SIZES:
            rows.append(row(material, radius, speed, band, top, js))
            print(rows[-1], flush=True)
    with (out_dir / "tail.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    head = " | ".join("quasi-static residual" if j == 0 else f"J = {j}" for j in js)
    lines = [
        f"peak force at {band / 1e3:g} kHz + tail against all modes to {top / 1e3:g} kHz, "
        f"{speed:g} m/s",
        "",
        f"| material | radius (mm) | {head} |",
        "|---|---|" + "---|" * len(js),
    ]
    for r in rows:
        cells = " | ".join(f"{r[f'J{j}']:+.2%}" for j in js)
        lines.append(f"| {r['material']} | {r['radius_mm']:g} | {cells} |")
    worst = {j: max(abs(r[f"J{j}"]) for r in rows) for j in js}
    lines.append("| worst | | " + " | ".join(f"{worst[j]:.2%}" for j in js) + " |")
    (out_dir / "table.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out/probe_stream_tail")
    ap.add_argument("--speed", type=float, default=3.0)
    ap.add_argument("--band", type=float, default=10000.0)
    ap.add_argument("--top", type=float, default=40000.0)
    ap.add_argument("--oscillators", type=int, nargs="+", default=[0, 1, 2, 3, 4])
    args = ap.parse_args()
    main(Path(args.out), args.speed, args.band, args.top, args.oscillators)
