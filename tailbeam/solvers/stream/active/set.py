"""The compiled active-set integrator of the fast stream solver: Python wrapper.

The fast stream solver's driver advances balls in free flight in closed form and hands the
"active set" (balls in contact plus nearby flying balls, and the pairs to watch) to
``ActiveSet.advance``, which integrates them with a compiled DOP853 (8th order, dense output;
``kernel``) until the first structural event or ``t_stop``:

* returns at contact START / END (pair index), LEAVE (ball, edge in
  ``tailbeam.physics.incline.EDGES`` order), SETTLE (ball: ``EventCode.REST``), or ``t_stop``
  (``EventCode.NONE``);
* handles inside (and logs) the kinks of the IMPACT law: penetration = d (when c > 0) and
  clamp on/off; no accepted step straddles a kink;
* all events are located on the dense output: squared distances, plate gaps and edge
  distances are polynomials of degree <= 14 on a step, certified positive by their
  Chebyshev coefficients or searched for their first crossing
  (``tailbeam.solvers.numerics.chebyshev``), so a grazing approach and retreat inside one step
  is not missed;
* the rows whose events were applied at the time t a call returns at are carried into the
  next call from t (``fresh_rows``, ``set_fresh``): one found crossing again right at t
  while back on its side just after is searched again (``kernel.advance``);
* SETTLE is checked at accepted step ends only: a ball whose only touching pair is the plate
  and whose normal excess energy over the static state (``pairs.settle_excess``)
  falls below its settle energy;
* a growing buffer of plate force rows (t, pair, F): every accepted step end, ``nodes_per_step``
  equally spaced interior points of each step (dense output), contact start and end (the end
  row repeats the time of the last step end); and a log of the kinks (t, ``EventCode``,
  pair).

Optional modal plate (two-way): m mass-normalised modes (omega, zeta), state q, q' after the
balls; each plate pair has the mode shapes phi (m,) at its contact point (fixed per contact,
given by the caller); the plate under the ball deflects by w = phi . q, the penetration is
r - (z - w), the ball's force F (+z) loads the modes with -phi F; constant dead loads f_dead
(m,) on the modes. The plate gap z - w is still a polynomial on a step, so events are located
as on the rigid plate. Residual flexibility (optional): each plate pair may have the static
compliance C (m/N) of the truncated modes at its contact point in series with the contact
(``compliance``, ``set_compliance``; ``pairs.plate_force_with_residual``). Without
modes (and C = 0) every result is bit-for-bit the rigid plate's.

Everything in the plate frame (x downhill, z the plate normal, surface z = 0), SI units.
Cost per step: O(balls + pairs watched). The first call compiles the kernel (cached on disk).
"""

import math
from dataclasses import dataclass

import numpy as np

from tailbeam.errors import InputError, WorkLimitError
from tailbeam.physics.contact_law import LAW_COLUMNS, LAW_E, LAW_K, law_table
from tailbeam.physics.contacts import PLATE, ContactTable, LawOptions
from tailbeam.results.records import EventCode
from tailbeam.solvers.numerics.chebyshev import tables as cheb_tables
from tailbeam.solvers.numerics.dop853 import dop853_tables
from tailbeam.solvers.stream.active import kernel as ak
from tailbeam.solvers.stream.active.modal_block import ModalBlock
from tailbeam.solvers.stream.active.pairs import (
    L_CRES,
    R_EDGE,
    clamp_indicator,
    pair_state,
    plate_contact_energy,
)

DEFAULT_NODES = 40  # interior force rows per step: linear interpolation < 1e-5 of the peak


@dataclass(frozen=True)
class Outcome:
    """Why ``ActiveSet.advance`` returned.

    Attributes
    ----------
    code : EventCode
        The event it stopped at: ``CONTACT_START``, ``CONTACT_END``, ``LEAVE``, ``REST`` (a
        ball's plate contact settled: SETTLE), or ``NONE`` (t_stop reached).
    t : float
        Time reached (s).
    index : int
        The pair (start, end) or the ball (leave, settle); -1 at t_stop.
    edge : int
        Leave: the edge passed, 0..3 in ``tailbeam.physics.incline.EDGES`` order; else -1.
    """

    code: EventCode
    t: float
    index: int = -1
    edge: int = -1


def pair_laws(balls, pairs, plate_material, **options):
    """Laws of ``pairs`` ((i, j), j = -1 the plate) of ``balls`` (tailbeam.Ball): their rows
    of the balls' contact table (``tailbeam.physics.contacts``) with the IMPACT ``options``
    (exponent, damping, penetration, clamp)."""
    table = ContactTable.from_settings(balls, plate_material, LawOptions(**options))
    return [table.law(i, PLATE if j < 0 else j) for i, j in pairs]


