"""Slow, independent reference: scipy's solve_ivp (DOP853) restarted at every kink.

Flights are closed form (shared with the fast solver); each contact is integrated with
scipy.integrate.solve_ivp(method="DOP853", rtol=1e-12) in the local time tau = t - t_contact for
the state (delta, u). Every kink of the force law is a terminal event (penetration = d, clamp
on/off, separation) at which the integration restarts with the right-hand side of the new
region; within a region the right-hand side is that region's smooth formula (so no step
straddles a kink). Peaks of the force (dF/dt = 0) and of the penetration (u = 0) are
non-terminal events. Used by the tests and the benchmark as the truth for the fast solver.
"""

import math

import numpy as np
from scipy.integrate import solve_ivp

from tailbeam.errors import WorkLimitError
from tailbeam.physics import impact
from tailbeam.physics.bodies import STANDARD_GRAVITY
from tailbeam.results.records import End, EventKind
from tailbeam.solvers.rigid import driver
from tailbeam.solvers.rigid.model import (
    DEFAULT_MAX_CONTACTS,
    DEFAULT_MAX_STEPS,
    DEFAULT_REST_SPEED,
    check_rtol,
)

CHUNK = 400.0  # integrate at most this many contact time scales per solve_ivp call
_SAME_FUNCTION = {
    EventKind.FULL_DAMPING: ("full_damping",),
    EventKind.CLAMP_ON: ("clamp",),
    EventKind.CLAMP_OFF: ("clamp",),
}


def simulate_rigid_reference(
    balls,
    plate,
    laws,
    duration,
    *,
    rtol=1e-12,
    gravity=STANDARD_GRAVITY,
    rest_speed=DEFAULT_REST_SPEED,
    max_contacts=DEFAULT_MAX_CONTACTS,
    max_steps=DEFAULT_MAX_STEPS,
):
    """Same contract as ``simulate_rigid``; slow (pure scipy), for verification."""
    rtol = check_rtol(rtol)

    def integrate(pair, v_in, tau_max, steps_left):
        return _Contact(pair, rtol).run(v_in, tau_max, steps_left)

    solver = f"reference: scipy solve_ivp DOP853 rtol={rtol:g}, restarted at kinks"
    return driver.simulate_balls(
        balls, plate, laws, duration, integrate, gravity=gravity, rest_speed=rest_speed,
        max_contacts=max_contacts, max_steps=max_steps, info={"solver": solver},
    )  # fmt: skip


