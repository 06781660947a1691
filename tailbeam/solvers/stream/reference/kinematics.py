"""Penetration, rate and normal of the watched pairs at given states.

Each pair's geometry comes from ``tailbeam.physics.pair`` (against the undeformed plate) or,
on the modal plate, ``ReferencePlate.contact_geometry`` (against the deflected one).
"""

from dataclasses import dataclass, replace

import numpy as np

from tailbeam.physics.pair import pair_kinematics, plate_foot


@dataclass(frozen=True)
class PairIndex:
    """Where pairs' balls sit in the state.

    Parameters
    ----------
    li, lj : ndarray of int
        State positions of each pair's balls i and j (lj unused where ``is_plate``).
    is_plate : ndarray of bool
        Whether each pair is a ball-plate pair.
    radius_sum : ndarray
        r_i + r_j of each pair (m).
    frozen_phi : ndarray or None
        (P, m) mode shapes kept by frozen plate contacts, NaN rows where the shapes are
        evaluated exactly; None on the rigid plate.
    frozen_grad : ndarray or None
        (P, m, 2) their gradients (friction's lever on the plate's surface), zero rows where
        the shapes are evaluated exactly; None on the rigid plate.
    """

    li: np.ndarray
    lj: np.ndarray
    is_plate: np.ndarray
    radius_sum: np.ndarray
    frozen_phi: np.ndarray | None = None
    frozen_grad: np.ndarray | None = None


class Kinematics:
    """The pairs' contact kinematics on the current state layout.

    Parameters
    ----------
    layout : StateLayout
        Where each ball sits in the state.
    plate : ReferencePlate or None
        The modal plate, or None for the rigid plate.
    """

    def __init__(self, layout, plate):
        self.layout = layout
        self.plate = plate

    def index(self, pairs) -> PairIndex:
        """Local ball indices and radius sums of ``pairs`` (valid until a ball is dropped)."""
        loc = self.layout.local()
        li = loc[[p.i for p in pairs]]
        lj = loc[[max(p.j, 0) for p in pairs]]
        is_plate = np.array([p.j < 0 for p in pairs], dtype=bool)
        frozen = grads = None
        if self.plate is not None:
            frozen = np.full((len(pairs), self.plate.n_modes), np.nan)
            grads = np.zeros((len(pairs), self.plate.n_modes, 2))
            for k, p in enumerate(pairs):
                if p.phi0 is not None:
                    frozen[k], grads[k] = p.phi0, p.grad0
        rsum = np.array([p.radius_sum for p in pairs])
        return PairIndex(li, lj, is_plate, rsum, frozen, grads)

    def of(self, pairs, x, v, modes=None):
        """Kinematics of ``pairs`` (a list or its ``index``) at positions x (m) and
        velocities v (m/s) of shape (..., n, 3), and on the modal plate modes (q, q'), each
        (..., m).

        Returns
        -------
        kin : PairKinematics
            Flattened over the leading axes and the pairs.
        li, lj : ndarray of int
            State positions of the pairs' balls.
        is_plate : ndarray of bool
            Ball-plate pairs.
        """
        if self.plate is not None:
            return self.modal(pairs, x, v, modes)[:4]
        ix = pairs if isinstance(pairs, PairIndex) else self.index(pairs)
        return self.rigid(ix, x, v)[:4]

    @staticmethod
    def rigid(ix, x, v):
        """``of`` against the undeformed plate; also returns the balls i's centres and
        velocities (..., P, 3) and the radius sums (..., P)."""
        li, lj, is_plate = ix.li, ix.lj, ix.is_plate
        xi, vi = x[..., li, :], v[..., li, :]
        foot = plate_foot(xi.reshape(-1, 3)).reshape(xi.shape)
        xj = np.where(is_plate[:, None], foot, x[..., lj, :])
        vj = np.where(is_plate[:, None], 0.0, v[..., lj, :])
        rsum = np.broadcast_to(ix.radius_sum, xi.shape[:-1])
        kin = pair_kinematics(*(a.reshape(-1, 3) for a in (xi, vi, xj, vj)), rsum.reshape(-1))
        return kin, li, lj, is_plate, xi, vi, rsum

    def modal(self, pairs, x, v, modes):
        """``of`` on the modal plate: the plate pairs' penetration and rate against the
        deflected plate; also returns their slope (P', 2), shapes (P', m) and the shapes'
        gradients (P', m, 2) (a frozen contact's kept ones: no slope term, but friction's
        lever), flattened over the leading axes as the kinematics."""
        ix = pairs if isinstance(pairs, PairIndex) else self.index(pairs)
        kin, li, lj, is_plate, xi, vi, rsum = self.rigid(ix, x, v)
        gap, rate, slope, phi, grad = self.plate.contact_geometry(
            xi, vi, is_plate, ix.frozen_phi, modes
        )
        kept = ~np.isnan(ix.frozen_phi[:, 0]) if self.plate.n_modes else is_plate & False
        if np.any(kept):  # a frozen contact's lever for friction: the gradients it kept
            grad[..., kept, :, :] = ix.frozen_grad[kept]
        flat = np.broadcast_to(is_plate, rsum.shape).reshape(-1)
        kin = replace(
            kin,
            penetration=np.where(flat, (rsum + gap).reshape(-1), kin.penetration),
            rate=np.where(flat, rate.reshape(-1), kin.rate),
        )
        m = self.plate.n_modes
        return (kin, li, lj, is_plate, slope.reshape(-1, 2), phi.reshape(-1, m),
                grad.reshape(-1, m, 2))  # fmt: skip

    def surface_velocity(self, grad, qd, pairs: int):
        """In-plane velocity (P', 3) of the plate's top surface under each pair's point
        (m/s; z left 0): -(h/2) grad phi . q'. ``grad`` (P', m, 2) as ``modal`` returns it
        for ``pairs`` pairs per state, qd (..., m) the modal rates of those states."""
        rows = np.repeat(np.reshape(qd, (-1, self.plate.n_modes)), pairs, axis=0)
        out = np.zeros((grad.shape[0], 3))
        half = 0.5 * self.plate.basis.plate.thickness
        out[:, :2] = -half * np.einsum("rmk,rm->rk", grad, rows)
        return out
