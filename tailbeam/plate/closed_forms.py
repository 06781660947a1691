"""Closed-form and tabulated plate frequencies: the independent truths the FE models are checked
against, and the estimates the automatic theory/mesh choice is based on.

- Simply supported (SSSS) Kirchhoff: f_mn = (pi/2)(m^2/a^2 + n^2/b^2) sqrt(D/(rho h)), and
  the exact modal basis of that plate (``ssss_kirchhoff_basis``, with the Navier series of its
  static compliance).
- SSSS Reissner-Mindlin (shear coefficient kappa = 5/6, rotary inertia rho h^3/12): the modes
  are the same sin*sin shapes; the flexural frequency of each (m, n) is the lower root of
      rho h I omega^4 - omega^2 (S I k^2 + rho h D k^2 + rho h S) + S D k^4 = 0,
  with k^2 = (m pi/a)^2 + (n pi/b)^2, S = kappa G h, I = rho h^3/12 (Mindlin 1951, "hard"
  simple support: w = 0 and the tangential rotation = 0).
- Square plates CCCC, FFFF, CFFF: Leissa's nondimensional frequencies
  lambda = omega a^2 sqrt(rho h / D) (Ritz upper bounds; digits and source below).
"""

from dataclasses import dataclass

import numpy as np

from tailbeam.errors import InputError
from tailbeam.physics.bodies import Plate
from tailbeam.plate.basis import ModalBasis

SHEAR_COEFFICIENT = 5.0 / 6.0  # Reissner's value for a homogeneous plate
NAVIER_TERMS = 2000  # per direction
NAVIER_CHUNK = 256  # points per matrix product of the Navier series


def ssss_kirchhoff_frequencies(plate: Plate, m, n) -> np.ndarray:
    """Closed form f_mn = (pi/2)(m^2/a^2 + n^2/b^2) sqrt(D/(rho h)) in Hz (simply supported)."""
    m = np.asarray(m, dtype=float)
    n = np.asarray(n, dtype=float)
    a, b = plate.size_x, plate.size_y
    return (
        0.5
        * np.pi
        * (m**2 / a**2 + n**2 / b**2)
        * np.sqrt(plate.bending_stiffness / plate.mass_per_area)
    )


def ssss_kirchhoff_basis(plate: Plate, fmax_hz: float) -> ModalBasis:
    """Exact Kirchhoff modes of the simply supported plate below ``fmax_hz``.

    phi_mn = 2/sqrt(rho h a b) sin(m pi (x + a/2)/a) sin(n pi (y + b/2)/b).
    The static compliance and cross compliance (point loads, the Kirchhoff load model) are
    the Navier double series, summed to 1e-6 relative.
    """
    a, b = plate.size_x, plate.size_y
    f1 = ssss_kirchhoff_frequencies(plate, 1, 1)
    if fmax_hz < f1:
        raise InputError("fmax_hz", f"no mode below {fmax_hz!r} Hz; the first is {f1:.4g} Hz")
    m_max = int(np.ceil(np.sqrt(fmax_hz / ssss_kirchhoff_frequencies(plate, 1, 0)))) + 1
    n_max = int(np.ceil(np.sqrt(fmax_hz / ssss_kirchhoff_frequencies(plate, 0, 1)))) + 1
    mm, nn = np.meshgrid(np.arange(1, m_max + 1), np.arange(1, n_max + 1), indexing="ij")
    freqs = ssss_kirchhoff_frequencies(plate, mm, nn).ravel()
    order = np.argsort(freqs, kind="stable")
    keep = order[freqs[order] <= fmax_hz]
    m_idx, n_idx, freqs = mm.ravel()[keep], nn.ravel()[keep], freqs[keep]
    amp = 2.0 / np.sqrt(plate.mass_per_area * a * b)

    def deflection_at(points: np.ndarray) -> np.ndarray:
        x = points[:, 0:1] + 0.5 * a
        y = points[:, 1:2] + 0.5 * b
        return amp * np.sin(m_idx * np.pi * x / a) * np.sin(n_idx * np.pi * y / b)

    def navier(load_point, points):
        # Navier series at points (p, 2); terms fall like 1/(m^2 + n^2)^2, so the tail beyond
        # N is O(1/N^2). Summed as a matrix product, NAVIER_CHUNK points at a time.
        k = np.arange(1, NAVIER_TERMS + 1)
        inv_denom = 1.0 / (k[:, None] ** 2 / a**2 + k[None, :] ** 2 / b**2) ** 2
        lx = np.sin(k * np.pi * (load_point[0] + 0.5 * a) / a)
        ly = np.sin(k * np.pi * (load_point[1] + 0.5 * b) / b)
        out = np.empty(len(points))
        for s in range(0, len(points), NAVIER_CHUNK):
            chunk = points[s : s + NAVIER_CHUNK]
            sx = np.sin(k * np.pi * (chunk[:, 0:1] + 0.5 * a) / a) * lx
            sy = np.sin(k * np.pi * (chunk[:, 1:2] + 0.5 * b) / b) * ly
            out[s : s + NAVIER_CHUNK] = np.sum(sx * (sy @ inv_denom.T), axis=1)
        return 4.0 / (a * b * plate.bending_stiffness * np.pi**4) * out

    def point_load_only(contact_radius):
        if contact_radius != 0.0:
            raise InputError("contact_radius", "the closed-form Kirchhoff basis takes point loads")

    def static_compliance_at(points: np.ndarray, contact_radius: float = 0.0) -> np.ndarray:
        point_load_only(contact_radius)
        points = np.atleast_2d(np.asarray(points, dtype=float))
        return np.array([navier(p, p[None, :])[0] for p in points])

    def static_deflection_at(load_point, points, contact_radius: float = 0.0) -> np.ndarray:
        point_load_only(contact_radius)
        points = np.atleast_2d(np.asarray(points, dtype=float))
        return navier(np.asarray(load_point, dtype=float).reshape(2), points)

    return ModalBasis(
        plate=plate,
        frequencies_hz=freqs,
        deflection_at=deflection_at,
        theory="kirchhoff-closed-form",
        boundary="SSSS",
        static_compliance_at=static_compliance_at,
        static_deflection_at=static_deflection_at,
        info={"m": m_idx, "n": n_idx},
    )


