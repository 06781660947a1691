"""What a sensor channel reads of the modal plate or structure: displacement at its point
along its direction, as mode shapes and as a static cross compliance.

A channel is a single-direction ``SensorSpec`` (``SensorSpec.channels``). On a structure from
a mesh (a basis with its ``StructureModel``) the point is any point of the surface (a point
(x, y) is (x, y, 0) on the impact face), read along the direction (default +z, the impact
face's normal) by the structure's own displacement operator (``surface_operator``: the
nearest surface point within ``tailbeam.plate.solid.surface.SURFACE_TOLERANCE`` of the
structure's size). On the flat plate a channel at a point of its top (z = 0) or bottom
(z = -thickness) face reads the surface's motion by Kirchhoff's kinematics: the deflection w
along the direction's z component, and the in-plane displacement -zeta grad w (zeta the
point's height above the mid-plane: +h/2 on top, -h/2 below) along its x, y components;
grad w by central differences (``tailbeam.plate.slopes``, one-sided at an edge). On a Mindlin plate
this reads the slope of w where the plate's own rotation differs from it by the shear angle.

The static part (the full model's displacement at the channel under 1 N pressing on the
impact face, for the truncated modes' quasi-static response) is taken by Maxwell-Betti
reciprocity: one static solve per channel under a unit force at the channel along its
direction, read as the z-displacement at the load points. On a structure those solutions
are kept in the cache beside its basis (``tailbeam.plate.solid.face.influence``), so a run
whose channels were solved before factorises nothing for them.
"""

import numpy as np

from tailbeam.physics.contact_patch import disc_rule
from tailbeam.plate.slopes import values_and_slopes
from tailbeam.plate.solid.face.influence import FaceInfluence, channel_points


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
        self._influence = self._shapes = None
        self.static = None
        if getattr(basis, "static_deflection_at", None) is not None:
            self.static = self._static_solid if self.model is not None else self._static_flat

    def _points_directions(self):
        """(p, 3) m points and (p, 3) unit directions of the channels."""
        return channel_points(self.channels)

    def _operator(self):
        """(p, n_dofs) sparse: the structure's displacement at the channels."""
        pts, dirs = self._points_directions()
        fields = ", ".join(f"sensors[{c.name}].position" for c in self.channels)
        return self.model.surface_operator(pts, dirs, fields)

    def _flat(self):
        """(points (p, 2) m, z components (p,), levers (p, 2) m) of the channels on the flat
        plate: a channel reads z w + lever . grad w, lever = -zeta (dx, dy)."""
        pts, dirs = self._points_directions()
        zeta = pts[:, 2] + 0.5 * self.basis.plate.thickness
        return pts[:, :2], dirs[:, 2], -zeta[:, None] * dirs[:, :2]

    def _flat_reading(self, evaluate) -> np.ndarray:
        """(p, k) the channels' readings of a field: ``evaluate(i, points (m, 2))`` -> (m, k)
        its deflection at points of the plate for channel i (the same field for every
        channel, or one per channel)."""
        xy, zs, levers = self._flat()
        rows = []
        for i, (point, z, lever) in enumerate(zip(xy, zs, levers, strict=True)):
            if not np.any(lever):
                rows.append(z * evaluate(i, point[None, :])[0])
                continue
            plate = self.basis.plate
            half = 0.5 * np.array([plate.size_x, plate.size_y])
            value, slope = values_and_slopes(lambda pts, i=i: evaluate(i, pts), point, half)
            rows.append(z * value[0] + slope[0] @ lever)
        return np.array(rows)

    def shapes(self) -> np.ndarray:
        """(p, n_modes) modal displacements along each channel's direction, 1/sqrt(kg)
        (computed once: ``residual_cross`` reads them at every contact point)."""
        if self._shapes is None:
            n = self.basis.n_modes
            if self.model is not None:
                self._shapes = np.asarray(self._operator() @ self.basis.mode_vectors)[:, :n]
            else:
                self._shapes = self._flat_reading(lambda _i, pts: self.basis.deflection(pts))
        return self._shapes

    def _static_flat(self, loads) -> np.ndarray:
        """(q, p): by reciprocity, the deflection at the loads under 1 N at each channel's
        point, read at that point as the channel reads a field."""
        loads = np.atleast_2d(np.asarray(loads, dtype=float))

        def at(_i, pts):  # (m, q): deflection at the loads under 1 N at each of pts
            return np.array([self.basis.static_deflection_at(p, loads, 0.0) for p in pts])

        return self._flat_reading(at).T

    def _static_solid(self, loads) -> np.ndarray:
        """(q, p) by reciprocity from each channel's K^-1 of a unit force at it along its
        direction (``FaceInfluence``: cached beside the basis)."""
        if self._influence is None:
            pts, dirs = self._points_directions()
            dirs = dirs / np.linalg.norm(dirs, axis=1, keepdims=True)
            cache_dir = getattr(self.basis.static_compliance_at, "cache_dir", None)
            self._influence = FaceInfluence(self.model, self._operator(), pts, dirs, cache_dir)
        return self._influence(loads)

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
