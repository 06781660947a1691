"""The modal plate under a stream (two-way): its state between active sets and its bounds.

The modes q, q' (mass-normalised, ``tailbeam.plate.basis.ModalBasis``) live here while no
contact is integrated, advanced exactly (``tailbeam.solvers.plate_loads.propagator``) under the
dead loads of the balls resting on the plate (constant modal forces -sum phi(x_i, y_i) m_i g
cos theta, refreshed whenever the modes are handed to the active set). While the active set
runs, the modes are part of its state (``stream.active.integrator.set``: the plate pairs
feel w = phi . q, the modes feel -phi F) and come back here after every advance.

``deflection_bound`` bounds |w| anywhere on the plate until the next contact: each mode's
energy about its static position under the dead loads cannot grow while only the dead
loads act, so |q_k| <= |s_k| + sqrt((q_k - s_k)^2 + (q'_k / omega_k)^2), s_k = f_k / omega_k^2.
The stream driver predicts a flying ball's plate touch that far above the plate, so that the
integrator (which sees the vibrating plate) finds the real start.

Residual flexibility (``residual_flexibility``, the scene's ``plate.residual_flexibility``,
default on as in the single-ball coupled solver): ``compliance`` gives the static compliance
of the truncated modes at a contact point (``tailbeam.plate.compliance.Compliance``: the full
model's static compliance minus the kept modes' part, cached per basis and point), which the
active set puts in series with the contact. With a ``tail``
(``tailbeam.plate.contact_tail``, ``plate.tail = "ritz"``) each contact gets a few
oscillators for the modes above the band instead, and the spring only for those above the
tail's wider band.
"""

import numpy as np

from tailbeam.errors import InputError
from tailbeam.physics.contact_patch import disc_rule
from tailbeam.plate.compliance import Compliance
from tailbeam.plate.slopes import values_and_slopes
from tailbeam.solvers.plate_loads.propagator import advance, coefficients

GRID = 61  # points per side where max |phi_k| is sampled
GRID_SAFETY = 1.1  # the sampled maximum, raised for peaks between grid points


