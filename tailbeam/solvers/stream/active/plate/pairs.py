"""The modal block of the active set's plate pairs: mode shapes, residual compliance, tails.

On the modal plate each plate pair (i, -1) carries the mode shapes (1/sqrt(kg)) at the point
of its contact (``shapes.ShapeCache``), fixed while it touches and refreshed at its ball's
position while it does not (where the change cannot close its gap). It also carries either
the residual compliance (m/N) of the truncated modes at that point
(``StreamPlate.compliance``, set when its contact starts or it is put at rest: the force is 0
then, so nothing jumps) or, with a contact tail (``tailbeam.plate.contact_tail``), the tail's
oscillators (``tails.Tails``) and the spring of the modes above its band. All of it is kept
by pair key across rebuilds of the set; ``block`` gives the modal inputs of a rebuilt set.
"""

import numpy as np

from tailbeam.physics.contact_patch import load_radius
from tailbeam.solvers.stream.active.compiled.pairs import L_CRES
from tailbeam.solvers.stream.active.plate.rest import static_height
from tailbeam.solvers.stream.active.plate.shapes import ShapeCache
from tailbeam.solvers.stream.active.plate.tails import Tails


class PlatePairs:
    """Shapes, compliance and tails of the plate pairs, by key, across rebuilds.

    Parameters
    ----------
    plate : StreamPlate
        The two-way modal plate.
    balls : Balls
        The stream's balls (their particles and plate laws give the load radius).
    rtol : float
        The set's relative tolerance (its modal tolerances follow from it).
    dead_loads : callable
        () -> (xy (p, 2) m, weights (p,) N) of the balls resting on the plate outside the set.
    """

    def __init__(self, plate, balls, rtol, dead_loads):
        self.plate, self.balls, self.rtol = plate, balls, rtol
        self.dead_loads = dead_loads
        self.cache = ShapeCache(plate)
        self.tails = Tails()
        self.points = {}  # plate pair key -> the point (x, y) m of its mode shapes
        self.load_radii = {}  # ball -> radius (m) of its load model (contact_patch)
        self.kept_phi = {}  # plate pair key -> its mode shapes in the last built set
        self.kept_cres = {}  # plate pair key -> its compliance (m/N) in the last built set
        self.grads = {}  # plate pair key -> (point, its shapes' gradients) (with friction)

    def save(self, s, index) -> None:
        """Keep the shapes, compliance and tail states of the plate pairs of ``s`` (the built
        ``ActiveSet``; ``index``: pair key -> its pair)."""
        n = self.plate.n_modes
        self.kept_phi = {k: s.model.phi[p, :n].copy() for k, p in index.items() if k[1] < 0}
        self.tails.save(s.q, s.qd)
        self.kept_cres = {k: s.model.law[p, L_CRES] for k, p in index.items() if k[1] < 0}
        self.points = {k: xy for k, xy in self.points.items() if k in self.kept_phi}

    def block(self, members, keys, x, quiet, now) -> dict:
        """The modal inputs of a set rebuilt at ``now`` (s), as ``ActiveSet`` takes them.

        The plate's state now, the mode shapes under each member (rows of ball-ball pairs
        stay 0), the dead loads of the resting non-members, the tails. Resting members
        (``quiet``) sit at their static penetration on the deflected plate: their heights in
        ``x`` (ball -> position (3,) m, the members' states) are set here.
        """
        plate = self.plate
        plate.propagate(now)
        plate.set_dead_loads(*self.dead_loads())
        new = [i for i in members if (i, -1) not in self.kept_phi]
        new_phi, new_xy = self.cache.shapes(new, [x[i][:2] for i in new])
        shapes = dict(zip(new, new_phi, strict=True))
        self.points.update({(i, -1): new_xy[k] for k, i in enumerate(new)})
        phi = np.zeros((len(keys), plate.n_modes))
        cres = np.zeros(len(keys))
        for q, i in enumerate(members):  # the plate pairs come first, in member order
            key = (i, -1)
            if key in self.kept_phi:
                phi[q], cres[q] = self.kept_phi[key], self.kept_cres[key]
            else:
                phi[q], cres[q] = shapes[i], 0.0
            if i in quiet:
                cres[q] = self.compliance(key)
                x[i][2] = static_height(self.balls, i, cres[q]) + phi[q] @ plate.q
        atol_x = self.rtol * 1e-3
        scale = float(np.max(plate.phi_max))
        block = self.tails.block(plate, phi, keys.index)
        return dict(**block, atol_q=atol_x / scale, atol_qd=self.rtol / scale, compliance=cres)

    def refresh(self, s, free, index) -> list:
        """New mode shapes for the plate pairs not touching, at their balls' positions now.

        Only where the change of the plate under the ball cannot close its gap (a ball just
        off the plate keeps its shapes: no start or end out of nothing); the change includes
        the deflection of the tail of its last contact, dropped with them.

        Parameters
        ----------
        s : ActiveSet
            The built set (its shapes and compliance are changed in place).
        free : list of tuple
            (local index, ball) of the members whose plate pair does not touch.
        index : dict
            Pair key -> its pair in ``s``.

        Returns
        -------
        list of tuple
            The keys of the pairs given new shapes (their tails are to be dropped).
        """
        shapes, points = self.cache.shapes([i for _, i in free], [s.x[q, :2] for q, _ in free])
        moved, phi = [], s.model.phi
        for (_, i), shape, xy in zip(free, shapes, points, strict=True):
            p = index[(i, -1)]
            gap = -s.penetration(p)[0]
            n = len(shape)
            if gap > abs((shape - phi[p, :n]) @ s.q[:n] - phi[p, n:] @ s.q[n:]) + 1e-9:
                s.model.set_phi(p, np.concatenate([shape, np.zeros(phi.shape[1] - n)]))
                s.model.set_compliance(p, 0.0)  # (set when its contact starts)
                self.points[(i, -1)] = xy
                moved.append((i, -1))
        return moved

    def gradient(self, key) -> np.ndarray:
        """Gradients (m, 2) 1/(m sqrt(kg)) of the plate's mode shapes at the point of plate
        pair ``key``'s shapes (``StreamPlate.gradients``; kept while the point is)."""
        point = tuple(self.points[key])
        kept = self.grads.get(key)
        if kept is None or kept[0] != point:
            kept = self.grads[key] = (point, self.plate.gradients([point])[0])
        return kept[1]

    def deflection(self, s, p: int) -> tuple[float, float]:
        """Deflection (m) and its rate (m/s) of the plate's modes under plate pair p of ``s``
        (an ``ActiveSet``; the tails' oscillators excluded)."""
        n = self.plate.n_modes
        phi = s.model.phi
        return phi[p, :n] @ s.q[:n], phi[p, :n] @ s.qd[:n]

    def compliance(self, key) -> float:
        """Residual compliance (m/N) of plate pair ``key`` at the point of its mode shapes."""
        i = key[0]
        return float(self.plate.compliance([self.points[key]], [self.load_radius(i)])[0])

    def load_radius(self, i: int) -> float:
        """Radius (m) of the disc ball i's force is spread over in the residual compliance
        (``tailbeam.physics.contact_patch``: 0 on a Kirchhoff basis, the Hertz radius on a
        Mindlin one)."""
        if i not in self.load_radii:
            b = self.balls
            self.load_radii[i] = load_radius(self.plate.basis.theory, b.particles[i].ball(),
                                             b.plate_law(i), float(-b.g[2]))  # fmt: skip
        return self.load_radii[i]

    def new_tail(self, key):
        """The contact tail (``TailModes``) of plate pair ``key`` at the point of its shapes,
        or None (no tail there, or one without oscillators)."""
        tail = self.plate.tail_at(self.points[key], self.load_radius(key[0]))
        if tail is None or not len(tail.nu):
            return None
        return tail

    def add_tail(self, key, tail) -> None:
        """Plate pair ``key`` gets the oscillators of ``tail``, at rest, and its compliance."""
        self.kept_cres[key] = tail.compliance
        self.tails.add(key, tail)
