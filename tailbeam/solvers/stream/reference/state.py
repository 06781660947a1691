"""The stream reference's state vector, pair geometry and right-hand side (a mixin of
``tailbeam.solvers.stream.reference.solver._Reference``, which provides ``balls``, ``active``,
``pairs``, ``mass``, ``g`` and ``plate``).

The state is [positions | velocities] of the active balls (3 each, in the order of
``active``), followed on the modal plate by the modal coordinates [q | q']. Each pair's
penetration and rate come from ``tailbeam.physics.pair`` (against the undeformed plate) or
``ReferencePlate.contact_geometry`` (against the deflected one); the right-hand side applies
every pair's force in its current region (``impact_force_in_region``).
"""

from dataclasses import dataclass, replace

import numpy as np

from tailbeam.physics.contact_law import impact_force_in_region
from tailbeam.physics.pair import pair_kinematics, plate_foot


@dataclass(frozen=True)
class _PairIndex:
    """Local indices (li, lj; lj unused where is_plate) and radius sums (m) of pairs."""

    li: np.ndarray
    lj: np.ndarray
    is_plate: np.ndarray
    radius_sum: np.ndarray
    frozen_phi: np.ndarray | None = None  # (P, m), NaN rows: shapes evaluated exactly


@dataclass
class _Laws:
    """ImpactLaw parameters as arrays over pairs (duck-types ImpactLaw for the law helpers)."""

    stiffness: np.ndarray
    exponent: np.ndarray
    damping: np.ndarray
    penetration: np.ndarray


