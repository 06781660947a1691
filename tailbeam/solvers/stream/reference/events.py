"""The stream reference's events: the watched functions (rows) and the search for the first
crossing on a step.

Event search (``tailbeam.solvers.numerics.step_events``). DOP853's dense output is a
polynomial of degree 7 in time on each step, so the squared distance of two centres (and the
plate gap, the edge distances) is a polynomial of degree <= 14 there, interpolated exactly at
15 Chebyshev points and certified or root-found: no contact is missed, however short the
step's approach and retreat. The clamp indicator (not polynomial) is sampled at the 15 points
and bracketed with ``brentq``. A redone step is checked again (a root placed by a step that
straddled the kink can be late). Each event fires when its function passes a dead band
beyond zero (see ``EventSearch.rows``), against round-off chatter at grazing contacts.
"""

import math
from typing import NamedTuple

import numpy as np
from scipy.optimize import brentq

from tailbeam.physics.contact_law import clamp_indicator
from tailbeam.physics.incline import EDGES
from tailbeam.results.records import EventKind
from tailbeam.solvers.numerics.step_events import (
    STEP_POINTS,
    certified_positive,
    chebyshev_coefficients,
    first_downward_crossing,
)
from tailbeam.solvers.stream.reference.sticking import SLIP_TINY

CONTACT = frozenset({EventKind.CONTACT_START, EventKind.CONTACT_END})  # one row, two sides
CLAMP = frozenset({EventKind.CLAMP_ON, EventKind.CLAMP_OFF})
SLIDING = frozenset({EventKind.STICK, EventKind.SLIP})  # Coulomb's law (``sticking``)
ROLLING = frozenset({EventKind.ROLL_HOLD, EventKind.ROLL_FREE})
COULOMB = SLIDING | ROLLING
SIDES = (CONTACT, CLAMP, SLIDING, ROLLING)  # the kinds a row switches between
FORCE_BAND = 1e-9  # N (N m for torques): a stuck contact's force past its limit by this
SPEED_BAND = 1e-13  # m/s: a slip (or R x rolling rate) past zero by this


class RowKey(NamedTuple):
    """What a row watches: ``kind`` (an ``EventKind``) of ``target``, a pair key (i, j) or,
    for ``LEAVE``, (ball, edge index into ``EDGES``)."""

    kind: EventKind
    target: tuple


class Row(NamedTuple):
    """A watched function: its ``key``, the ``sign`` (+1 or -1) of its value on the side it
    is on, whether it is a ``polynomial`` on a step, and its dead ``band``."""

    key: RowKey
    sign: float
    polynomial: bool
    band: float