def _mindlin_constants(plate: Plate):
    """(rho h, rho I, D, S): mass/area kg/m^2, rotary inertia kg, D N m, S = kappa G h N/m."""
    mat = plate.material
    shear_modulus = mat.youngs_modulus / (2.0 * (1.0 + mat.poisson_ratio))
    rho_h = plate.mass_per_area
    rho_i = mat.density * plate.thickness**3 / 12.0
    return (
        rho_h,
        rho_i,
        plate.bending_stiffness,
        SHEAR_COEFFICIENT * shear_modulus * plate.thickness,
    )


def mindlin_flexural_omega(plate: Plate, k2) -> np.ndarray:
    """Flexural angular frequency (rad/s) of a Mindlin plate wave with k^2 (rad^2/m^2)."""
    k2 = np.asarray(k2, dtype=float)
    rho_h, rho_i, d, s = _mindlin_constants(plate)
    qa = rho_h * rho_i
    qb = s * rho_i * k2 + rho_h * d * k2 + rho_h * s
    qc = s * d * k2**2
    # lower root of qa x^2 - qb x + qc = 0, in the cancellation-free form 2c / (b + sqrt(.))
    return np.sqrt(2.0 * qc / (qb + np.sqrt(qb**2 - 4.0 * qa * qc)))


def kirchhoff_omega(plate: Plate, k2) -> np.ndarray:
    """Kirchhoff flexural angular frequency (rad/s): omega = k^2 sqrt(D / (rho h))."""
    return np.asarray(k2, dtype=float) * np.sqrt(plate.bending_stiffness / plate.mass_per_area)


def bending_wavenumber(plate: Plate, frequency_hz, theory: str) -> np.ndarray:
    """Free bending wavenumber k (rad/m) at ``frequency_hz`` for 'kirchhoff' or 'mindlin'."""
    omega = 2.0 * np.pi * np.asarray(frequency_hz, dtype=float)
    if theory == "kirchhoff":
        return np.sqrt(omega / np.sqrt(plate.bending_stiffness / plate.mass_per_area))
    rho_h, rho_i, d, s = _mindlin_constants(plate)
    # the dispersion relation as a quadratic in K = k^2; the bending branch is its larger root
    lin = omega**2 * (s * rho_i + rho_h * d)
    const = rho_h * rho_i * omega**4 - omega**2 * rho_h * s
    k2 = (lin + np.sqrt(lin**2 - 4.0 * s * d * const)) / (2.0 * s * d)
    return np.sqrt(k2)


