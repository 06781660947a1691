"""Event-driven bookkeeping of flights and contacts, shared by the fast and reference solvers.

A global event queue (a heap keyed on the predicted start time of each pair's next contact)
advances the scene: pop the earliest contact, integrate it (the solver-specific
``integrate_contact``), then predict that pair's next contact in closed form and push it back.
With a rigid plate the balls are independent, so each pair is only ever the ball-plate pair.

Adding ball-ball contact (tailbeam.physics.contact_law.ball_ball_law) fits this design: a ball-ball
pair's next contact is the first root of |x_i(t) - x_j(t)| = R_i + R_j for two ballistic
flights (a quartic with gravity cancelling: a quadratic in t), pushed into the same heap; a
popped prediction is discarded when either ball's trajectory changed since it was made (a
version counter per ball), and a contact involving a ball already in contact integrates the
coupled state of all balls in the overlapping contacts together.
"""

import heapq
import math
from dataclasses import dataclass, field

import numpy as np

from tailbeam.errors import WorkLimitError
from tailbeam.physics.contacts import contact_table
from tailbeam.results.records import PLATE, End, Event, EventKind, Impact
from tailbeam.results.result import Result
from tailbeam.solvers.numerics.flight import lateral_leaves
from tailbeam.solvers.rigid.model import Pair, make_pairs, time_to_contact
from tailbeam.solvers.rigid.states import RigidStates
from tailbeam.solvers.rigid.trajectory import TrajectoryBuilder
from tailbeam.streams.generator import balls_as_particles


@dataclass
class ContactOutcome:
    """What a contact integrator reports, in the local time tau = t - t_contact (s)."""

    status: End  # SEPARATED, REST (rule B) or DURATION (the simulation ended)
    tau_end: float
    v_out: float
    peak_force: float
    tau_peak: float
    max_penetration: float
    events: list  # (tau, EventKind) in local time: the driver records them as Event
    tau_start: np.ndarray  # dense-output pieces: validity start, step origin, step, y0, coef
    tau_old: np.ndarray
    step: np.ndarray
    y_old: np.ndarray
    coef: np.ndarray
    nfev: int
    n_steps: int
    info: dict = field(default_factory=dict)


def simulate_balls(balls, plate, laws, duration, integrate_contact, *, gravity, rest_speed,
                   max_contacts, max_steps, labels=(), info=None) -> Result:  # fmt: skip
    """The rigid solvers' common part (``simulate_rigid`` and its reference): check the
    inputs, make each ball's Pair (``make_pairs``), ``run`` them with the solver's own
    ``integrate_contact`` and return their Result.

    Parameters
    ----------
    balls, plate, laws, duration
        As ``simulate_rigid`` takes them (``laws`` as ``make_pairs`` takes them).
    integrate_contact : callable
        ``(pair, v_in, tau_max, max_steps) -> ContactOutcome``: one contact from
        penetration 0.
    labels : sequence of str
        coal / gangue per ball (empty: from the material, ``default_label``).
    info : dict, optional
        The solver's description, for ``Result.info``.
    """
    pairs = make_pairs(
        balls, plate, laws, duration, gravity=gravity, rest_speed=rest_speed,
        max_contacts=max_contacts, max_steps=max_steps,
    )  # fmt: skip
    contacts = contact_table(balls, laws)
    states = run(pairs, plate, duration, integrate_contact, max_contacts, max_steps)
    trajectories = {
        st.pair.name: st.builder.build(
            st.pair.radius, st.pair.mass, contacts.law(i, PLATE), st.pair.gravity
        )
        for i, st in enumerate(states)
    }
    return Result(
        duration=float(duration),
        particles=balls_as_particles(balls, labels),
        impacts=sorted((imp for st in states for imp in st.impacts), key=lambda m: m.t_start),
        events=sorted((ev for st in states for ev in st.events), key=lambda ev: ev.t),
        leaves=lateral_leaves(balls, plate, duration),
        message="reached the end of the simulation (duration)",
        stats={"nfev": sum(st.nfev for st in states),
               "n_steps": sum(st.n_steps for st in states)},
        info=dict(info or {}),
        states=RigidStates(trajectories, {st.pair.name: st.rest_time for st in states}),
    )  # fmt: skip