class _Contact:
    """One contact integrated region by region."""

    def __init__(self, p, rtol):
        self.p, self.rtol = p, rtol

    # --- the law of one region (ramp: delta < d; clamped: force held at 0), from the core ---
    def _law(self):
        p = self.p
        return p.k, p.e, p.c, p.d

    def force(self, delta, u, ramp, clamped):
        if clamped or delta <= 0.0:
            return 0.0
        return impact.region_force(delta, u, *self._law(), ramp, False)

    def clamp_indicator(self, delta, u, ramp):
        """Sign of the unclamped force, not 0 at delta = 0 (``impact.clamp_indicator``)."""
        return impact.clamp_indicator(delta, u, *self._law(), ramp)

    def dforce(self, delta, u, ramp):
        """dF/dt of the unclamped force along the motion."""
        accel = self.p.gravity - self.force(delta, u, ramp, False) / self.p.mass
        return impact.region_force_rate(delta, u, accel, *self._law(), ramp)

    def run(self, v_in, tau_max, steps_left):
        """Integrate the contact from delta = 0, u = v_in (m/s) for at most tau_max (s) and
        steps_left steps: a ``driver.ContactOutcome``."""
        p = self.p
        t_s = p.scales(v_in)[2]
        tau, y = 0.0, np.array([0.0, v_in])
        ramp, clamped = p.d > 0.0, False
        events, pieces = [], []
        maxima = (0.0, 0.0, 0.0)  # (peak force N, its tau s, max penetration m)
        work = [0, 0]  # nfev, steps
        fresh = None  # the switch event whose root we restart on
        status, v_out = End.DURATION, math.nan
        while tau < tau_max:
            evs = self._events(ramp, clamped, fresh, tau)
            rhs = self._rhs(ramp, clamped)
            sol = self._solve_region(rhs, tau, min(tau_max, tau + CHUNK * t_s), y, evs, v_in)
            self._count(work, sol, steps_left)
            pieces.extend(_pieces(sol))
            maxima, hit = self._maxima(sol, evs, ramp, clamped, maxima)
            tau, y = sol.t[-1], sol.y[:, -1].copy()
            fresh = hit
            if hit is None:
                continue
            if hit in (EventKind.FULL_DAMPING, EventKind.CLAMP_ON, EventKind.CLAMP_OFF):
                ramp, clamped = self._switch(hit, y, ramp, clamped)
                events.append((tau, hit))
            elif hit == EventKind.CONTACT_END:
                y = self._exit_state(rhs, sol, tau, y, v_in, pieces, work)
                events.append((tau, hit))
                status, v_out = End.SEPARATED, -y[1]
                break
            elif hit == EventKind.REST:
                status, v_out = End.REST, 0.0
                break
        tau_start, tau_old, step, y_old, coef = (np.array(x) for x in zip(*pieces, strict=True))
        peak, tau_peak, pen = maxima
        return driver.ContactOutcome(
            status, float(tau), float(v_out), float(peak), float(tau_peak), float(pen),
            [(float(t), k) for t, k in events],
            tau_start, tau_old, step, y_old, coef, work[0], work[1],
        )  # fmt: skip

    def _atol(self, v_in):
        """Absolute tolerances (m, m/s) of the state from the contact's scales."""
        delta_s, v_s, _t_s = self.p.scales(v_in)
        return np.array([self.rtol * delta_s, self.rtol * v_s])

    def _solve_region(self, rhs, tau, t_stop, y, evs, v_in):
        """solve_ivp in one region from (tau s, y) to t_stop (s) or the first terminal event."""
        p = self.p
        _delta_s, v_s, t_s = p.scales(v_in)
        sol = solve_ivp(
            rhs,
            (tau, t_stop),
            y,
            method="DOP853",
            rtol=self.rtol,
            atol=self._atol(v_in),
            events=[ev for ev, _, _ in evs],
            dense_output=True,
            max_step=t_s,
            first_step=min(t_s * self.rtol ** (1.0 / (p.e + 2.0)), 0.5 * p.d / v_s, t_stop - tau),
        )
        if sol.status < 0:
            raise RuntimeError(f"reference integrator failed: {sol.message}")
        return sol

    def _count(self, work, sol, steps_left):
        """Add the solve's work to work = [nfev, steps]; WorkLimitError past steps_left."""
        work[0] += sol.nfev
        work[1] += len(sol.t) - 1
        if work[1] > steps_left:
            raise WorkLimitError(
                f"ball {self.p.name!r}: reference solver exceeded max_steps; raise max_steps"
            )

    def _maxima(self, sol, evs, ramp, clamped, maxima):
        """The maxima (peak N, tau_peak s, pen m) updated with the region's ends and its peak
        events, and the terminal event the solve stopped on (None if it reached t_stop)."""
        peak, tau_peak, pen = maxima
        # candidates at both ends of this region for the peaks
        for s_tau, s_y in ((sol.t[0], sol.y[:, 0]), (sol.t[-1], sol.y[:, -1])):
            f = self.force(s_y[0], s_y[1], ramp, clamped)
            if f > peak:
                peak, tau_peak = f, s_tau
            pen = max(pen, s_y[0])
        hit = None
        for (_, kind, role), te, ye in zip(evs, sol.t_events, sol.y_events, strict=True):
            for t_e, y_e in zip(te, ye, strict=True):
                if role == "peak":
                    f = self.force(y_e[0], y_e[1], ramp, clamped)
                    if f > peak:
                        peak, tau_peak = f, t_e
                elif role == "pen":
                    pen = max(pen, y_e[0])
                elif sol.status == 1 and t_e == sol.t[-1]:
                    hit = kind
        return (peak, tau_peak, pen), hit

    def _switch(self, hit, y, ramp, clamped):
        """The region (ramp, clamped) after a kink; a full-damping restart sits exactly on
        delta = d (y changed in place)."""
        if hit == EventKind.FULL_DAMPING:
            y[0] = self.p.d  # exactly on the kink
            return not ramp, clamped
        return ramp, hit == EventKind.CLAMP_ON

    def _exit_state(self, rhs, sol, tau, y, v_in, pieces, work):
        """State at the separation tau (s). Past delta = 0 the force is 0, so the step holding
        the root straddles a kink: its part up to the root is integrated again, on its own,
        and replaces the step's piece."""
        if not (len(sol.t) >= 2 and sol.t[-2] < tau):
            return y
        redo = solve_ivp(rhs, (sol.t[-2], tau), sol.y[:, -2], method="DOP853", rtol=self.rtol,
                         atol=self._atol(v_in), dense_output=True,
                         first_step=tau - sol.t[-2])  # fmt: skip
        work[0] += redo.nfev
        pieces.pop()
        pieces.extend(_pieces(redo))
        return redo.y[:, -1]

    def _rhs(self, ramp, clamped):
        p = self.p

        def rhs(t, s):
            return (s[1], p.gravity - self.force(s[0], s[1], ramp, clamped) / p.mass)

        return rhs

    def _events(self, ramp, clamped, fresh, tau0):
        """(function, kind, role) of the events watched in a region. ``fresh``: the kind of
        switch we restart on at tau0; its function is 0 there, so it is divided by tau - tau0
        (same sign and roots after tau0, and the known sign before the crossing at tau0):
        otherwise a quick return across 0 within the first step would go unnoticed."""
        p = self.p

        def mk(fun, terminal, direction, kind=None):
            if kind is not None and kind in _SAME_FUNCTION.get(fresh, ()):
                raw = fun

                def fun(t, s):
                    return raw(t, s) / (t - tau0) if t > tau0 else -float(direction)

            fun.terminal, fun.direction = terminal, direction
            return fun

        evs = [
            (
                mk(lambda t, s: s[0] - p.d, True, 1 if ramp else -1, "full_damping"),
                EventKind.FULL_DAMPING,
                "switch",
            ),
            (mk(lambda t, s: s[0], True, -1), EventKind.CONTACT_END, "switch"),
            (mk(lambda t, s: s[1], False, -1), None, "pen"),
        ]
        if p.clamp and p.c > 0.0:
            evs.append(
                (
                    mk(
                        lambda t, s: self.clamp_indicator(s[0], s[1], ramp),
                        True,
                        1 if clamped else -1,
                        "clamp",
                    ),
                    EventKind.CLAMP_OFF if clamped else EventKind.CLAMP_ON,
                    "switch",
                )
            )
        if not clamped:
            evs.append((mk(lambda t, s: self.dforce(s[0], s[1], ramp), False, -1), None, "peak"))
        if p.e_rest > 0.0:
            evs.append(
                (
                    mk(lambda t, s: p.excess_energy(s[0], s[1]) - p.e_rest, True, -1),
                    EventKind.REST,
                    "switch",
                )
            )
        return evs


def _pieces(sol):
    """The dense-output pieces of a solve_ivp solution: (tau_start, t_old, h, y_old, F)."""
    ts = sol.sol.ts
    return [
        (ts[j], it.t_old, it.h, it.y_old.copy(), it.F) for j, it in enumerate(sol.sol.interpolants)
    ]
