"""The stream reference's events: the watched functions (rows) and the search for the first
crossing on a step (a mixin of ``tailbeam.solvers.stream.reference.solver._Reference``, which
provides ``pairs``, ``active``, ``incline`` and the state layout of ``reference_state``).

Event search (``tailbeam.solvers.numerics.step_events``). DOP853's dense output is a polynomial of
degree 7 in time on each step, so the squared distance of two centres (and the plate gap,
the edge distances) is a polynomial of degree <= 14 there, interpolated exactly at 15
Chebyshev points and certified or root-found: no contact is missed, however short the
step's approach and retreat. The clamp indicator (not polynomial) is sampled at the 15 points
and bracketed with ``brentq``. A redone step is checked again (a root placed by a step that
straddled the kink can be late). Each event fires when its function passes a dead band
beyond zero (see ``ReferenceEvents.rows``), against round-off chatter at grazing contacts.
"""

import math

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


class ReferenceEvents:
    """Rows, their values and the first event on a step of the stream reference."""

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
