"""Slow, independent reference for streams: all balls and the inclined plate together, the
plate rigid or modal (two-way, ``plate=ReferencePlate(...)``, see below).

One ODE for every ball (3-D translation, frictionless, normal forces only, no rotation),
integrated by scipy's DOP853 (the method of ``solve_ivp(method="DOP853")``, driven step by
step through its ``OdeSolver`` class so that every step can be checked for contacts; rtol
1e-12 by default). Every pair is watched (O(N^2): this is the slow reference):

* ball-ball and ball-plate contacts use the IMPACT law of ``tailbeam.physics.contact_law``
  (``ball_ball_law``: R = R1 R2 / (R1 + R2), E* of both materials; ``ball_plate_law``), the
  pair geometry of ``tailbeam.physics.pair`` and the plate frame of
  ``tailbeam.physics.incline`` (gravity g (sin theta, 0, -cos theta));
* events at every kink: contact start and end of every pair, penetration = d (STEP kink,
  when c > 0), clamp on/off (when c > 0 and the clamp is on), and a ball's centre passing an
  edge of the plate (the ball leaves and is dropped). Inside a region each pair's force is
  that region's smooth formula; a step in which an event is found is discarded and redone
  to end exactly at the event, where the integration restarts with the new region, so no
  accepted step straddles a kink.

Event search (``tailbeam.solvers.stream.step_events``). DOP853's dense output is a polynomial of
degree 7 in time on each step, so the squared distance of two centres (and the plate gap,
the edge distances) is a polynomial of degree <= 14 there, interpolated exactly at 15
Chebyshev points and certified or root-found: no contact is missed, however short the
step's approach and retreat. The clamp indicator (not polynomial) is sampled at the 15 points
and bracketed with ``brentq``. A redone step is checked again (a root placed by a step that
straddled the kink can be late). Each event fires when its function passes a dead band
beyond zero (see ``_Reference.rows``), against round-off chatter at grazing contacts.
Peak force and maximum penetration: the maximum of their Chebyshev interpolant on each
step. Balls may enter later (``release_times``).

Modal plate (``tailbeam.solvers.stream.reference_plate``: the model, exact or frozen mode shapes).
The state gains the modal coordinates [q | q'] after the balls (atol: deflections to rtol x
1 mm, rates to rtol x 1 m/s). A ball's plate rows use the gap z - w, w = phi(x, y) . q.
What is certified: with frozen shapes (a contact's) the rows are polynomials of degree
<= 14 on a step, as above. With exact shapes phi(x(s), y(s)) is not a polynomial; the 15
values are exact samples, and the certificate and the root search act on their
interpolant. Every step is bounded so that no ball moves sideways more than 1 / k_max
(k_max: the top mode's wavenumber; the step is redone shorter otherwise): along such a path
each shape's Chebyshev coefficients fall like (k L / 4)^n / n!, and the interpolant misses
the row only by products of them with the top coefficients of the dense output (~rtol):
an estimate (~1e-12 of the row's scale; measured 1.5e-14 of r^2), not a certificate. A
crossing found on the interpolant is applied only where the true row lies within its dead
band (else the step goes on and finds it again, closer), so no event is applied early; a
dip narrower than that estimate could be missed. The modes also bound the steps (at least
MODAL_STEPS_PER_PERIOD per period of the top mode: too long a run is refused at once).
"""

import math
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.integrate import DOP853
from scipy.optimize import brentq

from tailbeam.errors import InputError, WorkLimitError, require_positive
from tailbeam.physics.contact_law import (
    HERTZ_EXPONENT,
    ImpactLaw,
    ball_ball_law,
    ball_plate_law,
    clamp_indicator,
    elastic_energy,
    impact_force_in_region,
)
from tailbeam.physics.hertz import hertz_max_penetration
from tailbeam.physics.incline import EDGES, InclinedPlate
from tailbeam.physics.pair import pair_kinematics, plate_foot
from tailbeam.solvers.records import PLATE, Event, EventKind, Impact, LeaveEvent
from tailbeam.solvers.stream.reference_plate import ReferencePlate
from tailbeam.solvers.stream.step_events import (
    STEP_POINTS,
    certified_positive,
    chebyshev_coefficients,
    first_downward_crossing,
    interpolant_max,
)