class StreamPlate:
    """Modal state of the plate ``basis`` with damping ratios ``zeta`` (one per mode); with
    ``residual_flexibility`` the contacts get the truncated modes' static compliance."""

    def __init__(self, basis, zeta, residual_flexibility=True, tail=None):
        if residual_flexibility and basis.static_compliance_at is None:
            raise InputError(
                "plate.residual_flexibility",
                f"the {basis.theory} {basis.boundary} basis has no static compliance (a plate "
                "with rigid-body modes); set plate.residual_flexibility = false",
            )
        if tail is not None and not residual_flexibility:
            raise InputError("plate.tail", "'ritz' needs residual_flexibility = true")
        self.basis = basis
        self.tail = tail  # a contact_tail.ContactTail, or None (the static spring alone)
        self.residual_flexibility = bool(residual_flexibility)
        self._compliance = Compliance(basis, self.residual_flexibility)
        self._face = _face_modes(basis)  # a structure's fast face readings, or None
        self.omega = np.ascontiguousarray(basis.omega, dtype=float)
        self.zeta = np.ascontiguousarray(zeta, dtype=float)
        n = self.omega.shape[0]
        self.q, self.qd = np.zeros(n), np.zeros(n)
        self.t = 0.0
        self.f_dead = np.zeros(n)
        self._coef = np.empty((8, n))
        plate = basis.plate
        xs = np.linspace(-0.5 * plate.size_x, 0.5 * plate.size_x, GRID)
        ys = np.linspace(-0.5 * plate.size_y, 0.5 * plate.size_y, GRID)
        grid = np.array([(x, y) for x in xs for y in ys])
        self.phi_max = GRID_SAFETY * np.max(np.abs(self.shapes(grid)), axis=0)

    def reset(self) -> None:
        """The plate at rest at t = 0 (before a run)."""
        self.q[:], self.qd[:], self.f_dead[:] = 0.0, 0.0, 0.0
        self.t = 0.0

    @property
    def n_modes(self) -> int:
        return self.omega.shape[0]

    def shapes(self, xy) -> np.ndarray:
        """(p, m) mode shapes (1/sqrt(kg)) at points xy (p, 2) m: point loads."""
        if self._face is not None:
            return self._face(np.atleast_2d(np.asarray(xy, dtype=float)))
        return np.ascontiguousarray(self.basis.deflection(np.atleast_2d(xy)), dtype=float)

    def gradients(self, xy) -> np.ndarray:
        """(p, m, 2) gradients d phi / d(x, y) (1/(m sqrt(kg))) of the mode shapes at points
        xy (p, 2) m (``tailbeam.plate.slopes``), where friction acts on the plate's top
        surface (``active.compiled.friction``)."""
        return values_and_slopes(self.shapes, xy)[1]

    def compliance(self, xy, radii) -> np.ndarray:
        """(p,) residual compliance (m/N) at points xy (p, 2) m for loads spread over discs
        of ``radii`` (p,) m (``tailbeam.physics.contact_patch.load_radius``; 0: a point load); all 0
        when residual flexibility is off."""
        xy = np.atleast_2d(np.asarray(xy, dtype=float))
        if self._face is not None and self.residual_flexibility:
            return np.array([self._structure_residual(p, float(r))
                             for p, r in zip(xy, np.ravel(radii), strict=True)])  # fmt: skip
        return np.array([self._compliance(float(x), float(y), float(r))
                         for (x, y), r in zip(xy, np.ravel(radii), strict=True)])  # fmt: skip

    def _structure_residual(self, xy, radius: float) -> float:
        """``ModalBasis.residual_compliance`` of a structure at one point through its fast
        face readings: the face compliance (``tailbeam.plate.solid.face.compliance``) minus
        the kept modes' part over the same disc."""
        pts, weights = disc_rule(self.basis.plate, xy, radius)
        full = float(self.basis.static_compliance_at([xy], radius)[0])
        phibar = weights @ self.shapes(pts)
        return max(full - float(np.sum(phibar**2 / self.omega**2)), 0.0)

    def tail_at(self, xy, radius: float):
        """The dynamic tail (``contact_tail.TailModes``) of a contact at xy (2,) m with load
        radius ``radius`` m, or None without one."""
        if self.tail is None:
            return None
        return self.tail.at(xy, radius, self.compliance([xy], [radius])[0])

    def set_dead_loads(self, xy, weights) -> None:
        """Dead loads from now on: weights (N, pressing down) at points xy (p, 2)."""
        if len(weights):
            self.f_dead = -(np.asarray(weights, dtype=float) @ self.shapes(xy))
        else:
            self.f_dead = np.zeros(self.n_modes)

    def propagate(self, t: float) -> None:
        """Advance the free modes (dead loads only) exactly from self.t to t."""
        tau = t - self.t
        if tau > 0.0:
            coefficients(self.omega, self.zeta, tau, self._coef)
            q, qd = self.q.copy(), self.qd.copy()
            advance(self._coef, q, qd, self.f_dead, self.f_dead, self.q, self.qd)
        self.t = max(self.t, t)

    def take(self, q, qd, t: float) -> None:
        """The modal state the active set reached at time t."""
        self.q[:], self.qd[:] = q, qd
        self.t = t

    def deflection_bound(self) -> float:
        """A bound (m) on |w| anywhere while only the dead loads act (module docstring)."""
        s = self.f_dead / self.omega**2
        amp = np.abs(s) + np.sqrt((self.q - s) ** 2 + (self.qd / self.omega) ** 2)
        return float(self.phi_max @ amp)

    def energy(self) -> float:
        """Modal kinetic + strain energy (J) minus the dead loads' work potential."""
        return float(0.5 * np.sum(self.qd**2 + (self.omega * self.q) ** 2) - self.f_dead @ self.q)


def _face_modes(basis):
    """The mode shapes on a structure's impact face through its fast readings
    (``tailbeam.plate.solid.face.readings``), or None (a flat plate's basis, or a face the
    fast readings do not cover: the basis' own ``deflection``)."""
    model, vectors = getattr(basis, "model", None), getattr(basis, "mode_vectors", None)
    if model is None or vectors is None:
        return None
    readings = model.face_readings()
    if readings is None:
        return None
    return readings.modal(np.asarray(vectors)[:, : basis.n_modes])