def kirchhoff_model_error(plate: Plate, frequency_hz) -> np.ndarray:
    """How much Kirchhoff overestimates a bending mode near ``frequency_hz`` relative to
    Mindlin (f_K / f_M - 1 at the same wavenumber): the modelling error of the thin theory."""
    k = bending_wavenumber(plate, frequency_hz, "mindlin")
    return kirchhoff_omega(plate, k**2) / mindlin_flexural_omega(plate, k**2) - 1.0


@dataclass(frozen=True)
class SsssModes:
    """Closed-form SSSS modes sorted by frequency: indices m, n and frequencies (Hz)."""

    m: np.ndarray
    n: np.ndarray
    frequencies_hz: np.ndarray


def ssss_modes(plate: Plate, theory: str, *, fmax_hz: float | None = None, count=None):
    """All closed-form SSSS modes up to ``fmax_hz`` (and/or the first ``count``), sorted.

    theory: 'kirchhoff' or 'mindlin'. Degenerate (m, n)/(n, m) pairs of a square plate are
    both listed (ties keep m-major order).
    """
    a, b = plate.size_x, plate.size_y
    if fmax_hz is None:
        if count is None:
            raise ValueError("give fmax_hz or count")
        # enough (m, n) to hold `count` modes: the quarter disc of radius r holds ~ pi r^2 / 4
        r = int(np.ceil(np.sqrt(4.0 * count / np.pi) * max(a, b) / min(a, b))) + 2
        m_max = n_max = r
    else:
        k_max = float(bending_wavenumber(plate, fmax_hz, theory))
        m_max = int(k_max * a / np.pi) + 1
        n_max = int(k_max * b / np.pi) + 1
    mm, nn = np.meshgrid(np.arange(1, m_max + 1), np.arange(1, n_max + 1), indexing="ij")
    mm, nn = mm.ravel(), nn.ravel()
    if theory == "kirchhoff":
        freqs = ssss_kirchhoff_frequencies(plate, mm, nn)
    elif theory == "mindlin":
        k2 = (mm * np.pi / a) ** 2 + (nn * np.pi / b) ** 2
        freqs = mindlin_flexural_omega(plate, k2) / (2.0 * np.pi)
    else:
        raise ValueError(f"unknown theory {theory!r}")
    order = np.argsort(freqs, kind="stable")
    if fmax_hz is not None:
        order = order[freqs[order] <= fmax_hz]
    if count is not None:
        order = order[:count]
    return SsssModes(mm[order], nn[order], freqs[order])


def ssss_mode_count(plate: Plate, fmax_hz: float, theory: str) -> int:
    """Number of SSSS modes with frequency <= fmax_hz (closed form of ``theory``)."""
    return int(len(ssss_modes(plate, theory, fmax_hz=fmax_hz).frequencies_hz))


@dataclass(frozen=True)
class LeissaTable:
    """Published nondimensional frequencies lambda = omega a^2 sqrt(rho h / D) of a square
    Kirchhoff plate. ``poisson_ratio`` is None where lambda does not depend on nu."""

    boundary: str
    lambdas: tuple
    poisson_ratio: float | None
    source: str
    table_accuracy: float  # relative; how far the tabulated Ritz values may lie above the truth


# Leissa's square-plate values come from Ritz solutions with beam-function products (upper
# bounds). For clamped edges the beam functions satisfy every edge condition, and the
# values are converged to about 1e-3. Free edges are different: beam functions do not
# satisfy the free-edge conditions (zero moment and Kirchhoff shear), so the Ritz series
# converges from above more slowly. Leissa (1973) puts these values about 1 % above the
# truth, so we allow 1.5 %.
LEISSA_SQUARE = {
    "CCCC": LeissaTable(
        "CCCC",
        (35.992, 73.413, 73.413, 108.27, 131.64, 132.24),
        None,
        "Leissa, Vibration of Plates, NASA SP-160 (1969) Table 4.23; Leissa, J. Sound Vib. 31 "
        "(1973) 257-293 Table 2 (5 significant figures)",
        2e-3,
    ),
    "FFFF": LeissaTable(
        "FFFF",
        (13.49, 19.79, 24.43, 35.02, 35.02),
        0.3,
        "Leissa (1969) Table 4.77 / Leissa (1973), nu = 0.3, as quoted to 4 significant "
        "figures in Code_Aster validation case SDLS01",
        1.5e-2,
    ),
    "CFFF": LeissaTable(
        "CFFF",
        (3.492, 8.525, 21.43, 27.33, 31.11, 54.44),
        0.3,
        "Leissa (1969) Table 4.53 (Barton 1951), nu = 0.3, as quoted to 4 significant figures "
        "in Code_Aster validation case SDLS01",
        1.5e-2,
    ),
}