SAME_TIME = 1e-9  # events closer than this (fraction of a step) are simultaneous
MODAL_STEPS_PER_PERIOD = 5  # a lower bound of the steps per period of the top mode


@dataclass
class _Pair:
    """A watched pair: ball i and ball j (j = -1: the plate), its law and region flags."""

    i: int
    j: int
    law: ImpactLaw
    radius_sum: float
    in_contact: bool = False
    ramp: bool = True
    clamped: bool = False
    records: list = field(default_factory=list)
    peak: float = 0.0
    t_peak: float = math.nan
    pen: float = 0.0
    phi0: np.ndarray | None = None  # shapes kept by a frozen plate contact (modal plate)

    @property
    def kinked(self) -> bool:
        """Whether the law has a STEP kink at delta = d (it does only with damping)."""
        return self.law.damping > 0.0


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


@dataclass
class StreamReferenceResult:
    """Contacts (one ``Impact`` per ball per contact), leave events, the event log
    (``Event`` records in time order), and per accepted step: times, total energy (J) and states
    (names of the balls present, positions (n, 3) m, velocities (n, 3) m/s)."""

    names: tuple
    masses: np.ndarray
    contacts: list
    leaves: list
    events: list
    times: np.ndarray
    energy: np.ndarray
    states: list
    steps: int
    info: dict
    plate_states: list = field(default_factory=list)  # (q, q') per step (modal plate)

    def contacts_of(self, ball: str) -> list:
        return [c for c in self.contacts if c.ball == ball]


def simulate_stream_reference(
    balls,
    incline: InclinedPlate,
    duration: float,
    *,
    damping: float = 0.0,
    penetration: float = 1e-4,
    clamp: bool = True,
    exponent: float = HERTZ_EXPONENT,
    rtol: float = 1e-12,
    max_steps: int = 200_000,
    release_times=None,
    progress=None,
    plate: ReferencePlate | None = None,
) -> StreamReferenceResult:
    """Integrate ``balls`` (``tailbeam.Ball``, positions and velocities in the plate frame)
    on ``incline`` for ``duration`` s; see the module docstring.

    damping c (N s/m), penetration d (m), clamp, exponent e: the IMPACT parameters of every
    pair (stiffness from Hertz). rtol: DOP853's relative tolerance (atol = rtol x 1 mm on
    positions, rtol x 1 m/s on velocities). max_steps bounds the work (WorkLimitError).
    release_times (s, one per ball, default all 0): a ball enters the scene at its time, at
    its given position and velocity (event ``release``; the energy series jumps there).
    progress: optional callable, called with the time (s) reached after every accepted step.
    plate: a ``ReferencePlate`` (the modal plate, two-way,
    ``tailbeam.solvers.stream.reference_plate``) or None (the rigid plate).
    """
    duration = require_positive("duration", duration)
    if not 1e-14 <= rtol <= 1e-3:
        raise InputError("rtol", f"must lie in [1e-14, 1e-3], got {rtol!r}")
    options = dict(exponent=exponent, damping=damping, penetration=penetration, clamp=clamp)
    balls = list(balls)
    release = _release_times(release_times, len(balls))
    if plate is not None:
        if not isinstance(plate, ReferencePlate):
            raise InputError("plate", "must be a ReferencePlate (a modal basis and its damping)")
        plate.check_size(incline)
        _check_modal_work(plate, duration, max_steps)
    sim = _Reference(balls, incline, options, rtol, max_steps, release, plate)
    sim.progress = progress
    return sim.run(duration)