class ActiveSet:
    """n balls and P watched pairs, advanced by the compiled kernel.

    x, v: (n, 3) positions (m) and velocities (m/s), views of the state (in/out); mass (n,) kg;
    radius (n,) m; pairs: (P, 2) ball indices (j = -1: the plate); laws: P ``ImpactLaw``s (or a
    (P, LAW_COLUMNS) ``law_table``; kept with the compliance in column L_CRES); gravity (3,)
    m/s^2 in the plate frame; half_sizes (a/2, b/2) m; settle_energy (n,) J (0 = never); rtol;
    atol_x (m), atol_v (m/s) (default rtol x 1 mm, rtol x 1 m/s, as the reference); max_steps
    per ``advance`` call; nodes_per_step: interior force rows per step. Modal plate (optional,
    all m modes): omega (m,) rad/s, zeta (m,), q, qd (m,) initial modal state (m sqrt(kg), m
    sqrt(kg)/s; default 0), phi (P, m) mode shapes at each pair's contact point in 1/sqrt(kg)
    (rows of ball-ball pairs ignored; ``set_phi`` changes a row for a new contact), f_dead (m,)
    constant modal forces in N/sqrt(kg) (balls resting quasi-statically elsewhere); atol_q,
    atol_qd (default atol_x / s, atol_v / s with s = max |phi| at construction, so that the
    deflection under a ball is held to about atol_x; pass them when phi is only set later);
    compliance (P,) m/N: the residual compliance of each plate pair (default 0; entries of
    ball-ball pairs ignored). ``q``, ``qd``: views of the modal state (in/out). Per-pair state
    (in/out): touching, ramp, clamped, peak (N), t_peak (s), pen (m, max penetration). ``alive``
    (n,): balls still integrated (False after a leave).

    For the driver: pairs overlapping at construction start touching (``open_overlapping``,
    region from the state, accumulators reset): overwrite the per-pair arrays to carry a
    contact over from another set. After a START the next call's first step is the small
    start-up step (``self.h``; pass it on as ``h`` if the set is rebuilt). START/END leave
    the pair's accumulators (peak, t_peak, pen) for the caller to read. After a LEAVE call
    ``remove_ball``.
    """

    def __init__(self, x, v, mass, radius, pairs, laws, gravity, half_sizes, *,
                 settle_energy=None, rtol=1e-10, atol_x=None, atol_v=None, max_steps=100_000,
                 nodes_per_step=DEFAULT_NODES, row_capacity=4096, log_capacity=256,
                 omega=None, zeta=None, q=None, qd=None, phi=None, f_dead=None, atol_q=None,
                 atol_qd=None, compliance=None):  # fmt: skip
        x = np.asarray(x, dtype=float).reshape(-1, 3)
        n = x.shape[0]
        npairs = np.asarray(pairs).reshape(-1, 2).shape[0]
        modal = ModalBlock.build(npairs, omega, zeta, q, qd, phi, f_dead)
        nm = modal.omega.shape[0]
        self.omega, self.zeta = modal.omega, modal.zeta
        self.phi, self.f_dead = modal.phi, modal.f_dead
        self.y = np.concatenate(
            [x.ravel(), np.asarray(v, dtype=float).reshape(n, 3).ravel(), modal.q, modal.qd]
        )
        self.x = self.y[: 3 * n].reshape(n, 3)
        self.v = self.y[3 * n : 6 * n].reshape(n, 3)
        self.q = self.y[6 * n : 6 * n + nm]
        self.qd = self.y[6 * n + nm :]
        self.mass = np.asarray(mass, dtype=float).reshape(n).copy()
        self.radius = np.asarray(radius, dtype=float).reshape(n).copy()
        pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
        self.pi, self.pj = pairs[:, 0].copy(), pairs[:, 1].copy()
        if not isinstance(laws, np.ndarray):
            laws = law_table(laws)
        self.law = _with_compliance(laws, self.pj, compliance)
        _check(n, self.pi, self.pj, self.law, rtol, nodes_per_step, max_steps)
        _check_positive("mass", self.mass)
        _check_positive("radius", self.radius)
        self.rsum = self.radius[self.pi] + np.where(self.pj >= 0, self.radius[self.pj], 0.0)
        self.g = np.asarray(gravity, dtype=float).reshape(3).copy()
        self.half = np.asarray(half_sizes, dtype=float).reshape(2).copy()
        _check_positive("half_sizes", self.half)
        settle = np.zeros(n) if settle_energy is None else settle_energy
        self.settle_energy = np.asarray(settle, dtype=float).reshape(n).copy()
        if not np.all(self.settle_energy >= 0.0):
            raise InputError("settle_energy", "must be >= 0 J for every ball (0 = never)")
        self.alive = np.ones(n, dtype=bool)
        p = len(self.pi)
        self.touching = np.zeros(p, dtype=bool)
        self.ramp = np.ones(p, dtype=bool)
        self.clamped = np.zeros(p, dtype=bool)
        self.peak = np.zeros(p)
        self.t_peak = np.full(p, math.nan)
        self.pen = np.zeros(p)
        self.rtol = float(rtol)
        self.atol_x = rtol * 1e-3 if atol_x is None else float(atol_x)
        self.atol_v = rtol * 1.0 if atol_v is None else float(atol_v)
        scale = float(np.max(np.abs(self.phi))) if self.phi.size else 1.0
        scale = scale if scale > 0.0 else 1.0
        atol_q = self.atol_x / scale if atol_q is None else float(atol_q)
        atol_qd = self.atol_v / scale if atol_qd is None else float(atol_qd)
        self.atol = np.concatenate([np.full(3 * n, self.atol_x), np.full(3 * n, self.atol_v),
                                    np.full(nm, atol_q), np.full(nm, atol_qd)])  # fmt: skip
        self.max_steps, self.nodes = int(max_steps), int(nodes_per_step)
        self.tab = dop853_tables()
        self.tab = (self.tab[0], self.tab[1], self.tab[3], self.tab[4], self.tab[5])
        self.pts, self.vinv = cheb_tables()
        self.rows = np.zeros((int(row_capacity), 3))
        self.log = np.zeros((int(log_capacity), 3))
        self.iout = np.zeros(ak.IO_SIZE, dtype=np.int64)
        self.fresh = np.zeros((ak.MAX_FRESH, 2), dtype=np.int64)
        self.t_fresh = math.nan  # the time the rows in fresh were applied at
        self.h = 0.0
        self.open_overlapping()

    @classmethod
    def from_balls(cls, balls, pairs, incline, *, damping=0.0, penetration=1e-4, clamp=True,
                   exponent=1.5, **kwargs):  # fmt: skip
        """From ``tailbeam.Ball``s (plate-frame positions, velocities) on an ``InclinedPlate``;
        laws from ``contact_law`` with the given IMPACT parameters."""
        options = dict(damping=damping, penetration=penetration, clamp=clamp, exponent=exponent)
        laws = pair_laws(balls, pairs, incline.plate.material, **options)
        return cls(
            [b.position for b in balls], [b.velocity for b in balls],
            [b.mass for b in balls], [b.radius for b in balls], pairs, laws,
            incline.gravity_vector, incline.half_sizes, **kwargs,
        )  # fmt: skip

    # --- state -----------------------------------------------------------------------------
    def model(self):
        return (self.mass, self.radius, self.g, self.half, self.pi, self.pj, self.law,
                self.rsum, self.settle_energy, self.alive, self.omega, self.zeta, self.phi,
                self.f_dead)  # fmt: skip

    def set_phi(self, p: int, shape):
        """Mode shapes (m,) 1/sqrt(kg) at plate pair p's new contact point (before it touches)."""
        self.phi[p] = np.asarray(shape, dtype=float).reshape(self.phi.shape[1])

    def set_compliance(self, p: int, compliance: float):
        """Residual compliance (m/N) at plate pair p's new contact point (before it touches)."""
        self.law[p, L_CRES] = _compliance_value(compliance)

    def contact_energy(self, p: int) -> float:
        """Elastic energy (J) of pair p now (0 when not touching; a plate pair's includes its
        residual spring's C F^2 / 2)."""
        if not self.touching[p]:
            return 0.0
        delta, _ = self.penetration(p)
        k, e, cres = self.law[p, LAW_K], self.law[p, LAW_E], self.law[p, L_CRES]
        return float(plate_contact_energy(delta, k, e, cres if self.pj[p] < 0 else 0.0))

    def modal_energy(self) -> float:
        """Kinetic + strain energy of the modes now, J: 1/2 (q'^2 + omega^2 q^2) summed."""
        return float(0.5 * np.sum(self.qd**2 + (self.omega * self.q) ** 2))

    def pstate(self):
        return (self.touching, self.ramp, self.clamped, self.peak, self.t_peak, self.pen)

    def penetration(self, p: int) -> tuple[float, float]:
        """(delta m, rate m/s) of pair p now."""
        d, rate, _, _, _ = pair_state(self.y, len(self.mass), self.pi[p], self.pj[p],
                                      self.rsum[p], self.phi, p)  # fmt: skip
        return float(d), float(rate)

    def open_overlapping(self):
        """Pairs overlapping now start touching, in their region (a ball placed at its static
        penetration), as ``tailbeam.solvers.stream.reference``'s ``touch``."""
        for p in range(len(self.pi)):
            if self.touching[p] or not self.alive[self.pi[p]]:
                continue
            delta, rate = self.penetration(p)
            if delta <= 0.0:
                continue
            k, e, c, d, clamp = self.law[p, :LAW_COLUMNS]  # (LAW_K ... LAW_CLAMP)
            self.touching[p] = True
            self.ramp[p] = delta < d or c <= 0.0
            ind = clamp_indicator(delta, rate, k, e, c, d, self.ramp[p])
            self.clamped[p] = bool(clamp > 0 and c > 0 and ind < 0.0)
            self.peak[p], self.t_peak[p], self.pen[p] = 0.0, math.nan, delta

    def remove_ball(self, b: int):
        """Stop integrating ball b (after a leave): its touching pairs end."""
        self.alive[b] = False
        self.touching[(self.pi == b) | (self.pj == b)] = False
        for p in np.flatnonzero((self.pi == b) | (self.pj == b)):
            self.forget_fresh(int(p))

    # --- the events just applied (carried to the next call at the same time) ----------------
    def fresh_rows(self) -> tuple[float, list]:
        """(t s, [(kind, index)]): the rows whose events were applied at the time t the last
        ``advance`` returned at (kind ``pairs.R_CONTACT``, ``R_FULL``, ``R_CLAMP``:
        index a pair; ``R_EDGE``: index 4 ball + edge). The next call from t does not find
        them again at t (``kernel.advance``)."""
        n = int(self.iout[ak.IO_FRESH])
        return self.t_fresh, [(int(k), int(i)) for k, i in self.fresh[:n]]

    def set_fresh(self, t: float, rows):
        """Rows (kind, index) whose events were applied at time t (s), as ``fresh_rows``
        gives them: a set rebuilt at t carries those of the set it replaces."""
        rows = list(rows)[: ak.MAX_FRESH]
        for q, (k, i) in enumerate(rows):
            self.fresh[q] = k, i
        self.iout[ak.IO_FRESH] = len(rows)
        self.t_fresh = float(t)

    def forget_fresh(self, p: int):
        """Pair p's state was changed by the caller: its rows are no longer fresh."""
        t, rows = self.fresh_rows()
        kept = [(k, i) for k, i in rows if k == R_EDGE or i != p]
        if len(kept) < len(rows):
            self.set_fresh(t, kept)

    # --- integration -----------------------------------------------------------------------
    def advance(self, t0: float, t_stop: float, h: float | None = None) -> Outcome:
        """Integrate from t0 until the first returning event or t_stop; see the module
        docstring. h: first step (s; default: the step suggested by the previous call, or
        1e-5 s). Grows the force-row and log buffers as needed. A call that starts at the
        time the previous one returned at carries the rows whose events were applied then
        (``fresh_rows``): one whose crossing sits on 0 there is not applied again at once
        (``kernel.advance``)."""
        tio = np.array([float(t0), float(h or self.h or 1e-5)])
        if tio[0] != self.t_fresh:
            self.iout[ak.IO_FRESH] = 0
        while True:
            self.iout[ak.IO_STATUS] = -1
            ak.advance(
                tio, self.y, float(t_stop), self.rtol, self.atol, self.max_steps, self.nodes,
                self.model(), self.pstate(), self.tab, self.pts, self.vinv, self.rows, self.log,
                self.iout, self.fresh,
            )  # fmt: skip
            status = int(self.iout[ak.IO_STATUS])
            if status != ak.ST_BUFFER:
                break
            self._grow()
        self.h = float(tio[1])
        self.t_fresh = float(tio[0])
        if status == ak.ST_STEP_LIMIT:
            raise WorkLimitError(
                f"active set: more than max_steps={self.max_steps} steps in one advance by "
                f"t = {tio[0]:.6g} s; raise max_steps or hand smaller sets/intervals"
            )
        if status == ak.ST_STEP_TINY:
            raise RuntimeError(f"active set: step size underflow at t = {tio[0]:.17g} s")
        code = EventCode(status)
        index = int(self.iout[ak.IO_INDEX]) if code != EventCode.NONE else -1
        edge = int(self.iout[ak.IO_EDGE]) if code == EventCode.LEAVE else -1
        return Outcome(code, float(tio[0]), index, edge)

    def _grow(self):
        if self.iout[ak.IO_ROWS] + 4 * (self.nodes + 1) * len(self.pi) > self.rows.shape[0] // 2:
            rows = np.zeros((2 * self.rows.shape[0] + 4 * (self.nodes + 1) * len(self.pi), 3))
            rows[: self.rows.shape[0]] = self.rows
            self.rows = rows
        if self.iout[ak.IO_LOG] + 2 > self.log.shape[0] // 2:
            log = np.zeros((2 * self.log.shape[0] + 4, 3))
            log[: self.log.shape[0]] = self.log
            self.log = log

    # --- outputs ---------------------------------------------------------------------------
    def force_rows(self) -> np.ndarray:
        """(R, 3) rows (t s, pair, F N) of the plate forces written so far."""
        return self.rows[: self.iout[ak.IO_ROWS]]

    def kink_log(self) -> list:
        """(t s, ``EventKind``, pair) of the kinks handled inside so far."""
        out = self.log[: self.iout[ak.IO_LOG]]
        return [(float(t), EventCode(int(k)).kind, int(p)) for t, k, p in out]

    def clear_outputs(self):
        """Forget the force rows and the kink log (the caller has consumed them)."""
        self.iout[ak.IO_ROWS] = 0
        self.iout[ak.IO_LOG] = 0

    @property
    def stats(self) -> dict:
        """Accepted steps, attempted steps, right-hand-side evaluations and events found
        again at the instant they were applied (searched again: ``kernel.advance``)."""
        return {"steps": int(self.iout[ak.IO_STEPS]), "attempts": int(self.iout[ak.IO_ATTEMPTS]),
                "nfev": int(self.iout[ak.IO_NFEV]),
                "found_again": int(self.iout[ak.IO_AGAIN])}  # fmt: skip


