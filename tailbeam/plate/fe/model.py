"""The assembled FE plate: constrained stiffness and mass matrices, the deflection operator
(mid-surface deflection at points) and load vectors. Shared by the modal solver and by
anyone who needs the matrices themselves (e.g. a Newmark cross-check of the modal model).
"""

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from skfem import Basis, MeshTri, condense

from tailbeam.errors import InputError, require_nonnegative
from tailbeam.physics.bodies import Plate
from tailbeam.physics.contact_patch import disc_rule
from tailbeam.plate.fe.boundary import parse_boundary
from tailbeam.plate.fe.kirchhoff import ELEMENT_NAME as KIRCHHOFF_ELEMENT
from tailbeam.plate.fe.kirchhoff import assemble_kirchhoff
from tailbeam.plate.fe.mesh import check_mesh, default_mesh, load_mesh
from tailbeam.plate.fe.mindlin import DEFAULT_DEGREE, assemble_mindlin
from tailbeam.plate.fe.sparse_solve import SymmetricSolver
from tailbeam.plate.probes import PointProbe

THEORIES = ("kirchhoff", "mindlin")


def check_points(plate: Plate, points, field: str = "points") -> np.ndarray:
    """(p, 2) float array of points on the plate (edges included), else InputError."""
    pts = np.atleast_2d(np.asarray(points, dtype=float))
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise InputError(field, f"must be an array of (x, y) pairs, got shape {pts.shape}")
    tol = 1e-9 * max(plate.size_x, plate.size_y)
    off = (np.abs(pts[:, 0]) > 0.5 * plate.size_x + tol) | (
        np.abs(pts[:, 1]) > 0.5 * plate.size_y + tol
    )
    if not np.all(np.isfinite(pts)) or off.any():
        bad = pts[np.argmax(off | ~np.isfinite(pts).all(axis=1))]
        where = ", ".join(f"{float(v):.6g}" for v in bad)
        raise InputError(field, f"point ({where}) m is not on the plate (centred on the origin)")
    # nudge points exactly on the boundary inside so the element finder always succeeds
    half = 0.5 * np.array([plate.size_x, plate.size_y]) * (1.0 - 1e-12)
    return np.clip(pts, -half, half)


@dataclass(eq=False)
class PlateModel:
    """Constrained FE model of a plate: K u = f, M u'' + K u = f on the free DOFs.

    stiffness, mass: (n, n) CSR matrices (N/m and kg in the sense of generalised DOFs) on the
    free DOFs ``free_dofs`` of the full vector (length ``n_full``); ``expand`` maps back.
    deflection_basis: the skfem Basis of the deflection w; its DOFs sit at
    [w_offset, w_offset + deflection_basis.N) of the full vector.
    """

    plate: Plate
    boundary: str
    theory: str
    mesh: MeshTri
    element: str
    stiffness: sp.csr_matrix
    mass: sp.csr_matrix
    free_dofs: np.ndarray
    n_full: int
    deflection_basis: Basis
    w_offset: int = 0
    _solver: SymmetricSolver | None = field(default=None, repr=False)
    _probe: PointProbe | None = field(default=None, repr=False)

    @property
    def n_dofs(self) -> int:
        return int(self.stiffness.shape[0])

    def expand(self, x) -> np.ndarray:
        """Full DOF vector(s) (n_full,) or (n_full, k) from free-DOF vector(s); fixed DOFs 0."""
        x = np.asarray(x)
        out = np.zeros((self.n_full,) + x.shape[1:], dtype=x.dtype)
        out[self.free_dofs] = x
        return out

    def deflection_operator(self, points) -> sp.csr_matrix:
        """(p, n) sparse matrix: deflection (m) at points (p, 2) from free-DOF vectors."""
        pts = check_points(self.plate, points)
        if self._probe is None:
            self._probe = PointProbe(self.deflection_basis)
        probe = self._probe.operator(pts)
        full = sp.csr_matrix(
            (probe.data, probe.indices + self.w_offset, probe.indptr),
            shape=(probe.shape[0], self.n_full),
        )
        return full[:, self.free_dofs].tocsr()

    def load_vector(self, point, contact_radius: float = 0.0) -> np.ndarray:
        """(n,) generalised load of a unit total force (1 N, along +z) spread uniformly over
        a disc of ``contact_radius`` m about ``point``; radius 0 is a point load."""
        radius = require_nonnegative("contact_radius", contact_radius)
        pts, weights = disc_rule(self.plate, check_points(self.plate, point)[0], radius)
        return np.asarray(self.deflection_operator(pts).T @ weights).ravel()

    def solver(self) -> SymmetricSolver:
        """Cached sparse factorisation of K (InputError for a plate that can move rigidly)."""
        if self._solver is None:
            self._solver = SymmetricSolver(self.stiffness)
        return self._solver

    def static_compliance(self, points, contact_radius: float = 0.0) -> np.ndarray:
        """(p,) static compliance w/F (m/N): mean deflection under a unit load spread over a
        disc of ``contact_radius`` about each point (radius 0: deflection under a point
        load; finite in the FE model, though Mindlin's continuum value diverges)."""
        pts = check_points(self.plate, points)
        out = np.empty(len(pts))
        for i, p in enumerate(pts):
            f = self.load_vector(p, contact_radius)
            out[i] = f @ self.solver().solve(f)
        return out

    def static_deflection(self, load_point, points, contact_radius: float = 0.0) -> np.ndarray:
        """(p,) static deflection (m/N) at ``points`` under a unit load at ``load_point``
        (spread over a disc of ``contact_radius`` m): the static cross compliance."""
        f = self.load_vector(load_point, contact_radius)
        return np.asarray(self.deflection_operator(points) @ self.solver().solve(f)).ravel()