class _Reference:
    def __init__(self, balls, incline, options, rtol, max_steps, release, plate=None):
        _check_balls(balls, incline)
        self.plate, self.h_cap = plate, math.inf
        self.trial_errors = {} if plate is None else dict(over="ignore", invalid="ignore")
        self.balls, self.incline, self.rtol, self.max_steps = balls, incline, rtol, max_steps
        self.g = incline.gravity_vector
        self.mass = np.array([b.mass for b in balls])
        self.options = options
        self.active = [i for i in range(len(balls)) if release[i] <= 0.0]
        self.waiting = sorted((float(release[i]), i) for i in range(len(balls)) if release[i] > 0)
        self.pairs = {}
        for i in self.active:
            self.add_pairs(i)
        self.contacts, self.leaves, self.events = [], [], []
        self.times, self.energy, self.states, self.plate_states = [], [], [], []
        self.steps = 0
        self.progress = None
        pos = np.array([balls[i].position for i in self.active], dtype=float).reshape(-1, 3)
        vel = np.array([balls[i].velocity for i in self.active], dtype=float).reshape(-1, 3)
        m = 0 if plate is None else plate.n_modes
        self.y = self.join(pos, vel, (np.zeros(m), np.zeros(m)) if m else None)
        self.t = 0.0
        self.touch(list(self.pairs.values()), 0.0)

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
        (``tailbeam.solvers.stream.reference_plate``) on the balls (normal and slope) and modes."""
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

    # --- main loop ------------------------------------------------------------------------
    def run(self, duration):
        fresh, pending, h0 = set(), None, None
        t_bound = self.next_stop(duration)
        solver = self.new_solver(self.t, self.y, t_bound, h0)
        self.record_step(self.t, self.y)
        while True:
            if solver.status == "finished":
                if pending is None and solver.t >= duration:
                    break
                if pending is None:  # a release time
                    fresh, h0 = set(), self.release_due(solver.t, solver.y)
                else:
                    fresh, h0 = self.finish_redo(pending[0], solver.t, solver.y)
                pending, t_bound = None, self.next_stop(duration)
                self.h_cap = math.inf
                solver = self.new_solver(self.t, self.y, t_bound, h0)
                continue
            t0, y0 = solver.t, solver.y.copy()
            with np.errstate(**self.trial_errors):  # (see make_modal_rhs)
                message = solver.step()
            if solver.status == "failed":
                raise RuntimeError(f"stream reference: DOP853 failed: {message}")
            self.steps += 1
            if self.steps > self.max_steps:
                raise WorkLimitError(
                    f"stream reference: more than max_steps={self.max_steps} steps by "
                    f"t = {t0:.6g} s; raise max_steps or shorten the duration"
                )
            dense, t1 = solver.dense_output(), solver.t
            if self.too_far(dense, t0, t1):  # modal plate: the step bound of the gap rows
                self.h_cap = 0.5 * (t1 - t0)
                solver = self.new_solver(t0, y0, t_bound, self.h_cap)
                continue
            found = self.detect(dense, t0, t1, fresh)
            if found is not None and pending and found[1] >= pending[1] - SAME_TIME * (t1 - t0):
                found = None  # (about) simultaneous with the pending event: taken after it
            if found is None:
                self.accept(dense, t0, t1)
                self.record_step(t1, solver.y)
                if self.progress is not None:
                    self.progress(t1)
                fresh = set() if t1 > t0 else fresh
                continue
            row, t_e = found
            if t_e <= t0 + 4.0 * np.spacing(t0):  # at the restart (to round-off): apply there
                h0 = self.apply(row[0], t0, y0)
                fresh = fresh | {row[0]}
                pending, t_bound = None, self.next_stop(duration)
            else:  # redo the step so that it ends exactly at the event
                self.t, self.y = t0, y0
                pending, t_bound, h0 = (row, t_e), t_e, t_e - t0
            solver = self.new_solver(self.t, self.y, t_bound, h0)
        self.finish()
        return self.result(duration)

    def finish_redo(self, row, t, y):
        """At the end of a redone step: apply the event if its row is within its dead band
        of the crossing; otherwise (the discarded step, which straddled the kink, placed the
        root early) go on from here: the next step finds it again, closer. Returns the
        fresh set and the next first step."""
        x, v = self.split(y)
        key, sign, _, band = row
        modes = self.modes(y[None])
        if sign * self.row_values([row], x[None], v[None], modes)[0, 0] <= band:
            return {key}, self.apply(key, t, y)
        self.t, self.y = t, y
        return set(), None

    def new_solver(self, t, y, t_bound, h0):
        self.t, self.y = t, y
        n = len(self.active)  # atol: rtol x 1 mm on positions, rtol x 1 m/s on velocities
        atol = self.rtol * np.concatenate([np.full(3 * n, 1e-3), np.ones(3 * n)])
        if self.plate is not None:
            atol = np.concatenate([atol, self.plate.atol(self.rtol)])
        if h0 is not None:
            h0 = min(h0, t_bound - t) if t_bound > t else None
        return DOP853(self.make_rhs(), t, y, t_bound, rtol=self.rtol, atol=atol, first_step=h0,
                      max_step=self.h_cap)  # fmt: skip

    def too_far(self, dense, t0, t1) -> bool:
        """Modal plate: whether a ball moved more than 1 / k_max sideways on the step (k_max:
        the top mode's wavenumber). Below it the mode shapes along the path are so smooth that
        the 15-point interpolant of the plate gap rows is exact to round-off (module
        docstring); the step is then redone shorter."""
        if self.plate is None or t1 <= t0 or not self.active:
            return False
        x = self.states_at(dense, t0 + STEP_POINTS * (t1 - t0))[0]
        travel = np.max(np.linalg.norm(x[:, :, :2] - x[:1, :, :2], axis=-1))
        return bool(self.plate.k_max * travel > 1.0)

    # --- events ---------------------------------------------------------------------------
    def rows(self):
        """Watched functions: (key, expected sign, polynomial?, dead band) in a fixed order.

        A row's event is its value crossing the dead band on the far side of zero (squared
        distances: 1e-12 (r_i + r_j)^2, i.e. a penetration of ~5e-13 (r_i + r_j), ~1e-14 m;
        edges 1e-13 m; clamp indicator 1e-10): round-off at a grazing touch (two balls
        parting at zero normal speed) then does not start and end contacts over and over.
        """
        rows = []
        for pk, p in self.pairs.items():
            band = 1e-12 * p.radius_sum**2
            if not p.in_contact:
                rows.append(((EventKind.CONTACT_START, pk), 1.0, True, band))
                continue
            rows.append(((EventKind.CONTACT_END, pk), -1.0, True, band))
            if p.kinked:
                rows.append(((EventKind.FULL_DAMPING, pk), 1.0 if p.ramp else -1.0, True, band))
            if p.kinked and p.law.clamp:
                sign = -1.0 if p.clamped else 1.0
                rows.append(((EventKind.CLAMP_ON, pk), sign, False, 1e-10))
        for b in self.active:
            for e in range(len(EDGES)):
                rows.append(((EventKind.LEAVE, (b, e)), 1.0, True, 1e-13))
        return rows

    def row_values(self, rows, x, v, modes=None):
        """Values of ``rows`` at the states x, v (K, n, 3) (and modes, each (K, m)): array
        (len(rows), K)."""
        pair_keys = [r[0][1] for r in rows if r[0][0] != EventKind.LEAVE]
        pairs = [self.pairs[k] for k in dict.fromkeys(pair_keys)]
        index = {id(p): q for q, p in enumerate(pairs)}
        out = np.empty((len(rows), x.shape[0]))
        if pairs:
            kin, _, _, _ = self.kinematics(pairs, x, v, modes)
            delta = kin.penetration.reshape(x.shape[0], len(pairs)).T
            rate = kin.rate.reshape(x.shape[0], len(pairs)).T
        loc = self.local()
        edges = self.incline.edge_distances(x[..., :2])  # (K, n, 4)
        for r, ((kind, key), *_) in enumerate(rows):
            if kind == EventKind.LEAVE:
                out[r] = edges[:, loc[key[0]], key[1]]
                continue
            p = self.pairs[key]
            q = index[id(p)]
            dist = p.radius_sum - delta[q]
            if kind in (EventKind.CONTACT_START, EventKind.CONTACT_END):
                out[r] = dist**2 - p.radius_sum**2
            elif kind == EventKind.FULL_DAMPING:
                out[r] = dist**2 - (p.radius_sum - p.law.penetration) ** 2
            else:
                out[r] = [
                    clamp_indicator(d_, u_, p.law, p.ramp)
                    for d_, u_ in zip(delta[q], rate[q], strict=True)
                ]
        return out

    def states_at(self, dense, times):
        """Positions, velocities (K, n, 3) and modes ((K, m) each, or None) at ``times``."""
        ys = np.atleast_2d(dense(times).T)  # (K, 6n [+ 2m])
        n = len(self.active)
        x, v = ys[:, : 3 * n].reshape(-1, n, 3), ys[:, 3 * n : 6 * n].reshape(-1, n, 3)
        return x, v, self.modes(ys)

    def detect(self, dense, t0, t1, fresh):
        """Earliest (row, time) of an event on [t0, t1], or None."""
        rows = self.rows()
        if not rows or t1 <= t0:
            return None
        values = self.row_values(rows, *self.states_at(dense, t0 + STEP_POINTS * (t1 - t0)))
        # g = sign x value + band: positive on the row's side, its event where g < 0
        g = (
            np.array([r[1] for r in rows])[:, None] * values
            + np.array([r[3] for r in rows])[:, None]
        )
        coef = chebyshev_coefficients(g)  # Chebyshev coefficients of every row
        certified = certified_positive(coef) & np.array([r[2] for r in rows])
        best = (math.inf, None)
        for r in np.flatnonzero(~certified):
            key, _, poly, _ = rows[r]
            is_fresh = _same_switch(key, fresh)
            if poly:
                s = first_downward_crossing(coef[r], g[r], is_fresh)
            else:
                s = self.first_sampled_crossing(rows[r], g[r], dense, t0, t1, is_fresh)
            if s < best[0]:
                best = (s, rows[r])
        if best[1] is None:
            return None
        return best[1], t0 + best[0] * (t1 - t0)

    def first_sampled_crossing(self, row, values, dense, t0, t1, is_fresh):
        """First s where a sampled (non-polynomial) row leaves its side: a node on the wrong
        side right after one on the right side, bracketed by brentq. A row an event just sat
        on (``is_fresh``) may start on the wrong side by round-off (its root was located on
        the discarded step's interpolant): only a right-to-wrong change counts for it."""
        key, sign, _, band = row
        right = values > 0.0
        if not is_fresh and not right[0]:
            return 0.0
        change = np.flatnonzero(right[:-1] & ~right[1:])
        if change.size == 0:
            return math.inf
        k = int(change[0]) + 1

        def f(s):
            states = self.states_at(dense, np.array([t0 + s * (t1 - t0)]))
            return sign * self.row_values([row], *states)[0, 0] + band

        return brentq(f, STEP_POINTS[k - 1], STEP_POINTS[k], xtol=1e-15, rtol=1e-15)

    def apply(self, key, t, y):
        """Apply event ``key`` at time t with state y; returns the next first step (s)."""
        self.t, self.y = float(t), y
        t = self.t
        kind, k = key
        if kind == EventKind.LEAVE:
            self.leave(k[0], EDGES[k[1]], t)
            return None
        p = self.pairs[k]
        x, v = self.split(y)
        kin, li, lj, _ = self.kinematics([p], x, v, self.modes(y))
        if kind == EventKind.CONTACT_START:
            self.open_contact(p, t, kin, x[li[0]], v, li[0], lj[0])
            return self.first_contact_step(p, kin.rate[0])
        if kind == EventKind.CONTACT_END:
            self.close_contact(p, t, kin, v, li[0], lj[0], "separated")
            return None
        if kind == EventKind.FULL_DAMPING:
            p.ramp = not p.ramp
        else:
            p.clamped = not p.clamped
            kind = EventKind.CLAMP_ON if p.clamped else EventKind.CLAMP_OFF
        self.log(t, kind, p)
        return None

    def log(self, t, kind, p):
        self.events.append(Event(t, self.balls[p.i].name, kind, self.partner_name(p)))

    def partner_name(self, p):
        return PLATE if p.j < 0 else self.balls[p.j].name

    def first_contact_step(self, p, rate):
        """tau^(e+2) reaches rtol at t_s rtol^(1/(e+2)) (as in the rigid reference)."""
        m_i = self.mass[p.i]
        m = m_i if p.j < 0 else m_i * self.mass[p.j] / (m_i + self.mass[p.j])
        speed = max(rate, 1e-3)
        t_s = hertz_max_penetration(m, speed, p.law.stiffness, p.law.exponent) / speed
        return min(
            t_s * self.rtol ** (1.0 / (p.law.exponent + 2.0)), 0.5 * p.law.penetration / speed
        )

    def open_contact(self, p, t, kin, x_i, v, li, lj):
        p.in_contact, p.ramp, p.clamped = True, True, False
        p.peak, p.t_peak, p.pen = 0.0, math.nan, max(0.0, float(kin.penetration[0]))
        if p.j < 0 and self.plate is not None and self.plate.frozen:
            p.phi0 = self.plate.shapes_at(x_i[:2])[0]
        n = kin.normal[0]
        point = x_i - n * (self.balls[p.i].radius - 0.5 * max(kin.penetration[0], 0.0))
        rate = float(kin.rate[0]) if p.j >= 0 or self.plate is None else float(-v[li] @ n)
        p.records = [
            Impact(ball=self.balls[p.i].name, partner=self.partner_name(p), t_start=t,
                   x=point[0], y=point[1], v_in=float(-v[li] @ n), approach_in=rate)
        ]  # fmt: skip
        if p.j >= 0:
            p.records.append(
                Impact(ball=self.balls[p.j].name, partner=self.balls[p.i].name, t_start=t,
                       x=point[0], y=point[1], v_in=float(v[lj] @ n), approach_in=rate)
            )  # fmt: skip
        self.contacts.extend(p.records)
        self.log(t, EventKind.CONTACT_START, p)

    def close_contact(self, p, t, kin, v, li, lj, end):
        n = kin.normal[0]
        outs = [float(v[li] @ n)] + ([float(-v[lj] @ n)] if p.j >= 0 else [])
        # approach speeds of a plate row: the ball's (as v_in, v_out), also on the modal plate
        out = -float(kin.rate[0]) if p.j >= 0 or self.plate is None else outs[0]
        for rec, v_out in zip(p.records, outs, strict=True):
            rec.t_end, rec.v_out, rec.approach_out, rec.end = t, v_out, out, end
            rec.peak_force, rec.t_peak, rec.max_penetration = p.peak, p.t_peak, p.pen
        p.in_contact, p.records, p.phi0 = False, [], None
        self.log(t, EventKind.CONTACT_END, p)

    def leave(self, ball, edge, t):
        x, v = self.split(self.y)
        modes = self.modes(self.y)
        for pk in [pk for pk in self.pairs if ball in pk]:
            p = self.pairs.pop(pk)
            if p.in_contact:
                kin, li, lj, _ = self.kinematics([p], x, v, modes)
                self.close_contact(p, t, kin, v, li[0], lj[0], "left")
        self.leaves.append(LeaveEvent(self.balls[ball].name, t, edge))
        self.events.append(Event(t, self.balls[ball].name, EventKind.LEAVE, edge))
        keep = [q for q, b in enumerate(self.active) if b != ball]
        self.active = [self.active[q] for q in keep]
        self.y = self.join(x[keep], v[keep], modes)

    def next_stop(self, duration):
        """Where the integration must stop next: the next release time or the end."""
        return min(duration, self.waiting[0][0]) if self.waiting else duration

    def release_due(self, t, y):
        """Add the balls whose release time is t (their given state), with their pairs."""
        self.t, self.y = t, y
        x, v = self.split(y)
        modes = self.modes(y)
        new = []
        while self.waiting and self.waiting[0][0] <= t:
            _, i = self.waiting.pop(0)
            ball = self.balls[i]
            self.active.append(i)
            x = np.vstack([x, ball.position])
            v = np.vstack([v, ball.velocity])
            new.extend(self.add_pairs(i))
            self.events.append(Event(t, ball.name, EventKind.RELEASE, ""))
        self.y = self.join(x, v, modes)
        self.touch(new, t)
        return None

    def add_pairs(self, i):
        """Create the pairs of ball i with the plate and with every other active ball."""
        a, made = self.balls[i], []
        law = ball_plate_law(a.material, a.radius, self.incline.plate.material, **self.options)
        made.append(self.pairs.setdefault((i, -1), _Pair(i, -1, law, a.radius)))
        for j in self.active:
            if j != i:
                lo, hi = min(i, j), max(i, j)
                b, c = self.balls[lo], self.balls[hi]
                law = ball_ball_law(b.material, b.radius, c.material, c.radius, **self.options)
                pair = _Pair(lo, hi, law, b.radius + c.radius)
                made.append(self.pairs.setdefault((lo, hi), pair))
        return made

    def touch(self, pairs, t):
        """Pairs overlapping when they appear start in contact (e.g. a ball placed at its
        static penetration)."""
        x, v = self.split(self.y)
        for p in pairs:
            kin, li, lj, _ = self.kinematics([p], x, v, self.modes(self.y))
            if kin.penetration[0] > 0.0:
                self.open_contact(p, t, kin, x[li[0]], v, li[0], lj[0])
                p.ramp = bool(kin.penetration[0] < p.law.penetration) or not p.kinked
                ind = clamp_indicator(kin.penetration[0], kin.rate[0], p.law, p.ramp)
                p.clamped = bool(p.law.clamp and p.kinked and ind < 0.0)

    # --- accepted steps: peaks, energy, states ---------------------------------------------
    def accept(self, dense, t0, t1):
        """Update the peak force and maximum penetration of the contacts on [t0, t1]."""
        pairs = [p for p in self.pairs.values() if p.in_contact]
        if not pairs or t1 <= t0:
            return
        force, delta = self.pair_forces(pairs, *self.states_at(dense, t0 + STEP_POINTS * (t1 - t0)))
        # Refined only where the node maximum comes within 1 % of the record so far: between
        # nodes the interpolant cannot exceed them by more (a step resolved to rtol 1e-12
        # spans ~(1e-12)^(1/8) of the force's time scale; the overshoot is ~1e-6).
        for q, p in enumerate(pairs):
            if force[q].max() >= 0.99 * p.peak:
                s_peak, peak = interpolant_max(force[q])
                if peak > p.peak:
                    p.peak, p.t_peak = peak, t0 + s_peak * (t1 - t0)
            if delta[q].max() >= 0.99 * p.pen:
                p.pen = max(p.pen, interpolant_max(delta[q])[1])

    def pair_forces(self, pairs, x, v, modes=None):
        """Force (N) and penetration (m) of ``pairs`` at states x, v (K, n, 3) (and modes):
        (P, K) each."""
        kin, _, _, _ = self.kinematics(pairs, x, v, modes)
        laws = _law_table(pairs)
        ramp = np.array([p.ramp for p in pairs])
        clamped = np.array([p.clamped for p in pairs])
        k = x.shape[0]
        delta = kin.penetration.reshape(k, len(pairs))
        rate = kin.rate.reshape(k, len(pairs))
        force = impact_force_in_region(delta, rate, laws, ramp, clamped)
        return force.T, delta.T

    def total_energy(self, y):
        """Kinetic + gravitational + elastic energy in J of the active balls at state y."""
        x, v = self.split(y)
        m = self.mass[self.active]
        energy = 0.5 * float(np.sum(m[:, None] * v * v))
        energy += self.incline.potential_energy(m, x)
        modes = self.modes(y)
        if modes is not None:
            energy += self.plate.energy(*modes)
            modes = tuple(a[None] for a in modes)
        pairs = [p for p in self.pairs.values() if p.in_contact]
        if pairs:
            kin, _, _, _ = self.kinematics(pairs, x[None], v[None], modes)
            energy += float(np.sum(elastic_energy(kin.penetration, _law_table(pairs))))
        return energy

    def record_step(self, t, y):
        self.times.append(t)
        self.energy.append(self.total_energy(y))
        x, v = self.split(y)
        names = tuple(self.balls[b].name for b in self.active)
        self.states.append((names, x.copy(), v.copy()))
        if self.plate is not None:
            self.plate_states.append(tuple(a.copy() for a in self.modes(y)))

    def finish(self):
        for p in self.pairs.values():
            for rec in p.records:
                rec.peak_force, rec.t_peak, rec.max_penetration = p.peak, p.t_peak, p.pen

    def result(self, duration):
        info = {
            "solver": f"stream reference: scipy DOP853 rtol={self.rtol:g}, restarted at kinks",
            "plate": "rigid"
            if self.plate is None
            else f"modal, two-way: {self.plate.n_modes} modes, {self.plate.shapes} shapes",
            "duration": duration,
        }
        return StreamReferenceResult(
            tuple(b.name for b in self.balls), self.mass, self.contacts, self.leaves,
            self.events, np.array(self.times), np.array(self.energy), self.states,
            self.steps, info, self.plate_states,
        )  # fmt: skip


def _same_switch(key, fresh) -> bool:
    """Whether the row ``key`` is the function an event at the restart time sat on."""
    kind, k = key
    for f_kind, f_k in fresh:
        if f_k != k:
            continue
        same = {EventKind.CONTACT_START, EventKind.CONTACT_END}
        clamp = {EventKind.CLAMP_ON, EventKind.CLAMP_OFF}
        if (
            f_kind == kind
            or (kind in same and f_kind in same)
            or (kind in clamp and f_kind in clamp)
        ):
            return True
    return False


def _law_table(pairs) -> _Laws:
    return _Laws(*(np.array([getattr(p.law, a) for p in pairs], dtype=float)
                   for a in ("stiffness", "exponent", "damping", "penetration")))  # fmt: skip


def _check_modal_work(plate, duration, max_steps):
    """The modes bound the steps: at least MODAL_STEPS_PER_PERIOD per period of the top mode
    (measured 9-20 at rtol 1e-12); refuse a run that cannot fit max_steps before it starts."""
    estimate = MODAL_STEPS_PER_PERIOD * duration * float(np.max(plate.omega)) / (2.0 * math.pi)
    if estimate > max_steps:
        raise WorkLimitError(
            f"stream reference: the modal plate (top mode {np.max(plate.omega) / 2 / math.pi:.4g}"
            f" Hz) needs at least ~{estimate:.3g} steps for {duration:g} s, above "
            f"max_steps={max_steps}; raise max_steps, shorten the duration or keep fewer modes"
        )


def _release_times(release_times, n):
    if release_times is None:
        return np.zeros(n)
    times = np.asarray(release_times, dtype=float)
    if times.shape != (n,) or not np.all(np.isfinite(times)) or np.any(times < 0.0):
        raise InputError("release_times", f"must be {n} finite times >= 0 s (one per ball)")
    return times


def _check_balls(balls, incline):
    names = set()
    for b in balls:
        field_ = f"balls[{b.name}]"
        if b.name in names:
            raise InputError(f"{field_}.name", "is used by an earlier ball")
        names.add(b.name)
        if b.position[2] <= 0.0:
            raise InputError(f"{field_}.position", "the centre must lie above the plate (z > 0)")
        if np.any(incline.edge_distances(b.position[:2]) < 0.0):
            raise InputError(f"{field_}.position", "the centre must lie over the plate")
