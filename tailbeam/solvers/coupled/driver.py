"""The event loop of the two-way coupled solver (``simulate_coupled``).

The compiled kernel (``tailbeam.solvers.coupled.kernel``) steps the balls and the modes and
stops at every event; ``CoupledRun`` records the events and impacts (``records.ContactBook``),
refreshes each ball's contact point (its (x, y) at contact: mode shapes and residual compliance
there), declares balls at rest and grows the node buffers (``state.NodeBuffers``). Everything
physical happens in the kernel.
"""

import math

import numpy as np

from tailbeam.errors import WorkLimitError
from tailbeam.plate.compliance import Compliance
from tailbeam.progress import task
from tailbeam.results.records import EventCode
from tailbeam.results.result import Result
from tailbeam.solvers.coupled import kernel as K
from tailbeam.solvers.coupled import step as S
from tailbeam.solvers.coupled.records import ContactBook, close_contact
from tailbeam.solvers.coupled.replay import ModalReplay, NodeStates
from tailbeam.solvers.coupled.state import CoupledBalls, KernelState, NodeBuffers
from tailbeam.solvers.numerics.flight import lateral_leaves
from tailbeam.streams.generator import balls_as_particles


class CoupledRun:
    """One run of balls on the modal plate ``basis`` (SI units): the balls' constants, the
    kernel's state, the recorded solution and the records, and the loop that advances them.

    ``zeta``: damping ratio per mode; ``labels`` and ``info`` as ``simulate_coupled`` takes
    them; the other settings as in ``simulate_coupled``.
    """

    def __init__(self, balls, basis, contacts, duration, *, sensors, zeta, residual_flexibility,
                 steps_per_contact, rest_speed, rest_contact_factor, gravity, labels=(),
                 info=None):  # fmt: skip
        self.basis, self.duration, self.gravity = basis, duration, gravity
        self.sensors, self.labels, self.extra_info = tuple(sensors), tuple(labels), dict(info or {})
        self.zeta, self.omega = zeta, np.ascontiguousarray(basis.omega, dtype=float)
        self.residual_flexibility = residual_flexibility
        self.rest_speed, self.rest_contact_factor = rest_speed, rest_contact_factor
        self.balls = CoupledBalls(balls, contacts, basis, gravity, steps_per_contact)
        self.compliance = Compliance(basis, residual_flexibility)
        self.state = KernelState(self.balls, basis.n_modes, gravity)
        self.nodes = NodeBuffers(self.state)
        self.book = ContactBook(balls)

    # -- the loop ----------------------------------------------------------------------------

    def solve(self, max_steps: int, max_events: int) -> Result:
        """Integrate to ``duration`` and return the result (WorkLimitError past the limits)."""
        st = self.state
        with task(
            f"simulating {self.duration:g} s", total=1e3 * self.duration, unit="ms simulated"
        ) as bar:
            t_shown = 0.0
            while st.t < self.duration:
                if len(self.book.events) > max_events:
                    raise WorkLimitError(
                        f"more than max_events = {max_events} events by t = {st.t:.6g} s; "
                        "shorten duration"
                    )
                code = self._advance(self._refresh_points(), max_steps)
                bar.update(1e3 * (st.t - t_shown))
                t_shown = st.t
                self._on_stop(code, max_steps)
        for b, info in self.book.open.items():  # contacts still open at the end
            self.book.impacts.append(self._close(info, b, math.nan, at_rest=False))
        self.book.impacts.sort(key=lambda imp: (imp.t_start, imp.ball))
        return self._result()

    def _refresh_points(self) -> float:
        """Contact points of flying balls (lateral motion), balls leaving the plate; returns
        the time (s) the kernel may run to."""
        st, balls = self.state, self.balls
        t, t_stop, mode = st.t, self.duration, st.mode
        for b in range(len(balls)):
            if mode[b] == S.FLIGHT and balls.moving[b]:
                px, py = balls.xy(b, t)
                if not self.basis.plate.contains(px, py):
                    mode[b] = S.OFF
                    continue
                st.phi[b] = balls.shape(b, px, py)
                # refresh again after 1 mm of lateral travel (mode shapes vary on ~ cm scales)
                t_stop = min(t_stop, t + 1e-3 / math.hypot(balls.vx[b], balls.vy[b]))
            if mode[b] in (S.CONTACT, S.CLAMPED):
                info = self.book.open[b]
                t_stop = min(t_stop, info["t_start"] + info["t_limit"])
        self.nodes.new_phase(st.phi)
        return t_stop

    def _advance(self, t_stop: float, max_steps: int) -> int:
        """Run the kernel from t to t_stop or its first event; returns its status code."""
        st, b = self.state, self.balls
        ctx = (self.omega, self.zeta, st.phi, st.cres, b.mass, b.radius, b.kk, b.ee, b.cc, b.dd,
               b.clampf)  # fmt: skip
        code, st.t, nbuf_new, steps = K.run(
            ctx, st.arrays(), st.t, t_stop, st.h, max_steps - st.steps, self.gravity,
            self.nodes.bufs, self.nodes.nbuf, st.evout,
        )  # fmt: skip
        st.steps += steps
        self.nodes.advanced(nbuf_new)
        return code

    def _on_stop(self, code: int, max_steps: int) -> None:
        """Act on the kernel's status: grow buffers, limits, time limits, or an event."""
        if code == K.ST_FULL:
            self.nodes.grow()
        elif code == K.ST_STEPS:
            raise WorkLimitError(
                f"more than max_steps = {max_steps} steps by t = {self.state.t:.6g} s; "
                "shorten duration"
            )
        elif code == K.ST_FAIL:
            raise WorkLimitError(
                f"the contact forces could not be solved at t = {self.state.t:.9g} s, even on a "
                f"step halved {K.MAX_HALVINGS} times (a defect of the solver: please report "
                "the scene)"
            )
        elif code == K.ST_STOP:
            self._time_limits()
        else:
            self._on_event(int(self.state.evout[0]), int(self.state.evout[1]))

    def _time_limits(self) -> None:
        """Persistent contacts that reached their time limit come to rest."""
        st = self.state
        for b in range(len(self.balls)):
            info = self.book.open.get(b)
            if st.touching(b) and st.t >= info["t_start"] + (info["t_limit"] * (1 - 1e-12)):
                self._rest(b)
                self.book.impacts.append(self._close(self.book.open.pop(b), b, 0.0, at_rest=True))
                self._mark_rest(b)

    def _on_event(self, kind: int, b: int) -> None:
        self.book.event(self.state.t, b, EventCode(kind).kind)
        if kind == EventCode.CONTACT_START:
            self._start(b)
        elif kind == EventCode.CONTACT_END:
            self._end(b)

    def _start(self, b: int) -> None:
        """Ball b touches the plate: its contact point, step and residual compliance there."""
        st, balls = self.state, self.balls
        t = st.t
        px, py = balls.xy(b, t)
        st.phi[b] = balls.shape(b, px, py)
        w_rel = float(st.phi[b] @ st.qd)
        st.h[b] = balls.nominal_step(b, max(w_rel - st.vz[b], 1e-6))
        st.cres[b] = self.compliance(px, py, balls.rload[b])
        t_limit = self.rest_contact_factor * st.h[b] * balls.steps_per_contact
        self.book.start(b, t, (px, py, balls.rload[b]), -st.vz[b], self.nodes.nbuf - 1, t_limit)

    def _end(self, b: int) -> None:
        """Ball b leaves the plate: record the impact; a slow rebound comes to rest."""
        st = self.state
        info = self.book.open.pop(b)
        v_out = st.vz[b]
        at_rest = v_out < self.rest_speed
        self.book.impacts.append(self._close(info, b, v_out, at_rest=at_rest, z=st.z[b]))
        st.cres[b] = 0.0
        if at_rest:
            self._rest(b)
            self._mark_rest(b)
        else:
            st.h[b] = self.balls.nominal_step(b, v_out)

    def _close(self, info, b, v_out, *, at_rest, z=math.nan):
        return close_contact(
            info, b, self.balls.balls[b], self.state.t, v_out, self.nodes.bufs, self.nodes.nbuf,
            self.balls.radius[b], self.gravity, at_rest=at_rest, z=z,
        )  # fmt: skip

    def _rest(self, b: int) -> None:
        """Ball b sits on the plate from now on: a dead weight m g at its contact point."""
        st = self.state
        mg = self.balls.balls[b].mass * self.gravity
        w = float(st.phi[b] @ st.q)
        st.mode[b] = S.REST
        st.z[b] = self.balls.static_height(b, self.gravity) + w
        st.vz[b] = 0.0
        st.F[b] = mg
        st.cur[:, b] = 0.0

    def _mark_rest(self, b: int) -> None:
        """Record ball b's rest (time, event) and a node at this instant."""
        self.book.rest(b, self.state.t)
        self.nodes.append(self.state.t, self.state, self.nodes.seg_phase[-1])

    def _result(self) -> Result:
        nodes = self.nodes.nodes()
        seg_phase, phis = self.nodes.phases()
        balls = self.balls.balls
        return Result(
            duration=self.duration,
            particles=balls_as_particles(balls, self.labels),
            impacts=self.book.impacts,
            events=self.book.events,
            leaves=lateral_leaves(balls, self.basis.plate, self.duration),
            message="reached the end of the simulated time",
            stats={"nfev": self.state.steps, "n_steps": self.state.steps},
            info={
                "coupling": "two-way",
                "residual_flexibility": self.residual_flexibility,
                "steps_per_contact": self.balls.steps_per_contact,
                "n_modes": self.basis.n_modes,
                **self.extra_info,
            },
            sensors=self.sensors,
            states=NodeStates(balls, self.gravity, nodes, self.book.rest_time),
            plate=ModalReplay(self.basis, self.zeta, nodes, seg_phase, phis,
                              tuple(self.book.contact_points), self.residual_flexibility),
        )  # fmt: skip