class EventSearch:
    """The rows of the present balls and pairs, their values and the first event on a step.

    Parameters
    ----------
    pairs : PairSet
        The watched pairs.
    layout : StateLayout
        Which balls are present; its ``states_at`` reads a step's dense output.
    kinematics : Kinematics
        The pairs' contact kinematics.
    incline : InclinedPlate
        The plate's edges.
    plate : ReferencePlate or None
        The modal plate (its top wavenumber bounds a step's sideways travel), or None.
    """

    def __init__(self, pairs, layout, kinematics, incline, plate):
        self.pairs = pairs
        self.layout = layout
        self.kinematics = kinematics
        self.incline = incline
        self.plate = plate
        self.states_at = layout.states_at
        self.coulomb = None  # a CoulombState where a pair has Coulomb's law (set by the solver)

    def rows(self) -> list:
        """Watched functions (``Row``) in a fixed order.

        A row's event is its value crossing the dead band on the far side of zero (squared
        distances: 1e-12 (r_i + r_j)^2, i.e. a penetration of ~5e-13 (r_i + r_j), ~1e-14 m;
        edges 1e-13 m; clamp indicator 1e-10): round-off at a grazing touch (two balls
        parting at zero normal speed) then does not start and end contacts over and over.
        """
        rows = []
        for pk, p in self.pairs.items():
            band = 1e-12 * p.radius_sum**2
            if not p.in_contact:
                rows.append(Row(RowKey(EventKind.CONTACT_START, pk), 1.0, True, band))
                continue
            rows.append(Row(RowKey(EventKind.CONTACT_END, pk), -1.0, True, band))
            if p.kinked:
                sign = 1.0 if p.ramp else -1.0
                rows.append(Row(RowKey(EventKind.FULL_DAMPING, pk), sign, True, band))
            if p.kinked and p.law.clamp:
                sign = -1.0 if p.clamped else 1.0
                rows.append(Row(RowKey(EventKind.CLAMP_ON, pk), sign, False, 1e-10))
            if p.coulomb:
                rows.extend(_coulomb_rows(pk, p))
        for b in self.layout.active:
            for e in range(len(EDGES)):
                rows.append(Row(RowKey(EventKind.LEAVE, (b, e)), 1.0, True, 1e-13))
        return rows

    def row_values(self, rows, x, v, modes=None, w=None) -> np.ndarray:
        """Values of ``rows`` at the states x (m), v (m/s), (K, n, 3) each (and modes, each
        (K, m); w the angular velocities (K, n, 3) rad/s, for Coulomb's law's rows): array
        (len(rows), K) (m^2 for distances, m for edges, N or m/s for Coulomb's law's)."""
        if any(r.key.kind in COULOMB for r in rows):
            return self._with_coulomb_rows(rows, x, v, modes, w)
        pair_keys = [r.key.target for r in rows if r.key.kind != EventKind.LEAVE]
        pairs = [self.pairs[k] for k in dict.fromkeys(pair_keys)]
        index = {id(p): q for q, p in enumerate(pairs)}
        out = np.empty((len(rows), x.shape[0]))
        if pairs:
            kin, _, _, _ = self.kinematics.of(pairs, x, v, modes)
            delta = kin.penetration.reshape(x.shape[0], len(pairs)).T
            rate = kin.rate.reshape(x.shape[0], len(pairs)).T
        loc = self.layout.local()
        edges = self.incline.edge_distances(x[..., :2])  # (K, n, 4)
        for r, row in enumerate(rows):
            kind, key = row.key
            if kind == EventKind.LEAVE:
                out[r] = edges[:, loc[key[0]], key[1]]
                continue
            p = self.pairs[key]
            q = index[id(p)]
            dist = p.radius_sum - delta[q]
            if kind in CONTACT:
                out[r] = dist**2 - p.radius_sum**2
            elif kind == EventKind.FULL_DAMPING:
                out[r] = dist**2 - (p.radius_sum - p.law.penetration) ** 2
            else:
                out[r] = [
                    clamp_indicator(d_, u_, p.law, p.ramp)
                    for d_, u_ in zip(delta[q], rate[q], strict=True)
                ]
        return out

    def _with_coulomb_rows(self, rows, x, v, modes, w) -> np.ndarray:
        """``row_values`` where some rows are Coulomb's law's: those from the friction of the
        pairs in contact at each state (``CoulombState``), the others as usual."""
        out = np.empty((len(rows), x.shape[0]))
        plain = [r for r, row in enumerate(rows) if row.key.kind not in COULOMB]
        if plain:
            out[plain] = self.row_values([rows[r] for r in plain], x, v, modes)
        coulomb = [r for r, row in enumerate(rows) if row.key.kind in COULOMB]
        for k in range(x.shape[0]):
            pairs, f, fr, table = self.coulomb.at(x[k], v[k], w[k])
            index = {id(p): q for q, p in enumerate(pairs)}
            for r in coulomb:
                kind, key = rows[r].key
                p = self.pairs[key]
                out[r, k] = coulomb_value(kind, p, index[id(p)], f, fr, table)
        return out

    def set_directions(self, y) -> None:
        """Coulomb's law: each sliding or rolling contact's direction at the start of the
        step about to be taken (state vector y), which its force opposes past zero and its
        ``STICK`` or ``ROLL_HOLD`` row watches the slip or rolling velocity cross
        (``Pair.slide_dir`` / ``roll_dir`` while it is ~zero)."""
        if self.coulomb is None or not self.coulomb.any():
            return
        x, v = self.layout.split(y)
        pairs, _f, fr, table = self.coulomb.at(x, v, self.layout.spins(y))
        for q, p in enumerate(pairs):
            if not p.coulomb:
                continue
            slip, roll = fr.slip[q], fr.roll[q] * table.roll_radius[q]
            speed, rate = np.linalg.norm(slip), np.linalg.norm(roll)
            p.slide_ref = slip / speed if speed >= SLIP_TINY else p.slide_dir
            p.roll_ref = roll / rate if rate >= SLIP_TINY else p.roll_dir

    def detect(self, dense, t0, t1, fresh):
        """Earliest event on the step [t0, t1] (s) with dense output ``dense``: (row, time)
        or None. ``fresh``: keys of the events applied at t0."""
        rows = self.rows()
        if not rows or t1 <= t0:
            return None
        times = t0 + STEP_POINTS * (t1 - t0)
        spins = None
        if self.coulomb is not None and self.coulomb.any():
            spins = self.layout.spins_at(dense, times)
        values = self.row_values(rows, *self.states_at(dense, times), spins)
        # g = sign x value + band: positive on the row's side, its event where g < 0
        g = (
            np.array([r.sign for r in rows])[:, None] * values
            + np.array([r.band for r in rows])[:, None]
        )
        coef = chebyshev_coefficients(g)  # Chebyshev coefficients of every row
        certified = certified_positive(coef) & np.array([r.polynomial for r in rows])
        best = (math.inf, None)
        for r in np.flatnonzero(~certified):
            is_fresh = _same_switch(rows[r].key, fresh)
            if rows[r].polynomial:
                s = first_downward_crossing(coef[r], g[r], is_fresh)
            else:
                s = self.first_sampled_crossing(rows[r], g[r], dense, t0, t1, is_fresh)
            if s < best[0]:
                best = (s, rows[r])
        if best[1] is None:
            return None
        return best[1], t0 + best[0] * (t1 - t0)

    def first_sampled_crossing(self, row, values, dense, t0, t1, is_fresh):
        """First s in [0, 1] where a sampled (non-polynomial) row leaves its side: a node on
        the wrong side right after one on the right side, bracketed by brentq. A row an event
        just sat on (``is_fresh``) may start on the wrong side by round-off (its root was
        located on the discarded step's interpolant): only a right-to-wrong change counts
        for it."""
        right = values > 0.0
        if not is_fresh and not right[0]:
            return 0.0
        change = np.flatnonzero(right[:-1] & ~right[1:])
        if change.size == 0:
            return math.inf
        k = int(change[0]) + 1

        def f(s):
            at = np.array([t0 + s * (t1 - t0)])
            states = self.states_at(dense, at)
            spins = self.layout.spins_at(dense, at)
            return row.sign * self.row_values([row], *states, spins)[0, 0] + row.band

        return brentq(f, STEP_POINTS[k - 1], STEP_POINTS[k], xtol=1e-15, rtol=1e-15)

    def within_band(self, row, y) -> bool:
        """Whether ``row`` at state vector y has passed zero by no more than its dead band,
        i.e. its event may be applied there."""
        x, v = self.layout.split(y)
        modes = self.layout.modes(y[None])
        w = self.layout.spins(y[None])
        value = self.row_values([row], x[None], v[None], modes, w)[0, 0]
        return bool(row.sign * value <= row.band)

    def too_far(self, dense, t0, t1) -> bool:
        """Modal plate: whether a ball moved more than 1 / k_max sideways on the step [t0, t1]
        (k_max: the top mode's wavenumber, 1/m). Below it the mode shapes along the path are so
        smooth that the 15-point interpolant of the plate gap rows is exact to round-off
        (``tailbeam.solvers.stream.reference.solver``); the step is then redone shorter."""
        if self.plate is None or t1 <= t0 or not self.layout.active:
            return False
        x = self.states_at(dense, t0 + STEP_POINTS * (t1 - t0))[0]
        travel = np.max(np.linalg.norm(x[:, :, :2] - x[:1, :, :2], axis=-1))
        return bool(self.plate.k_max * travel > 1.0)


