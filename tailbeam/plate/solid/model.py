"""The assembled structure: a volume mesh with its elasticity, supports and impact face;
its stiffness and mass on the held DOFs q (full displacements u = T q), the operators that
read displacements on the impact face and anywhere on the surface, and static solves.

Building a model checks everything a scene needs checked (the mesh, the face, the supports,
that they hold the structure) from the mesh's geometry and the DOF numbering alone; the
stiffness and mass are assembled on first use (an eigen-solve, a static solve), so a run
whose basis and compliances come from the cache assembles nothing.
"""

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from tailbeam.errors import InputError, require_nonnegative
from tailbeam.physics.contact_patch import disc_rule
from tailbeam.physics.materials import CARBON_STEEL, Material
from tailbeam.plate.fe.model import check_points
from tailbeam.plate.solid.elasticity import ELEMENT_NAMES, assemble_on, dof_basis, vector_basis
from tailbeam.plate.solid.face.plane import ImpactFace, impact_face
from tailbeam.plate.solid.face.readings import FaceReadings, face_readings
from tailbeam.plate.solid.factor import factorize
from tailbeam.plate.solid.probe import DisplacementProbe
from tailbeam.plate.solid.supports import (
    Support,
    apply_supports,
    check_support,
    free_rigid_motions,
)
from tailbeam.plate.solid.surface import Surface, surface_of
from tailbeam.plate.solid.volume_mesh import VolumeMesh, read_volume_mesh

SUPPORTS_FIELD = "plate.supports"


@dataclass(eq=False)
class StructureModel:
    """A held (or deliberately free) linear elastic structure.

    basis : the displacement basis' DOF numbering, element and mapping (``dof_basis``).
    transform : (N, n) CSR, full DOFs u = transform @ q.
    spring : (N, N) CSR, the spring supports' stiffness on the full DOFs, N/m.
    rigid_modes : rigid-body motions left free (0 unless built with ``free=True``).
    ``stiffness`` and ``mass`` ((n, n) CSR on q, N/m and kg) are assembled on first use.
    """

    vmesh: VolumeMesh
    face: ImpactFace
    basis: object
    element: str
    transform: sp.csr_matrix
    spring: sp.csr_matrix
    rigid_modes: int
    supports: tuple
    material: Material
    _matrices: tuple | None = field(default=None, repr=False)  # (stiffness, mass)
    _surface: Surface | None = field(default=None, repr=False)
    _probe: DisplacementProbe | None = field(default=None, repr=False)
    _solver: object = field(default=None, repr=False)
    _face_readings: tuple | None = field(default=None, repr=False)  # (FaceReadings or None,)

    @property
    def plate(self):
        return self.face.plate

    @property
    def n_dofs(self) -> int:
        return int(self.transform.shape[1])

    @property
    def stiffness(self) -> sp.csr_matrix:
        return self._assembled()[0]

    @property
    def mass(self) -> sp.csr_matrix:
        return self._assembled()[1]

    @property
    def assembled(self) -> bool:
        """Whether the stiffness and mass have been assembled (they are on first use)."""
        return self._matrices is not None

    def _assembled(self) -> tuple:
        """(stiffness, mass) on the reduced DOFs, assembled once with the full quadrature."""
        if self._matrices is None:
            full = vector_basis(self.vmesh.mesh, self.vmesh.kind)
            if full.N != self.basis.N:
                raise RuntimeError("the assembly's DOF numbering differs from the model's")
            elastic = assemble_on(full, self.material, self.element)
            t = self.transform
            k = (t.T @ ((elastic.stiffness + self.spring) @ t)).tocsr()
            self._matrices = (k, (t.T @ (elastic.mass @ t)).tocsr())
        return self._matrices

    def probe(self) -> DisplacementProbe:
        if self._probe is None:
            self._probe = DisplacementProbe(self.basis)
        return self._probe

    def face_readings(self) -> FaceReadings | None:
        """The impact face's fast readings (``face.readings``), made once; None when a facet
        is not a parallelogram (the probe reads the face then)."""
        if self._face_readings is None:
            self._face_readings = (face_readings(self),)
        return self._face_readings[0]

    def face_operator(self, points) -> sp.csr_matrix:
        """(p, n) z-displacement (m) at impact-face points (p, 2) from reduced vectors."""
        pts = _face_points(self.plate, points)
        cells = self.face.cells_at(pts)
        xyz = np.column_stack([pts, np.zeros(len(pts))])
        dirs = np.tile([0.0, 0.0, 1.0], (len(pts), 1))
        return (self.probe().operator(xyz, cells, dirs) @ self.transform).tocsr()

    def surface(self) -> Surface:
        if self._surface is None:
            self._surface = surface_of(self.vmesh.mesh)
        return self._surface

    def surface_operator(self, points, directions=None, field_name="sensors") -> sp.csr_matrix:
        """(p, n) displacement (m) along ``directions`` (p, 3; default the outward surface
        normal there) at surface points (p, 3) from reduced vectors; InputError naming
        ``field_name`` for a point off the surface."""
        xyz, cells, normals = self.surface().locate(points, field_name)
        if directions is None:
            dirs = normals
        else:
            dirs = np.atleast_2d(np.asarray(directions, dtype=float))
            norm = np.linalg.norm(dirs, axis=1, keepdims=True)
            if dirs.shape != xyz.shape or np.any(norm == 0):
                raise InputError(field_name, "directions must be nonzero (x, y, z) vectors")
            dirs = dirs / norm
        return (self.probe().operator(xyz, cells, dirs) @ self.transform).tocsr()

    def load_vector(self, point, contact_radius: float = 0.0) -> np.ndarray:
        """(n,) generalised load of 1 N along +z spread uniformly over a disc of
        ``contact_radius`` m about the impact-face point (x, y)."""
        radius = require_nonnegative("contact_radius", contact_radius)
        centre = _face_points(self.plate, point)[0]
        pts, weights = disc_rule(self.plate, centre, radius)
        return np.asarray(self.face_operator(pts).T @ weights).ravel()

    def solver(self):
        """Cached factorisation of the stiffness (``factor.factorize``)."""
        if self.rigid_modes:
            raise InputError(SUPPORTS_FIELD, "a free structure has no static compliance")
        if self._solver is None:
            self._solver = factorize(self.stiffness)
        return self._solver

    def static_compliance(self, points, contact_radius: float = 0.0) -> np.ndarray:
        """(p,) mean z-deflection (m/N) over the disc under 1 N spread over it."""
        pts = _face_points(self.plate, points)
        out = np.empty(len(pts))
        for i, p in enumerate(pts):
            f = self.load_vector(p, contact_radius)
            out[i] = f @ self.solver().solve(f)
        return out

    def static_deflection(self, load_point, points, contact_radius: float = 0.0) -> np.ndarray:
        """(p,) z-deflection (m/N) at impact-face ``points`` under 1 N at ``load_point``."""
        f = self.load_vector(load_point, contact_radius)
        return np.asarray(self.face_operator(points) @ self.solver().solve(f)).ravel()