def leissa_frequencies(plate: Plate, boundary: str) -> np.ndarray | None:
    """Leissa's frequencies (Hz) for this plate and boundary, or None when the table does not
    apply (not square, no table for the boundary, or a Poisson ratio other than the table's).

    The boundary letters are in the order left, bottom, right, top; rotations and
    reflections of a square plate give the same frequencies, so e.g. FCFF uses CFFF.
    """
    if not np.isclose(plate.size_x, plate.size_y, rtol=1e-12):
        return None
    table = None
    for shift in range(4):
        rotated = boundary[shift:] + boundary[:shift]
        for candidate in (rotated, rotated[::-1]):
            table = table or LEISSA_SQUARE.get(candidate)
    if table is None:
        return None
    if table.poisson_ratio is not None and not np.isclose(
        plate.material.poisson_ratio, table.poisson_ratio, rtol=0, atol=1e-12
    ):
        return None
    scale = np.sqrt(plate.bending_stiffness / plate.mass_per_area) / plate.size_x**2
    return np.asarray(table.lambdas) * scale / (2.0 * np.pi)


def ssss_static_compliance(
    plate: Plate, points, contact_radius: float, theory: str, *, terms: int = 600
) -> np.ndarray:
    """Navier-series static compliance (m/N) of the SSSS plate: the mean deflection over a
    disc of ``contact_radius`` under a unit load spread uniformly over it.

    Per (m, n): w_mn = q_mn (1/(D k^4) + 1/(S k^2)) (Mindlin; Kirchhoff drops the shear
    term). The disc average of sin*sin is the centre value times 2 J1(k r)/(k r) (each
    sin*sin is a sum of plane waves of wavenumber k), which enters twice (load and mean).
    Mindlin with radius 0 diverges (logarithmically) and is refused.
    """
    from scipy.special import j1

    if theory == "mindlin" and contact_radius <= 0.0:
        raise ValueError("the Mindlin point-load deflection is infinite; use a disc")
    a, b = plate.size_x, plate.size_y
    _, _, d, s = _mindlin_constants(plate)
    idx = np.arange(1, terms + 1)
    alpha, gamma = idx * np.pi / a, idx * np.pi / b
    k2 = alpha[:, None] ** 2 + gamma[None, :] ** 2
    flex = 1.0 / (d * k2**2)
    if theory == "mindlin":
        flex = flex + 1.0 / (s * k2)
    if contact_radius > 0.0:
        kr = np.sqrt(k2) * contact_radius
        flex = flex * (2.0 * j1(kr) / kr) ** 2
    out = []
    for x0, y0 in np.atleast_2d(np.asarray(points, dtype=float)):
        sx = np.sin(alpha * (x0 + 0.5 * a))
        sy = np.sin(gamma * (y0 + 0.5 * b))
        out.append(4.0 / (a * b) * np.sum((sx[:, None] * sy[None, :]) ** 2 * flex))
    return np.asarray(out)


