"""The modal plate of the slow stream reference (two-way): its model, written independently.

m mass-normalised modes (``tailbeam.plate.basis.ModalBasis``, unit modal mass) are part of the
reference's ODE state after the balls, ``[x | v | q | q']``:

    q'' + 2 zeta omega q' + omega^2 q = -sum over plate contacts p of phi(x_p, y_p) F_p

A ball over the plate (plate frame: z the plate normal) touches the deflected plate with the
penetration delta = r - z + w, w = phi(x, y) . q the deflection under its centre (m). The
contact is the potential U(delta) of the IMPACT law (plus its damping), so every coordinate
feels the generalised force -F d(delta)/d(coordinate):

    ball z: +F;   modes: -phi(x, y) F;   ball x, y: -F (grad phi(x, y) . q)  (the slope)

and the penetration rate is the total derivative
delta' = -v_z + phi . q' + (grad phi . q) . (v_x, v_y). With c = 0 and undamped modes the
total energy (balls, modes 1/2 q'^2 + 1/2 omega^2 q^2, contacts) is then conserved exactly:
the reference's independent check.

Mode shapes (``shapes``):

* ``"exact"`` (default, the independent choice): phi and grad phi are evaluated at the ball's
  current (x, y) in every right-hand-side call and every event row. The slope term is the
  frictionless reaction of the tilted deflected surface to first order in its slope
  (~1e-5 here); the fast stream solver leaves it out.
* ``"frozen"``: while a plate contact lasts it keeps the shapes at its first touch and has no
  slope term (the fast solver's contact model: ``tailbeam.solvers.stream.active.compiled.pairs``);
  before a touch the gap is exact. Comparing both variants measures what freezing costs.

Friction (``friction=`` of the reference; with frozen shapes a contact keeps the
gradients of its first touch with its shapes, as the fast solver does). The friction force
F_t on a ball acts, reversed, on the plate's top surface, h/2 above its mid-surface, whose in-plane
displacement is -(h/2) grad w (Kirchhoff): the modes feel the generalised force
(h/2) F_t . grad phi, and the slip is measured against the surface's in-plane velocity
-(h/2) grad phi . q'. The plate then takes exactly the power the ball gives up less what
friction dissipates (F_t . slip), so with c = 0 and undamped modes energy + dissipated is
conserved (the check).

grad phi is a central difference of the basis (``tailbeam.plate.slopes``: relative error
~(k h)^2 / 6 < 1e-7 of the slope for wavenumbers k < 100 /m, itself ~1e-5 of the force).
"""

import math

import numpy as np

from tailbeam.errors import InputError
from tailbeam.plate.slopes import values_and_slopes

SHAPES = ("exact", "frozen")
GRID = 41  # points per side where max |phi| is sampled (scale of the modal tolerances)