def _face_points(plate, points) -> np.ndarray:
    """(p, 2) points of the impact face's rectangle, else InputError."""
    return check_points(plate, points)


def assemble_structure(
    mesh,
    impact_face_name: str,
    supports=(),
    *,
    material: Material = CARBON_STEEL,
    free: bool = False,
) -> StructureModel:
    """A structure from a volume mesh (a path, or a VolumeMesh): the mesh read, the impact
    face, the supports applied and checked (a structure they do not hold is refused); the
    stiffness and mass are assembled on first use (``StructureModel.stiffness``).

    Parameters
    ----------
    mesh : str, Path or VolumeMesh
        The volume mesh (``plate.mesh``).
    impact_face_name : str
        The named flat face in z = 0 where particles land (``plate.impact_face``).
    supports : sequence of Support
        ``plate.supports[1]``, ... in order.
    material : Material
        Of the whole structure (E Pa, nu, rho kg/m^3).
    free : bool
        Allow rigid-body motions (a free structure); else a structure the supports do not
        hold is refused.
    """
    vmesh = mesh if isinstance(mesh, VolumeMesh) else read_volume_mesh(mesh)
    face = impact_face(vmesh, impact_face_name, material)
    fields = [f"{SUPPORTS_FIELD}[{i}]" for i in range(1, len(supports) + 1)]
    supports = tuple(check_support(s, f) for s, f in zip(supports, fields, strict=True))
    basis = dof_basis(vmesh.mesh, vmesh.kind)
    cons = apply_supports(basis, vmesh, supports, fields)
    rigid = free_rigid_motions(basis, cons)
    if rigid and not free:
        said = "no supports" if not supports else "these supports"
        raise InputError(
            SUPPORTS_FIELD,
            f"the structure is not held: {rigid} rigid-body motion(s) stay free with {said}; "
            "add supports, or ask for a free structure",
        )
    return StructureModel(vmesh, face, basis, ELEMENT_NAMES[vmesh.kind], cons.transform,
                          cons.spring, rigid, supports, material)  # fmt: skip


__all__ = ["StructureModel", "Support", "assemble_structure"]