def _same_switch(key, fresh) -> bool:
    """Whether the row ``key`` is the function an event at the restart time sat on (the same
    kind, or the other side of the same contact or clamp row, of the same target)."""
    kind, k = key
    for f_kind, f_k in fresh:
        if f_k != k:
            continue
        if f_kind == kind or any(kind in side and f_kind in side for side in SIDES):
            return True
    return False


def _coulomb_rows(pk, p) -> list:
    """Coulomb's law's rows of pair ``p`` (key ``pk``) in contact: while stuck its force
    against mu_s |F_n| (``SLIP``), while sliding its slip along the step's start direction
    (``STICK``); the same for its rolling with mu_r > 0 (``ROLL_FREE``, ``ROLL_HOLD``)."""
    rows = []
    if p.friction.static > 0.0:
        kind = EventKind.SLIP if p.stuck else EventKind.STICK
        rows.append(Row(RowKey(kind, pk), 1.0, False, FORCE_BAND if p.stuck else SPEED_BAND))
    if p.friction.rolling > 0.0:
        kind = EventKind.ROLL_FREE if p.held else EventKind.ROLL_HOLD
        rows.append(Row(RowKey(kind, pk), 1.0, False, FORCE_BAND if p.held else SPEED_BAND))
    return rows


def coulomb_value(kind, p, q, normal, fr, table) -> float:
    """The value of pair ``p``'s Coulomb row of ``kind`` (its index q among the pairs in
    contact, their normal forces ``normal`` N, ``PairFriction`` ``fr`` and
    ``FrictionTable`` ``table``): the margin to the limit (N; N m for rolling) while stuck
    or held, else the slip (R x rolling velocity, m/s) along the step's start direction."""
    fn, radius = abs(normal[q]), table.roll_radius[q]
    if kind == EventKind.SLIP:
        return p.friction.static * fn - float(np.linalg.norm(fr.force[q]))
    if kind == EventKind.STICK:
        return float(fr.slip[q] @ p.slide_ref)
    if kind == EventKind.ROLL_FREE:
        return p.friction.rolling * radius * fn - float(np.linalg.norm(fr.rolling[q]))
    return float(radius * fr.roll[q] @ p.roll_ref)
