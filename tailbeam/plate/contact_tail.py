"""A dynamic tail at each plate contact of a stream: a few oscillators for the modes above
the band (``plate.tail = "ritz"`` on the stream solver).

The residual spring (``plate.residual_flexibility``) holds the modes above the band static.
A contact shorter than ~2 / band drives those near the band edge dynamically, so at 10 kHz
the contacts of 10-15 mm lumps read 1.1-1.8 % too stiff (docs/streams.md, "The band against
particle size"). Here the modes of a wider basis (``TAIL_BAND_FACTOR`` x the band, on the
band basis' own mesh) above the band, seen at the contact point (shapes phi_i, frequencies
omega_i), are replaced by k oscillators: the k-node Gauss rule of their spectral measure in
s = 1/omega^2 with weights phi_i^2 / omega_i^2, from k Lanczos steps started from
phi_i / omega_i. The k oscillators (frequencies nu_j, deflection b_j at the point per unit
modal coordinate) keep the moments sum_j b_j^2 / nu_j^(2m+2) = sum_i phi_i^2 /
omega_i^(2m+2) for m < 2k: the static compliance (m = 0) and the slow part of the point's
response, as the single-ball solver's Ritz tail does on the FE model
(tailbeam.plate.ritz_tail). The rest of the band's residual compliance, C_res - sum_j
b_j^2 / nu_j^2 (the modes above the wider band), stays a static spring in series, so the
contact's static compliance is the quasi-static tail's. Its accuracy against all modes to
40 kHz at a 10 kHz band: docs/streams.md (``benchmarks/bench_stream_band_size.py``).

The oscillators belong to one plate pair (a ball on the plate) at one contact point: they
start at rest when its contact starts there, keep moving while the ball bounces off and lands
again at the same point (dropping them when the contact ends would move the plate under the
ball at once), and are dropped, their energy counted (``ActiveMembers.tail_energy_dropped``),
when the ball's mode shapes move on (the plate under it is then far from closing its gap), it
is put at rest or leaves the active set. They carry no vibration to other contacts or to the
sensors (the kept modes do). Cost per contact point: one evaluation of the wider basis'
shapes there and k Lanczos steps on its modes above the band; the wider basis is computed
once and cached.
"""

from dataclasses import dataclass

import numpy as np

TAIL_BAND_FACTOR = 4.0  # the wider basis' band, in units of the stream's band ...
TAIL_MAX_HZ = 40_000.0  # ... and at most this: contacts of lumps >= 10 mm need no more
# dynamically (docs/streams.md); a wider basis costs minutes (~600 modes at 40 kHz on the
# 10 kHz mesh: 25 s)
BREAKDOWN = 1e-12  # a Lanczos vector this small against the first ends the rule early


@dataclass(frozen=True)
class TailModes:
    """The tail of one contact point: frequencies ``nu`` (k,) rad/s, damping ratios ``zeta``
    (k,), deflections ``b`` (k,) 1/sqrt(kg) at the point per unit modal coordinate, and the
    static compliance ``compliance`` (m/N) of the modes above the wider band, in series."""

    nu: np.ndarray
    zeta: np.ndarray
    b: np.ndarray
    compliance: float

    @property
    def static_compliance(self) -> float:
        """Static compliance (m/N) of the whole tail at the point: oscillators and spring."""
        return float(np.sum(self.b**2 / self.nu**2)) + self.compliance


def gauss_rule(phi, omega, k: int) -> tuple[np.ndarray, np.ndarray]:
    """(nu (j,) rad/s ascending, b (j,) 1/sqrt(kg)), j <= k: the oscillators whose moments
    sum b^2 / nu^(2m+2), m < 2j, equal those of the modes (phi (n,), omega (n,) rad/s) at a
    point; j < k when the modes' measure has fewer points or the Krylov space closes."""
    phi, omega = np.asarray(phi, dtype=float), np.asarray(omega, dtype=float)
    start = phi / omega
    beta0 = float(np.linalg.norm(start))
    if beta0 == 0.0 or k < 1:
        return np.zeros(0), np.zeros(0)
    s = 1.0 / omega**2
    vectors, alpha, beta = [start / beta0], [], []
    for _ in range(min(k, len(phi))):
        u = s * vectors[-1]
        alpha.append(float(vectors[-1] @ u))
        for v in vectors:  # full reorthogonalisation (k is a handful)
            u = u - (v @ u) * v
        beta.append(float(np.linalg.norm(u)))
        if beta[-1] <= BREAKDOWN * alpha[0]:
            break
        vectors.append(u / beta[-1])
    j = len(alpha)
    tri = np.diag(alpha) + np.diag(beta[: j - 1], 1) + np.diag(beta[: j - 1], -1)
    theta, vec = np.linalg.eigh(tri)
    nu = 1.0 / np.sqrt(theta)
    b = beta0 * np.abs(vec[0]) * nu
    order = np.argsort(nu)
    return nu[order], b[order]


class ContactTail:
    """Tails at contact points of a stream on ``band_omega`` (the kept modes, rad/s): from
    ``wide`` (a ModalBasis to a wider band), k oscillators per point with damping ratios
    ``damping(nu)``; cached by point and load radius."""

    def __init__(self, band_omega, wide, k: int, damping):
        self.wide, self.k, self.damping = wide, int(k), damping
        self.above = np.asarray(wide.omega) > float(np.max(band_omega)) * (1.0 + 1e-9)
        self.omega = np.asarray(wide.omega)[self.above]
        self._cache = {}

    def at(self, xy, load_radius: float, residual: float) -> TailModes:
        """The tail at point xy (2,) m for a load spread over a disc of ``load_radius`` m,
        where the band's residual compliance is ``residual`` m/N."""
        key = (round(float(xy[0]), 9), round(float(xy[1]), 9), float(load_radius))
        if key not in self._cache:
            phi = self.wide.deflection(np.atleast_2d(np.asarray(xy, dtype=float)))[0]
            nu, b = gauss_rule(phi[self.above], self.omega, self.k)
            spring = max(float(residual) - float(np.sum(b**2 / nu**2)), 0.0)
            self._cache[key] = TailModes(nu, np.asarray(self.damping(nu), dtype=float), b, spring)
        return self._cache[key]