def _with_compliance(laws, pj, compliance) -> np.ndarray:
    """(P, L_CRES + 1) law table: a (P, LAW_COLUMNS) ``law_table`` and the residual
    compliance of each plate pair (m/N; 0 for ball-ball pairs and when ``compliance`` is None)."""
    laws = np.asarray(laws, dtype=float)
    laws = laws if laws.ndim == 2 else laws.reshape(-1, LAW_COLUMNS)
    if laws.shape[0] != len(pj):
        raise InputError("laws", f"one law per pair: got {len(laws)} laws for {len(pj)} pairs")
    laws = laws[:, :LAW_COLUMNS]
    cres = np.zeros(len(pj)) if compliance is None else np.asarray(compliance, dtype=float)
    if cres.shape != (len(pj),) or not np.all(np.isfinite(cres)) or np.any(cres < 0.0):
        raise InputError("compliance", f"must be {len(pj)} finite values >= 0 m/N (one per pair)")
    return np.ascontiguousarray(np.column_stack([laws, np.where(pj < 0, cres, 0.0)]))


def _compliance_value(value) -> float:
    value = float(value)
    if not (math.isfinite(value) and value >= 0.0):
        raise InputError("compliance", f"must be finite and >= 0 m/N, got {value!r}")
    return value


def _check_positive(name, values):
    if not np.all(np.isfinite(values)) or not np.all(values > 0.0):
        raise InputError(name, f"must be finite and > 0, got {values.tolist()!r}")


def _check(n, pi, pj, law, rtol, nodes, max_steps):
    """InputError naming the argument that breaks its rule."""
    if not 1e-14 <= rtol <= 1e-3:
        raise InputError("rtol", f"must lie in [1e-14, 1e-3], got {rtol!r}")
    if nodes < 0:
        raise InputError("nodes_per_step", f"must be >= 0, got {nodes!r}")
    if max_steps < 1:
        raise InputError("max_steps", f"must be >= 1, got {max_steps!r}")
    if len(law) != len(pi):
        raise InputError("laws", f"one law per pair: got {len(law)} laws for {len(pi)} pairs")
    if np.any(pi < 0) or np.any(pi >= n) or np.any(pj >= n) or np.any(pj < -1):
        raise InputError("pairs", f"ball indices must lie in [0, {n}) (j = -1: the plate)")
    if np.any(pi == pj):
        raise InputError("pairs", "a ball cannot pair with itself")
