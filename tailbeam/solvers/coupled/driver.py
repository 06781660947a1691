"""The event loop of the two-way coupled solver (``simulate_coupled``).

The compiled kernel (``tailbeam.solvers.coupled.kernel``) steps the balls and the modes and stops at
every event; ``CoupledRun`` records the events and impacts, refreshes each ball's contact point
(its (x, y) at contact: mode shapes and residual compliance there), declares balls at rest and
grows the node buffers. Everything physical happens in the kernel.
"""

import math

import numpy as np

from tailbeam.errors import WorkLimitError
from tailbeam.physics.contact_patch import load_radius
from tailbeam.physics.hertz import hertz_contact_duration
from tailbeam.plate.compliance import Compliance
from tailbeam.progress import task
from tailbeam.results.records import PLATE, Event, EventCode, EventKind
from tailbeam.solvers.coupled import kernel as K
from tailbeam.solvers.coupled import step as S
from tailbeam.solvers.coupled.records import close_contact
from tailbeam.solvers.coupled.result import CoupledResult

NODE_CAPACITY = 65536  # nodes of the first buffers (they double when full)


class CoupledRun:
    """One run of balls on the modal plate ``basis``: state, buffers, records (SI units).

    ``zeta``: damping ratio per mode; the other settings as in ``simulate_coupled``.
    """

    def __init__(self, balls, basis, contacts, duration, *, sensors, zeta, residual_flexibility,
                 steps_per_contact, rest_speed, rest_contact_factor, gravity):  # fmt: skip
        self.balls, self.table, self.basis, self.duration = balls, contacts, basis, duration
        self.sensors, self.zeta, self.gravity = tuple(sensors), zeta, gravity
        self.residual_flexibility = residual_flexibility
        self.steps_per_contact, self.rest_speed = steps_per_contact, rest_speed
        self.rest_contact_factor = rest_contact_factor
        self.omega = np.ascontiguousarray(basis.omega, dtype=float)
        self._ball_arrays(balls, contacts)
        self.compliance = Compliance(basis, residual_flexibility)
        # the load model (tailbeam.physics.contact_patch): a point (Kirchhoff) or the Hertz disc
        # (Mindlin)
        self.rload = [
            load_radius(basis.theory, b, contacts.law(i, PLATE), gravity)
            for i, b in enumerate(balls)
        ]
        self._state(balls)
        self._records(balls)

    def _ball_arrays(self, balls, contacts) -> None:
        self.mass = np.array([b.mass for b in balls])
        self.radius = np.array([b.radius for b in balls])
        self.kk, self.ee, self.cc, self.dd, self.clampf = contacts.plate_arrays()
        self.x0 = np.array([b.position[0] for b in balls])
        self.y0 = np.array([b.position[1] for b in balls])
        self.vx = np.array([b.velocity[0] for b in balls])
        self.vy = np.array([b.velocity[1] for b in balls])
        self.moving = np.hypot(self.vx, self.vy) > 0

    def _state(self, balls) -> None:
        nb, n = len(balls), self.basis.n_modes
        self.q, self.qd = np.zeros(n), np.zeros(n)
        self.z = np.array([b.position[2] for b in balls])
        self.vz = np.array([b.velocity[2] for b in balls])
        self.F = np.zeros(nb)
        self.mode = np.full(nb, S.FLIGHT, dtype=np.int64)
        self.deep = np.zeros(nb, dtype=np.bool_)
        self.cur = np.zeros((4, nb))
        self.hist = np.zeros((2, nb))  # last step's force slope (N/s) and length (s), per ball
        self.cur[0] = self.radius - self.z
        self.cur[1] = -self.vz
        self.cur[3] = self.vz
        shapes = [self.shape(b, self.x0[b], self.y0[b]) for b in range(nb)]
        self.phi = np.ascontiguousarray(shapes, dtype=float)
        self.cres = np.zeros(nb)
        self.h = np.zeros(nb)
        for b in range(nb):
            if not self.basis.plate.contains(self.x0[b], self.y0[b]):
                self.mode[b] = S.OFF
            drop = 2 * self.gravity * max(self.z[b] - self.radius[b], 0)
            self.h[b] = self.nominal_step(b, math.sqrt(self.vz[b] ** 2 + drop))

    def _records(self, balls) -> None:
        nb, cap = len(balls), NODE_CAPACITY
        self.bufs = (np.empty(cap), *(np.empty((cap, nb)) for _ in range(4)))
        bt, bz, bvz, bF, bd = self.bufs
        bt[0], bz[0], bvz[0], bF[0], bd[0] = 0.0, self.z, self.vz, self.F, self.cur[0]
        self.nbuf = 1
        self.seg_phase = [0]
        self.phis = [self.phi.copy()]
        self.events, self.impacts, self.open, self.contact_points = [], [], {}, []
        self.counts = [0] * nb
        self.rest_time = {b.name: math.nan for b in balls}
        self.evout = np.zeros(2, dtype=np.int64)
        self.t, self.total_steps = 0.0, 0

    # -- geometry ----------------------------------------------------------------------------

    def shape(self, b, px, py):
        """Mode shapes under ball b's load centred at (px, py) m."""
        return self.basis.load_deflection([[px, py]], self.rload[b])[0]

    def xy(self, b, t):
        """Ball b's (x, y) at time t (s): its lateral motion is uniform."""
        return self.x0[b] + self.vx[b] * t, self.y0[b] + self.vy[b] * t

    def nominal_step(self, b, speed):
        """Step (s) of ball b's contact at approach speed ``speed`` (m/s)."""
        speed = max(abs(speed), 1e-3)
        dur = hertz_contact_duration(self.mass[b], speed, self.kk[b], self.ee[b])
        return dur / self.steps_per_contact

    # -- the loop ----------------------------------------------------------------------------

    def solve(self, max_steps: int, max_events: int) -> CoupledResult:
        """Integrate to ``duration`` and return the result (WorkLimitError past the limits)."""
        with task(
            f"simulating {self.duration:g} s", total=1e3 * self.duration, unit="ms simulated"
        ) as bar:
            t_shown = 0.0
            while self.t < self.duration:
                if len(self.events) > max_events:
                    raise WorkLimitError(
                        f"more than max_events={max_events} events; raise max_events"
                    )
                code = self._advance(self._refresh_points(), max_steps)
                bar.update(1e3 * (self.t - t_shown))
                t_shown = self.t
                self._on_stop(code, max_steps)
        for b, info in self.open.items():  # contacts still open at the end
            self.impacts.append(self._close(info, b, math.nan, at_rest=False))
        self.impacts.sort(key=lambda imp: (imp.t_start, imp.ball))
        return self._result()

    def _refresh_points(self) -> float:
        """Contact points of flying balls (lateral motion), balls leaving the plate; returns
        the time (s) the kernel may run to."""
        t, t_stop, mode = self.t, self.duration, self.mode
        for b in range(len(self.balls)):
            if mode[b] == S.FLIGHT and self.moving[b]:
                px, py = self.xy(b, t)
                if not self.basis.plate.contains(px, py):
                    mode[b] = S.OFF
                    continue
                self.phi[b] = self.shape(b, px, py)
                # refresh again after 1 mm of lateral travel (mode shapes vary on ~ cm scales)
                t_stop = min(t_stop, t + 1e-3 / math.hypot(self.vx[b], self.vy[b]))
            if mode[b] in (S.CONTACT, S.CLAMPED):
                t_stop = min(t_stop, self.open[b]["t_start"] + self.open[b]["t_limit"])
        self.phis.append(self.phi.copy())
        self.seg_phase[-1] = len(self.phis) - 1
        return t_stop

    def _advance(self, t_stop: float, max_steps: int) -> int:
        """Run the kernel from t to t_stop or its first event; returns its status code."""
        ctx = (self.omega, self.zeta, self.phi, self.cres, self.mass, self.radius, self.kk,
               self.ee, self.cc, self.dd, self.clampf)  # fmt: skip
        st = (self.q, self.qd, self.z, self.vz, self.F, self.mode, self.deep, self.cur, self.hist)
        code, self.t, nbuf_new, steps = K.run(
            ctx, st, self.t, t_stop, self.h, max_steps - self.total_steps, self.gravity,
            self.bufs, self.nbuf, self.evout,
        )  # fmt: skip
        self.total_steps += steps
        self.seg_phase.extend([len(self.phis) - 1] * (nbuf_new - self.nbuf))
        self.nbuf = nbuf_new
        return code

    def _on_stop(self, code: int, max_steps: int) -> None:
        """Act on the kernel's status: grow buffers, limits, time limits, or an event."""
        if code == K.ST_FULL:
            self.bufs = tuple(np.concatenate([a, np.empty_like(a)]) for a in self.bufs)
        elif code == K.ST_STEPS:
            raise WorkLimitError(f"more than max_steps={max_steps} steps; raise max_steps")
        elif code == K.ST_FAIL:
            raise WorkLimitError(
                f"the contact Newton iteration failed to converge at t = {self.t:.9g} s; "
                "raise steps_per_contact"
            )
        elif code == K.ST_STOP:
            self._time_limits()
        else:
            self._on_event(int(self.evout[0]), int(self.evout[1]))

    def _time_limits(self) -> None:
        """Persistent contacts that reached their time limit come to rest."""
        t = self.t
        for b in range(len(self.balls)):
            info = self.open.get(b)
            if self.mode[b] in (S.CONTACT, S.CLAMPED) and t >= info["t_start"] + (
                info["t_limit"] * (1 - 1e-12)
            ):
                self._rest(b)
                self.impacts.append(self._close(self.open.pop(b), b, 0.0, at_rest=True))
                self._mark_rest(b)

    def _on_event(self, kind: int, b: int) -> None:
        self.events.append(Event(self.t, self.balls[b].name, EventCode(kind).kind, PLATE))
        if kind == EventCode.CONTACT_START:
            self._start(b)
        elif kind == EventCode.CONTACT_END:
            self._end(b)

    def _start(self, b: int) -> None:
        """Ball b touches the plate: its contact point, step and residual compliance there."""
        t = self.t
        px, py = self.xy(b, t)
        self.phi[b] = self.shape(b, px, py)
        self.contact_points.append((t, b, px, py, self.rload[b]))
        w_rel = float(self.phi[b] @ self.qd)
        self.h[b] = self.nominal_step(b, max(w_rel - self.vz[b], 1e-6))
        self.cres[b] = self.compliance(px, py, self.rload[b])
        self.counts[b] += 1
        self.open[b] = {
            "index": self.counts[b],
            "t_start": t,
            "v_in": -self.vz[b],
            "node": self.nbuf - 1,
            "t_limit": self.rest_contact_factor * self.h[b] * self.steps_per_contact,
        }

    def _end(self, b: int) -> None:
        """Ball b leaves the plate: record the impact; a slow rebound comes to rest."""
        info = self.open.pop(b)
        v_out = self.vz[b]
        at_rest = v_out < self.rest_speed
        self.impacts.append(self._close(info, b, v_out, at_rest=at_rest, z=self.z[b]))
        self.cres[b] = 0.0
        if at_rest:
            self._rest(b)
            self._mark_rest(b)
        else:
            self.h[b] = self.nominal_step(b, v_out)

    def _close(self, info, b, v_out, *, at_rest, z=math.nan):
        return close_contact(
            info, b, self.balls[b], self.t, v_out, self.bufs, self.nbuf, self.radius[b],
            self.gravity, at_rest=at_rest, z=z,
        )  # fmt: skip

    def _rest(self, b: int) -> None:
        """Ball b sits on the plate from now on: a dead weight m g at its contact point."""
        mg = self.balls[b].mass * self.gravity
        w = float(self.phi[b] @ self.q)
        self.mode[b] = S.REST
        self.z[b] = self.radius[b] - self.table.law(b, PLATE).static_penetration(mg) + w
        self.vz[b] = 0.0
        self.F[b] = mg
        self.cur[:, b] = 0.0

    def _mark_rest(self, b: int) -> None:
        """Record ball b's rest (time, event) and a node at this instant."""
        name = self.balls[b].name
        self.rest_time[name] = self.t
        self.events.append(Event(self.t, name, EventKind.REST, PLATE))
        bt, bz, bvz, bF, bd = self.bufs
        if self.nbuf >= len(bt):
            raise WorkLimitError("node buffer full at a rest declaration; raise max_steps")
        i = self.nbuf
        bt[i], bz[i], bvz[i], bF[i], bd[i] = self.t, self.z, self.vz, self.F, self.cur[0]
        self.seg_phase.append(self.seg_phase[-1])
        self.nbuf += 1

    def _result(self) -> CoupledResult:
        n = self.nbuf
        return CoupledResult(
            balls=self.balls,
            laws=self.table.plate_laws(),
            basis=self.basis,
            duration=self.duration,
            gravity=self.gravity,
            zeta=self.zeta,
            impacts=self.impacts,
            events=self.events,
            rest_time=self.rest_time,
            nodes=tuple(a[:n].copy() for a in self.bufs),
            seg_phase=np.asarray(self.seg_phase[:n], dtype=np.int64),
            phis=np.ascontiguousarray(np.array(self.phis)),
            sensors=self.sensors,
            contact_points=tuple(self.contact_points),
            n_steps=self.total_steps,
            status=0,
            message="reached the end of the simulated time",
            info={
                "coupling": "two-way",
                "residual_flexibility": self.residual_flexibility,
                "steps_per_contact": self.steps_per_contact,
                "n_modes": self.basis.n_modes,
            },
        )