class ReferencePlate:
    """The two-way modal plate of ``simulate_stream_reference(..., plate=...)``; it starts at
    rest (q = q' = 0).

    Parameters
    ----------
    basis : ModalBasis
        Mass-normalised modes of the plate: angular frequencies ``omega`` (rad/s) and shapes
        (1/sqrt(kg)).
    zeta : float or array_like
        Modal damping ratios in [0, 1), one per mode or one for all.
    shapes : str
        ``"exact"`` (shapes evaluated at the ball's current position) or ``"frozen"`` (a
        plate contact keeps the shapes of its first touch); see the module docstring.

    Attributes
    ----------
    omega : ndarray
        Angular frequencies (rad/s), one per mode.
    n_modes : int
        Number of modes.
    phi_scale : float
        Largest |phi| over the plate (1/sqrt(kg)), sampled on a grid: the scale of the modal
        tolerances.
    k_max : float
        Wavenumber of the top mode (1/m), from the Kirchhoff dispersion relation.
    """

    def __init__(self, basis, zeta, shapes: str = "exact"):
        self.basis = basis
        self.omega = np.asarray(basis.omega, dtype=float)
        m = self.omega.shape[0]
        zeta = np.broadcast_to(np.asarray(zeta, dtype=float), (m,)).copy()
        if not np.all((zeta >= 0.0) & (zeta < 1.0)):
            raise InputError("zeta", "damping ratios must lie in [0, 1) (one per mode)")
        if shapes not in SHAPES:
            raise InputError("shapes", f"must be one of {SHAPES}, got {shapes!r}")
        self.zeta, self.shapes, self.n_modes = zeta, shapes, m
        plate = basis.plate
        xs = np.linspace(-0.5 * plate.size_x, 0.5 * plate.size_x, GRID)
        ys = np.linspace(-0.5 * plate.size_y, 0.5 * plate.size_y, GRID)
        grid = np.array([(x, y) for x in xs for y in ys])
        self.phi_scale = float(np.max(np.abs(basis.deflection(grid))))
        # Kirchhoff dispersion omega = k^2 sqrt(D / rho h): wavenumber (1/m) of the top mode
        speed = math.sqrt(plate.bending_stiffness / plate.mass_per_area)
        self.k_max = math.sqrt(float(np.max(self.omega)) / speed)

    @property
    def frozen(self) -> bool:
        """Whether a plate contact keeps the shapes of its first touch."""
        return self.shapes == "frozen"

    def check_size(self, incline) -> None:
        """The basis must describe the plate of ``incline`` (same size)."""
        a, b = self.basis.plate, incline.plate
        if not (math.isclose(a.size_x, b.size_x) and math.isclose(a.size_y, b.size_y)):
            raise InputError(
                "plate", f"the modal basis is for a {a.size_x} x {a.size_y} m plate, the "
                f"incline's plate is {b.size_x} x {b.size_y} m"
            )  # fmt: skip

    def atol(self, rtol: float) -> np.ndarray:
        """Absolute tolerances of [q | q']: deflections to rtol x 1 mm, rates rtol x 1 m/s."""
        m = self.n_modes
        return rtol / self.phi_scale * np.concatenate([np.full(m, 1e-3), np.ones(m)])

    def shapes_at(self, xy) -> np.ndarray:
        """(p, m) mode shapes in 1/sqrt(kg) at points xy (p, 2) m."""
        return self.basis.deflection(np.reshape(xy, (-1, 2)))

    def shapes_and_gradients(self, xy):
        """(p, m) mode shapes and (p, m, 2) their gradients d phi / d(x, y) in
        1/(m sqrt(kg)) at points xy (p, 2) m (``tailbeam.plate.slopes``: one evaluation of
        the basis at 5 p points)."""
        return values_and_slopes(self.shapes_at, xy)

    def acceleration(self, q, qd, modal_force) -> np.ndarray:
        """q'' (m sqrt(kg) / s^2) of the modes under modal forces (N / sqrt(kg))."""
        return modal_force - 2.0 * self.zeta * self.omega * qd - self.omega**2 * q

    def energy(self, q, qd) -> float:
        """Modal kinetic + strain energy in J (unit modal mass)."""
        return float(0.5 * np.sum(qd * qd + (self.omega * q) ** 2))

    def contact_geometry(self, xi, vi, is_plate, frozen_phi, modes):
        """Penetration, rate, slope and shapes of the plate pairs among P pairs.

        xi, vi: (..., P, 3) centre and velocity of each pair's ball i; is_plate (P,);
        frozen_phi: (P, m) shapes kept by frozen contacts (NaN rows: evaluate exactly);
        modes: (q, q') each (..., m). Returns arrays (..., P) delta - r (m, i.e. w - z),
        rate (m/s), (..., P, 2) slope, (..., P, m) shapes and (..., P, m, 2) their gradients
        (1/(m sqrt(kg)); zero for frozen shapes), zero where not is_plate.
        """
        q, qd = modes
        lead, p, m = xi.shape[:-2], xi.shape[-2], self.n_modes
        kept = ~np.isnan(frozen_phi[:, 0]) if m else np.zeros(p, dtype=bool)
        exact = is_plate & ~kept
        phi = np.zeros((*lead, p, m))
        grad = np.zeros((*lead, p, m, 2))
        if np.any(exact):
            xy = xi[..., exact, :2]
            shapes, gradients = self.shapes_and_gradients(xy)
            phi[..., exact, :] = shapes.reshape(*xy.shape[:-1], m)
            grad[..., exact, :, :] = gradients.reshape(*xy.shape[:-1], m, 2)
        phi[..., kept, :] = frozen_phi[kept]
        w = np.einsum("...pm,...m->...p", phi, q)
        wd = np.einsum("...pm,...m->...p", phi, qd)
        slope = np.einsum("...pmk,...m->...pk", grad, q)
        rate = -vi[..., 2] + wd + np.einsum("...pk,...pk->...p", slope, vi[..., :2])
        return w - xi[..., 2], rate, slope, phi, grad
