"""What a sensor channel reads of the modal plate or structure: displacement at its point
along its direction, as mode shapes and as a static cross compliance.

A channel is a single-direction ``SensorSpec`` (``SensorSpec.channels``). On a structure from
a mesh (a basis with its ``StructureModel``) the point is any point of the surface (a point
(x, y) is (x, y, 0) on the impact face), read along the direction (default +z, the impact
face's normal) by the structure's own displacement operator (``surface_operator``: the
nearest surface point within ``tailbeam.plate.solid.surface.SURFACE_TOLERANCE`` of the
structure's size). On the flat plate a channel reads the deflection w at (x, y) times the
direction's z component: the scene reader only lets through points of the top (z = 0) or
bottom (z = -thickness) surface read along +-z, where plate theory's normal displacement is
w at both faces.

The static part (the full model's displacement at the channel under 1 N pressing on the
impact face, for the truncated modes' quasi-static response) is taken by Maxwell-Betti
reciprocity: one static solve per channel under a unit force at the channel along its
direction, read as the z-displacement at the load points.
"""

import numpy as np

from tailbeam.errors import InputError
from tailbeam.physics.contact_patch import disc_rule


class Readings:
    """The channels ``channels`` (single-direction SensorSpecs) on ``basis``.

    ``shapes()`` (p, n_modes) modal displacements (1/sqrt(kg)) along each channel's direction;
    ``static`` (None without a static model) maps load points (q, 2) m to (q, p): the
    displacement (m/N) at each channel under 1 N (+z) at each point; ``residual_cross``
    the truncated modes' part of it under one load (as ModalBasis.residual_cross_compliance).
    """

    def __init__(self, basis, channels):
        self.basis = basis
        self.channels = tuple(channels)
        self.model = getattr(basis, "model", None)  # a StructureModel, or None: the flat plate
        self._columns = self._shapes = None
        self.static = None
        if getattr(basis, "static_deflection_at", None) is not None:
            self.static = self._static_solid if self.model is not None else self._static_flat

    def _points_directions(self):
        """(p, 3) m points and (p, 3) unit directions of the channels."""
        pts, dirs = [], []
        for c in self.channels:
            xyz = tuple(c.position) + (0.0,) * (3 - len(c.position))
            pts.append(xyz)
            dirs.append(c.direction if c.direction is not None else (0.0, 0.0, 1.0))
        return np.array(pts, dtype=float), np.array(dirs, dtype=float)

    def _operator(self):
        """(p, n_dofs) sparse: the structure's displacement at the channels."""
        pts, dirs = self._points_directions()
        fields = ", ".join(f"sensors[{c.name}].position" for c in self.channels)
        return self.model.surface_operator(pts, dirs, fields)

    def _flat(self):
        """(points (p, 2) m, z components (p,)) of the channels on the flat plate."""
        pts, dirs = self._points_directions()
        if np.any(np.abs(dirs[:, :2]) > 1e-12):
            raise InputError(
                "sensors", "on the flat plate a sensor reads along the normal (0, 0, +-1) only"
            )
        return pts[:, :2], dirs[:, 2]

    def shapes(self) -> np.ndarray:
        """(p, n_modes) modal displacements along each channel's direction, 1/sqrt(kg)
        (computed once: ``residual_cross`` reads them at every contact point)."""
        if self._shapes is None:
            n = self.basis.n_modes
            if self.model is not None:
                self._shapes = np.asarray(self._operator() @ self.basis.mode_vectors)[:, :n]
            else:
                pts, sign = self._flat()
                self._shapes = self.basis.deflection(pts) * sign[:, None]
        return self._shapes

    def _static_flat(self, loads) -> np.ndarray:
        pts, sign = self._flat()
        loads = np.atleast_2d(np.asarray(loads, dtype=float))
        cols = [self.basis.static_deflection_at(p, loads, 0.0) for p in pts]
        return np.column_stack(cols) * sign[None, :]

    def _static_solid(self, loads) -> np.ndarray:
        if self._columns is None:  # K^-1 of a unit force at each channel along its direction
            rhs = np.asarray(self._operator().T.todense())
            self._columns = self.model.solver().solve(rhs).reshape(rhs.shape)
        loads = np.atleast_2d(np.asarray(loads, dtype=float))
        return np.asarray(self.model.face_operator(loads) @ self._columns)

    def residual_cross(self, load_point, contact_radius: float = 0.0) -> np.ndarray:
        """(p,) static displacement (m/N) of the modes left out at the channels under 1 N
        spread over a disc of ``contact_radius`` m about the impact-face point ``load_point``
        (the full model's minus sum phi_i(channel) phibar_i(load) / omega_i^2)."""
        point = np.asarray(load_point, dtype=float).reshape(2)
        if contact_radius == 0.0:
            full = self.static(point[None, :])[0]
        else:
            pts, weights = disc_rule(self.basis.plate, point, contact_radius)
            full = weights @ self.static(pts)
        phibar = self.basis.load_deflection([load_point], contact_radius)[0]
        return full - self.shapes() @ (phibar / self.basis.omega**2)
