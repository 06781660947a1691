"""A plate's modal basis: natural frequencies and mass-normalised mode shapes.

This is the contract between the plate models (finite elements, ``tailbeam.plate.fe``; the
closed-form SSSS basis, ``tailbeam.plate.closed_forms``) and their users (the solvers, the
sensors). Shapes are normalised to unit modal mass, so
modal coordinates q_i have units m*sqrt(kg) and the deflection w(x, y) = sum_i phi_i(x, y) q_i
(m, positive up, +z) with phi_i in 1/sqrt(kg).
"""

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from tailbeam.errors import InputError
from tailbeam.physics.bodies import Plate
from tailbeam.physics.contact_patch import disc_rule

DEFAULT_DAMPING_RATIO = 0.01  # of every mode (welded steel with light joints)

PointEvaluator = Callable[[np.ndarray], np.ndarray]
ComplianceEvaluator = Callable[[np.ndarray, float], np.ndarray]
DeflectionEvaluator = Callable[[np.ndarray, np.ndarray, float], np.ndarray]


@dataclass(frozen=True, eq=False)
class ModalBasis:
    """Modes of a plate, sorted by frequency.

    frequencies_hz: (n,) natural frequencies in Hz (rigid-body modes, if any, are excluded).
    deflection_at: maps points (p, 2) [x, y] in m to the (p, n) modal deflections phi_i in
        1/sqrt(kg) (unit modal mass).
    static_compliance_at: optional; maps points (p, 2) and a contact radius (m) to the full
        model's static compliance w/F (m/N) under a load there, used for the residual
        flexibility of truncated modes. None where the model has none (e.g. a free plate).
    """

    plate: Plate
    frequencies_hz: np.ndarray
    deflection_at: PointEvaluator
    theory: str
    boundary: str
    static_compliance_at: ComplianceEvaluator | None = None
    static_deflection_at: DeflectionEvaluator | None = None
    info: dict = field(default_factory=dict)

    @property
    def n_modes(self) -> int:
        return int(len(self.frequencies_hz))

    @property
    def omega(self) -> np.ndarray:
        """Angular frequencies in rad/s."""
        return 2.0 * np.pi * np.asarray(self.frequencies_hz)

    def deflection(self, points) -> np.ndarray:
        """(p, n) modal deflections at points (p, 2) in m."""
        points = np.atleast_2d(np.asarray(points, dtype=float))
        return np.asarray(self.deflection_at(points))[:, : self.n_modes]

    def truncated(self, *, fmax_hz: float | None = None, count: int | None = None) -> "ModalBasis":
        """The modes below ``fmax_hz`` and/or the first ``count`` modes."""
        keep = self.n_modes
        if fmax_hz is not None:
            keep = int(np.searchsorted(self.frequencies_hz, fmax_hz, side="right"))
        if count is not None:
            keep = min(keep, int(count))
        if keep < 1:
            raise InputError("fmax_hz", f"no mode lies below {fmax_hz!r} Hz")
        parent = self.deflection_at
        return ModalBasis(
            plate=self.plate,
            frequencies_hz=np.asarray(self.frequencies_hz[:keep]),
            deflection_at=lambda p: np.asarray(parent(p))[:, :keep],
            theory=self.theory,
            boundary=self.boundary,
            static_compliance_at=self.static_compliance_at,
            static_deflection_at=self.static_deflection_at,
            info=dict(self.info),
        )

    def load_deflection(self, points, contact_radius: float = 0.0) -> np.ndarray:
        """(p, n) modal deflections averaged over a disc of ``contact_radius`` m about each
        point (tailbeam.physics.contact_patch.disc_rule; radius 0: at the point): the modal force of
        a unit load spread over the disc, and the mean plate deflection there."""
        points = np.atleast_2d(np.asarray(points, dtype=float))
        if contact_radius == 0.0:
            return self.deflection(points)
        rows = []
        for p in points:
            pts, weights = disc_rule(self.plate, p, contact_radius)
            rows.append(weights @ self.deflection(pts))
        return np.array(rows)

    def _require_static(self, what):
        if what is None:
            raise InputError(
                "plate.residual_flexibility",
                f"the {self.theory} {self.boundary} model provides no static compliance; "
                "switch residual flexibility off",
            )

    def residual_compliance(self, points, contact_radius: float = 0.0) -> np.ndarray:
        """Static compliance (m/N) of the modes left out, at each point: the full model's
        static compliance minus the part the kept modes carry, sum phibar_i^2 / omega_i^2,
        both for the same load (1 N over a disc of ``contact_radius`` m; 0: a point load;
        phibar = ``load_deflection``), so the residual vanishes when every mode is kept."""
        self._require_static(self.static_compliance_at)
        points = np.atleast_2d(np.asarray(points, dtype=float))
        full = np.asarray(self.static_compliance_at(points, contact_radius), dtype=float)
        phi = self.load_deflection(points, contact_radius)
        kept = np.sum(phi**2 / self.omega**2, axis=1)
        return np.maximum(full - kept, 0.0)

    def residual_cross_compliance(self, load_point, points, contact_radius=0.0) -> np.ndarray:
        """(p,) static deflection (m/N) of the modes left out at ``points`` under a unit load
        at ``load_point`` (spread as in ``residual_compliance``): the full model's static
        deflection minus sum phi_i(points) phibar_i(load) / omega_i^2. Times the contact force
        it is the truncated modes' quasi-static (mode-acceleration) response at a sensor."""
        self._require_static(self.static_deflection_at)
        load_point = np.asarray(load_point, dtype=float).reshape(2)
        points = np.atleast_2d(np.asarray(points, dtype=float))
        full = np.asarray(self.static_deflection_at(load_point, points, contact_radius))
        phibar = self.load_deflection([load_point], contact_radius)[0]
        return full - self.deflection(points) @ (phibar / self.omega**2)


def modal_damping(omega, damping_ratio=DEFAULT_DAMPING_RATIO, rayleigh=None) -> np.ndarray:
    """Damping ratio of each mode: constant, or Rayleigh zeta = alpha/(2 omega) + beta omega/2.

    Parameters
    ----------
    omega : array_like
        Angular frequencies of the modes (rad/s).
    damping_ratio : float
        The ratio of every mode when ``rayleigh`` is None, in [0, 1).
    rayleigh : tuple of float, optional
        (alpha 1/s, beta s), both >= 0.
    """
    omega = np.asarray(omega, dtype=float)
    if rayleigh is not None:
        alpha, beta = rayleigh
        if alpha < 0 or beta < 0:
            raise InputError("plate.rayleigh", "alpha and beta must be >= 0")
        zeta = alpha / (2.0 * omega) + 0.5 * beta * omega
        if np.any(zeta >= 1.0):
            raise InputError("plate.rayleigh", "gives a damping ratio >= 1 for some mode")
        return zeta
    if not 0 <= damping_ratio < 1:
        raise InputError("plate.damping_ratio", f"must be in [0, 1), got {damping_ratio!r}")
    return np.full(omega.shape, float(damping_ratio))