def _levy_columns(lam: float, beta: float, x: float, parity: str | None):
    """Values and derivatives (f, f', f'', f''') as a (4, k) table at x of the real
    solutions of X'''' - 2 beta^2 X'' + beta^4 X = lam^4 X, each column scaled by a positive
    factor (moves no root) to stay finite. Writing sin(q x)/q keeps the set continuous
    through lam = beta, where q = sqrt(lam^2 - beta^2) passes from real to imaginary."""
    p = np.sqrt(lam**2 + beta**2)
    ch, sh = np.cosh(p * x), np.sinh(p * x)
    cols = []
    if parity in (None, "even"):
        cols.append(np.array([ch, p * sh, p**2 * ch, p**3 * sh]) / ch)
    if parity in (None, "odd"):
        cols.append(np.array([sh, p * ch, p**2 * sh, p**3 * ch]) / ch)
    if lam >= beta:
        q = np.sqrt(lam**2 - beta**2)
        c, s = np.cos(q * x), np.sin(q * x)
        sinc = x * np.sinc(q * x / np.pi)  # sin(q x)/q, finite at q = 0
        if parity in (None, "even"):
            cols.append(np.array([c, -q * s, -(q**2) * c, q**3 * s]))
        if parity in (None, "odd"):
            cols.append(np.array([sinc, c, -q * s, -(q**2) * c]))
    else:
        r = np.sqrt(beta**2 - lam**2)
        ch2, sh2 = np.cosh(r * x), np.sinh(r * x)
        shc = sh2 / r if r * abs(x) > 1e-12 else x
        if parity in (None, "even"):
            cols.append(np.array([ch2, r * sh2, r**2 * ch2, r**3 * sh2]) / ch2)
        if parity in (None, "odd"):
            cols.append(np.array([shc, ch2, r * sh2, r**2 * ch2]) / ch2)
    return np.column_stack(cols)


def _levy_rows(cond: str, d: np.ndarray, beta: float, nu: float) -> np.ndarray:
    """Edge-condition rows from a derivative table d (4, k): C (X, X'), S (X, X''),
    F (moment X'' - nu beta^2 X, Kirchhoff shear X''' - (2 - nu) beta^2 X')."""
    if cond == "C":
        return d[[0, 1]]
    if cond == "S":
        return d[[0, 2]]
    return np.vstack([d[2] - nu * beta**2 * d[0], d[3] - (2.0 - nu) * beta**2 * d[1]])


def _levy_det(lam, beta, half, left, right, nu, parity):
    if parity is None:
        rows = [
            _levy_rows(left, _levy_columns(lam, beta, -half, None), beta, nu),
            _levy_rows(right, _levy_columns(lam, beta, half, None), beta, nu),
        ]
        return np.linalg.det(np.vstack(rows))
    # equal opposite edges: even and odd modes separate; the conditions at +a/2 suffice
    return np.linalg.det(_levy_rows(right, _levy_columns(lam, beta, half, parity), beta, nu))


def levy_frequencies(plate: Plate, boundary: str, fmax_hz: float) -> np.ndarray | None:
    """Exact Kirchhoff frequencies (Hz, sorted, <= fmax_hz) of a plate with two opposite
    edges simply supported (Levy: w = X(x) sin(n pi (y + b/2)/b)), the other two C, S or F
    in any combination; None when the boundary code has no such pair.

    Roots in lambda = (rho h omega^2 / D)^(1/4) are bracketed on a grid 64 times finer
    than their spacing (~pi/a) and refined by Brent's method.
    """
    from scipy.optimize import brentq

    left, bottom, right, top = boundary
    if bottom == "S" and top == "S":
        span, width, edge_lo, edge_hi = plate.size_x, plate.size_y, left, right
    elif left == "S" and right == "S":
        span, width, edge_lo, edge_hi = plate.size_y, plate.size_x, bottom, top
    else:
        return None
    nu = plate.material.poisson_ratio
    scale = np.sqrt(plate.bending_stiffness / plate.mass_per_area)
    lam_max = np.sqrt(2.0 * np.pi * fmax_hz / scale)
    half = 0.5 * span
    grid = np.arange(1e-3, lam_max + np.pi / span, np.pi / span / 64.0)
    parities = ("even", "odd") if edge_lo == edge_hi else (None,)
    roots = []
    for n in range(1, int(lam_max * width / np.pi) + 1):
        beta = n * np.pi / width
        for parity in parities:
            args = (beta, half, edge_lo, edge_hi, nu, parity)
            vals = np.array([_levy_det(g, *args) for g in grid])
            for i in np.nonzero(np.sign(vals[:-1]) * np.sign(vals[1:]) < 0)[0]:
                roots.append(brentq(_levy_det, grid[i], grid[i + 1], args=args, xtol=1e-14))
    freqs = np.sort(np.asarray(roots) ** 2 * scale / (2.0 * np.pi))
    return freqs[freqs <= fmax_hz]
