"""A plate's modal basis: natural frequencies and mass-normalised mode shapes.

This is the contract between the plate models (``tailbeam.plate``, finite elements; the closed
form below) and their users (coupling, sensors). Shapes are normalised to unit modal mass, so
modal coordinates q_i have units m*sqrt(kg) and the deflection w(x, y) = sum_i phi_i(x, y) q_i
(m, positive up, +z) with phi_i in 1/sqrt(kg).
"""

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from tailbeam.errors import InputError
from tailbeam.physics.bodies import Plate
from tailbeam.physics.contact_patch import disc_rule

PointEvaluator = Callable[[np.ndarray], np.ndarray]
NAVIER_TERMS = 2000  # per direction
NAVIER_CHUNK = 256  # points per matrix product of the Navier series
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