def resolve_mesh(plate: Plate, mesh, divisions) -> MeshTri:
    """A mesh from mesh=path/MeshTri or from divisions (default structured mesh)."""
    if mesh is not None and divisions is not None:
        raise InputError("divisions", "give either mesh or divisions, not both")
    if mesh is None:
        if divisions is None:
            raise InputError("divisions", "give mesh or divisions")
        return default_mesh(plate, divisions)
    if isinstance(mesh, MeshTri):
        return check_mesh(mesh, plate)
    return load_mesh(mesh, plate)


def assemble_plate(
    plate: Plate,
    boundary: str = "SSSS",
    *,
    theory: str = "kirchhoff",
    mesh=None,
    divisions=None,
    mindlin_degree: int = DEFAULT_DEGREE,
) -> PlateModel:
    """Assemble the constrained FE model of ``plate`` with edge conditions ``boundary``.

    theory: 'kirchhoff' (Argyris) or 'mindlin' (Lagrange P4 w, beta); mesh: a path or an
    skfem MeshTri with named edges; or divisions: int/(nx, ny) for the structured mesh.
    """
    if not isinstance(plate, Plate):
        raise InputError("plate", "must be a tailbeam Plate")
    boundary = parse_boundary(boundary)
    if theory not in THEORIES:
        raise InputError("theory", f"must be one of {', '.join(THEORIES)}, got {theory!r}")
    mesh = resolve_mesh(plate, mesh, divisions)
    if theory == "kirchhoff":
        K, M, basis, fixed = assemble_kirchhoff(plate, boundary, mesh)
        element = KIRCHHOFF_ELEMENT
    else:
        if mindlin_degree not in (3, 4):
            raise InputError("mindlin_degree", f"must be 3 or 4, got {mindlin_degree!r}")
        K, M, basis, fixed = assemble_mindlin(plate, boundary, mesh, degree=mindlin_degree)
        element = f"Lagrange P{mindlin_degree} for w, beta_x, beta_y"
    n_full = K.shape[0]
    # skfem's condense keeps the free DOFs I of the generalised problem (K_II, M_II)
    k_free, m_free, _, free = condense(K, M, D=fixed)
    return PlateModel(
        plate=plate,
        boundary=boundary,
        theory=theory,
        mesh=mesh,
        element=element,
        stiffness=k_free.tocsr(),
        mass=m_free.tocsr(),
        free_dofs=np.asarray(free, dtype=np.int64),
        n_full=n_full,
        deflection_basis=basis,
    )