class ReferenceState:
    """State layout, kinematics and right-hand side of the stream reference."""

    # --- state layout ---------------------------------------------------------------------
    def split(self, y):
        """Positions and velocities (n, 3) of the active balls from a state vector."""
        n = len(self.active)
        return y[: 3 * n].reshape(n, 3), y[3 * n : 6 * n].reshape(n, 3)

    def modes(self, y):
        """(q, q') of the modal plate from a state vector (or states (..., len)); None on the
        rigid plate."""
        if self.plate is None:
            return None
        off, m = 6 * len(self.active), self.plate.n_modes
        return y[..., off : off + m], y[..., off + m : off + 2 * m]

    @staticmethod
    def join(x, v, modes):
        """The state vector of positions, velocities (n, 3) and the modes (or None)."""
        parts = [x.ravel(), v.ravel()] + ([] if modes is None else list(modes))
        return np.concatenate(parts)

    def local(self):
        loc = np.full(len(self.balls), -1)
        loc[self.active] = np.arange(len(self.active))
        return loc

    def index(self, pairs) -> "_PairIndex":
        """Local ball indices and radius sums of ``pairs`` (valid until a ball is dropped)."""
        loc = self.local()
        li = loc[[p.i for p in pairs]]
        lj = loc[[max(p.j, 0) for p in pairs]]
        is_plate = np.array([p.j < 0 for p in pairs], dtype=bool)
        frozen = None
        if self.plate is not None:
            frozen = np.full((len(pairs), self.plate.n_modes), np.nan)
            for k, p in enumerate(pairs):
                if p.phi0 is not None:
                    frozen[k] = p.phi0
        return _PairIndex(li, lj, is_plate, np.array([p.radius_sum for p in pairs]), frozen)

    def kinematics(self, pairs, x, v, modes=None):
        """Kinematics of ``pairs`` (a list or its ``index``) at positions/velocities x, v of
        shape (..., n, 3) (and modes (q, q'), each (..., m), on the modal plate); also returns
        the local indices and the plate flags."""
        if self.plate is not None:
            return self.modal_kinematics(pairs, x, v, modes)[:4]
        ix = pairs if isinstance(pairs, _PairIndex) else self.index(pairs)
        return self.rigid_kinematics(ix, x, v)[:4]

    @staticmethod
    def rigid_kinematics(ix, x, v):
        """``kinematics`` against the undeformed plate; also returns the balls i's centres
        and velocities (..., P, 3) and the radius sums (..., P)."""
        li, lj, is_plate = ix.li, ix.lj, ix.is_plate
        xi, vi = x[..., li, :], v[..., li, :]
        foot = plate_foot(xi.reshape(-1, 3)).reshape(xi.shape)
        xj = np.where(is_plate[:, None], foot, x[..., lj, :])
        vj = np.where(is_plate[:, None], 0.0, v[..., lj, :])
        rsum = np.broadcast_to(ix.radius_sum, xi.shape[:-1])
        kin = pair_kinematics(*(a.reshape(-1, 3) for a in (xi, vi, xj, vj)), rsum.reshape(-1))
        return kin, li, lj, is_plate, xi, vi, rsum

    def modal_kinematics(self, pairs, x, v, modes):
        """``kinematics`` on the modal plate (``ReferencePlate.contact_geometry``): plate
        pairs' penetration and rate against the deflected plate; also returns their slope
        (P', 2) and shapes (P', m), flattened over the leading axes as the kinematics."""
        ix = pairs if isinstance(pairs, _PairIndex) else self.index(pairs)
        kin, li, lj, is_plate, xi, vi, rsum = self.rigid_kinematics(ix, x, v)
        gap, rate, slope, phi = self.plate.contact_geometry(xi, vi, is_plate, ix.frozen_phi, modes)
        flat = np.broadcast_to(is_plate, rsum.shape).reshape(-1)
        kin = replace(
            kin,
            penetration=np.where(flat, (rsum + gap).reshape(-1), kin.penetration),
            rate=np.where(flat, rate.reshape(-1), kin.rate),
        )
        return kin, li, lj, is_plate, slope.reshape(-1, 2), phi.reshape(-1, self.plate.n_modes)

    # --- right-hand side ------------------------------------------------------------------
    def make_rhs(self):
        pairs = [p for p in self.pairs.values() if p.in_contact]
        laws = _law_table(pairs)
        ramp = np.array([p.ramp for p in pairs], dtype=bool)
        clamped = np.array([p.clamped for p in pairs], dtype=bool)
        m = self.mass[self.active]
        ix = self.index(pairs)
        if self.plate is not None:
            return self.make_modal_rhs(pairs, laws, ramp, clamped, m, ix)

        def rhs(t, y):
            x, v = self.split(y)
            acc = np.tile(self.g, (len(m), 1))
            if pairs:
                kin, li, lj, is_plate = self.kinematics(ix, x, v)
                f = impact_force_in_region(kin.penetration, kin.rate, laws, ramp, clamped)
                fn = f[:, None] * kin.normal
                np.add.at(acc, li, fn / m[li, None])
                ball = ~is_plate
                np.add.at(acc, lj[ball], -fn[ball] / m[lj[ball], None])
            return np.concatenate([v.ravel(), acc.ravel()])

        return rhs

    def make_modal_rhs(self, pairs, laws, ramp, clamped, m, ix):
        """The right-hand side with the modal plate: the contacts' generalised forces
        (``tailbeam.solvers.stream.reference.plate``) on the balls (normal and slope) and modes."""
        plate = self.plate

        # A DOP853 trial step far too long for a stiff contact can overflow in its stages;
        # the error estimate is then nan and DOP853 rejects the step and shrinks it (only
        # accepted steps are used), so those warnings are silenced here.
        def rhs(t, y):
            with np.errstate(over="ignore", invalid="ignore"):
                return _modal_rhs(t, y)

        def _modal_rhs(t, y):
            x, v = self.split(y)
            q, qd = self.modes(y)
            acc = np.tile(self.g, (len(m), 1))
            modal_force = np.zeros(plate.n_modes)
            if pairs:
                kin, li, lj, is_plate, slope, phi = self.modal_kinematics(ix, x, v, (q, qd))
                f = impact_force_in_region(kin.penetration, kin.rate, laws, ramp, clamped)
                fn = f[:, None] * kin.normal
                fn[:, :2] -= f[:, None] * slope  # zero slope for ball-ball pairs
                np.add.at(acc, li, fn / m[li, None])
                ball = ~is_plate
                np.add.at(acc, lj[ball], -fn[ball] / m[lj[ball], None])
                modal_force = -(f @ phi)
            qdd = plate.acceleration(q, qd, modal_force)
            return np.concatenate([v.ravel(), acc.ravel(), qd, qdd])

        return rhs


def _law_table(pairs) -> _Laws:
    return _Laws(*(np.array([getattr(p.law, a) for p in pairs], dtype=float)
                   for a in ("stiffness", "exponent", "damping", "penetration")))  # fmt: skip