def run(pairs, plate, duration, integrate_contact, max_contacts, max_steps) -> list:
    """Simulate all pairs on [0, duration]; ``integrate_contact(pair, v_in, tau_max,
    max_steps)`` -> ContactOutcome integrates one contact starting at penetration 0.
    Returns each ball's state (its impacts, events, trajectory builder, work counts)."""
    states = []
    heap = []
    for i, p in enumerate(pairs):
        st = _BallState(p)
        states.append(st)
        _predict(st, plate, duration, heap, i)
    while heap:
        _, i = heapq.heappop(heap)
        st = states[i]
        _contact(st, integrate_contact, duration, max_contacts, max_steps)
        if not st.done:
            _predict(st, plate, duration, heap, i)

    return states


class _BallState:
    def __init__(self, pair: Pair):
        self.pair = pair
        self.t, self.z, self.vz = 0.0, pair.position[2], pair.velocity[2]
        self.builder = TrajectoryBuilder()
        self.impacts, self.events = [], []
        self.rest_time = math.nan
        self.nfev = self.n_steps = 0
        self.done = False
        self.t_contact = self.v_in = math.nan


def _predict(st: _BallState, plate, duration, heap, i):
    """Close the current flight at the next contact, or run it to the end."""
    p = st.pair
    tau, v_in = time_to_contact(max(st.z - p.radius, 0.0), st.vz, p.gravity)
    tc = st.t + tau
    if not tc < duration or not p.contains(plate, tc):
        st.builder.flight(st.t, st.z, st.vz)  # flies to the end (or falls past the plate)
        st.done = True
        return
    if tau > 0.0:
        st.builder.flight(st.t, st.z, st.vz)
    st.t_contact, st.v_in = tc, v_in
    heapq.heappush(heap, (tc, i))


def _contact(st: _BallState, integrate_contact, duration, max_contacts, max_steps):
    p = st.pair
    tc, v_in = st.t_contact, st.v_in
    index = len(st.impacts) + 1
    if index > max_contacts:
        raise WorkLimitError(
            f"ball {p.name!r}: more than max_contacts={max_contacts} contacts before "
            f"t = {tc:.6g} s; raise max_contacts, or shorten duration (bounces slower than "
            f"rest_speed = {p.rest_speed} m/s count as rest)"
        )
    st.events.append(Event(tc, p.name, EventKind.CONTACT_START, PLATE))
    if p.e_rest > 0.0 and p.excess_energy(0.0, v_in) <= p.e_rest:
        # Touching with (almost) no energy to spare: at rest at once (rule B at first touch).
        _rest(st, tc, index, v_in, 0.0, tc)
        return
    out = integrate_contact(p, v_in, duration - tc, max_steps - st.n_steps)
    st.nfev += out.nfev
    st.n_steps += out.n_steps
    st.builder.contact_pieces(tc, out.tau_start, out.tau_old, out.step, out.y_old, out.coef)
    for tau, kind in out.events:
        st.events.append(Event(tc + tau, p.name, kind, PLATE))
    t_end = tc + out.tau_end
    separated = out.status == End.SEPARATED
    at_rest = out.status == End.REST or (separated and out.v_out < p.rest_speed)
    v_out = {End.SEPARATED: out.v_out, End.REST: 0.0}.get(out.status, math.nan)
    apex = v_out**2 / (2.0 * p.gravity) if p.gravity > 0.0 and separated else None
    st.impacts.append(
        Impact.single_ball(
            p,
            index=index,
            t_start=tc,
            t_end=t_end,
            v_in=v_in,
            v_out=v_out,
            peak_force=out.peak_force,
            t_peak=tc + out.tau_peak,
            max_penetration=out.max_penetration,
            next_apex_height=math.nan if (apex is None or at_rest) else apex,
            at_rest=at_rest,
        )
    )
    if at_rest:
        st.events.append(Event(t_end, p.name, EventKind.REST, PLATE))
        st.builder.rest(t_end, p.radius - p.delta_static, p.mass * p.gravity)
        st.rest_time = t_end
        st.done = True
    elif out.status == End.DURATION:
        st.done = True
    else:
        st.t, st.z, st.vz = t_end, p.radius, out.v_out


def _rest(st, tc, index, v_in, v_out, t_end):
    p = st.pair
    st.impacts.append(
        Impact.single_ball(
            p, index=index, t_start=tc, t_end=t_end, v_in=v_in, v_out=v_out,
            peak_force=p.mass * p.gravity, t_peak=tc, max_penetration=p.delta_static,
            at_rest=True,
        )
    )  # fmt: skip
    st.events.append(Event(t_end, p.name, EventKind.REST, PLATE))
    st.builder.rest(t_end, p.radius - p.delta_static, p.mass * p.gravity)
    st.rest_time = t_end
    st.done = True
