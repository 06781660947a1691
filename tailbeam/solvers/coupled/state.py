"""What the coupled driver keeps during a run: the balls' constants (``CoupledBalls``), the
state the compiled kernel advances (``KernelState``) and the recorded solution
(``NodeBuffers``)."""

import math

import numpy as np

from tailbeam.errors import WorkLimitError
from tailbeam.physics.contact_patch import load_radius
from tailbeam.physics.contacts import PLATE
from tailbeam.physics.hertz import hertz_contact_duration
from tailbeam.solvers.coupled import step as S

NODE_CAPACITY = 65536  # nodes of the first buffers (they double when full)


class CoupledBalls:
    """The balls on the modal plate ``basis``: masses (kg), radii (m), their plate laws as
    arrays (``ContactTable.plate_arrays``), uniform lateral motion, and the load model (a
    point on a Kirchhoff basis, the Hertz disc on a Mindlin one:
    ``tailbeam.physics.contact_patch``)."""

    def __init__(self, balls, contacts, basis, gravity: float, steps_per_contact: int):
        self.balls, self.table, self.basis = balls, contacts, basis
        self.steps_per_contact = steps_per_contact
        self.mass = np.array([b.mass for b in balls])
        self.radius = np.array([b.radius for b in balls])
        self.kk, self.ee, self.cc, self.dd, self.clampf = contacts.plate_arrays()
        self.x0 = np.array([b.position[0] for b in balls])
        self.y0 = np.array([b.position[1] for b in balls])
        self.vx = np.array([b.velocity[0] for b in balls])
        self.vy = np.array([b.velocity[1] for b in balls])
        self.moving = np.hypot(self.vx, self.vy) > 0
        self.rload = [load_radius(basis.theory, b, contacts.law(i, PLATE), gravity)
                      for i, b in enumerate(balls)]  # fmt: skip

    def __len__(self) -> int:
        return len(self.balls)

    def shape(self, b: int, px: float, py: float) -> np.ndarray:
        """Mode shapes under ball b's load centred at (px, py) m."""
        return self.basis.load_deflection([[px, py]], self.rload[b])[0]

    def xy(self, b: int, t: float) -> tuple:
        """Ball b's (x, y) at time t (s): its lateral motion is uniform."""
        return self.x0[b] + self.vx[b] * t, self.y0[b] + self.vy[b] * t

    def nominal_step(self, b: int, speed: float) -> float:
        """Step (s) of ball b's contact at approach speed ``speed`` (m/s)."""
        speed = max(abs(speed), 1e-3)
        dur = hertz_contact_duration(self.mass[b], speed, self.kk[b], self.ee[b])
        return dur / self.steps_per_contact

    def static_height(self, b: int, gravity: float) -> float:
        """Height (m) of ball b's centre resting on the undeflected plate."""
        mg = self.balls[b].mass * gravity
        return self.radius[b] - self.table.law(b, PLATE).static_penetration(mg)


class KernelState:
    """The state the compiled kernel advances (``kernel.run``), SI units: the modes q, q'
    (m sqrt(kg), m sqrt(kg)/s); per ball its height z, vertical speed vz, contact force F,
    mode (``step.FLIGHT``, ...), whether its penetration is past d (``deep``), its contact
    quantities ``cur``, its last step's force slope and length ``hist``, the mode shapes
    ``phi`` and residual compliance ``cres`` under it and its step ``h``; the time ``t``."""

    def __init__(self, balls: CoupledBalls, n_modes: int, gravity: float):
        nb = len(balls)
        self.q, self.qd = np.zeros(n_modes), np.zeros(n_modes)
        self.z = np.array([b.position[2] for b in balls.balls])
        self.vz = np.array([b.velocity[2] for b in balls.balls])
        self.F = np.zeros(nb)
        self.mode = np.full(nb, S.FLIGHT, dtype=np.int64)
        self.deep = np.zeros(nb, dtype=np.bool_)
        self.cur = np.zeros((4, nb))
        self.hist = np.zeros((2, nb))  # last step's force slope (N/s) and length (s), per ball
        self.cur[0] = balls.radius - self.z
        self.cur[1] = -self.vz
        self.cur[3] = self.vz
        shapes = [balls.shape(b, balls.x0[b], balls.y0[b]) for b in range(nb)]
        self.phi = np.ascontiguousarray(shapes, dtype=float)
        self.cres = np.zeros(nb)
        self.h = np.zeros(nb)
        for b in range(nb):
            if not balls.basis.plate.contains(balls.x0[b], balls.y0[b]):
                self.mode[b] = S.OFF
            drop = 2 * gravity * max(self.z[b] - balls.radius[b], 0)
            self.h[b] = balls.nominal_step(b, math.sqrt(self.vz[b] ** 2 + drop))
        self.t, self.steps = 0.0, 0
        self.evout = np.zeros(2, dtype=np.int64)  # the kernel's event: (code, ball)

    def arrays(self) -> tuple:
        """(q, qd, z, vz, F, mode, deep, cur, hist): the kernel's ``st``."""
        return (self.q, self.qd, self.z, self.vz, self.F, self.mode, self.deep, self.cur,
                self.hist)  # fmt: skip

    def touching(self, b: int) -> bool:
        """Ball b is in contact (CONTACT or CLAMPED)."""
        return self.mode[b] in (S.CONTACT, S.CLAMPED)


class NodeBuffers:
    """The recorded solution: at each node time the balls' heights, speeds, contact forces and
    penetrations (buffers that double when full) and the row of ``phis`` (the mode shapes
    under the balls) valid from each node."""

    def __init__(self, state: KernelState):
        nb, cap = len(state.z), NODE_CAPACITY
        self.bufs = (np.empty(cap), *(np.empty((cap, nb)) for _ in range(4)))
        self.nbuf = 0
        self.seg_phase = []
        self.phis = [state.phi.copy()]
        self.append(0.0, state, 0)

    def grow(self) -> None:
        """Double the buffers."""
        self.bufs = tuple(np.concatenate([a, np.empty_like(a)]) for a in self.bufs)

    def new_phase(self, phi: np.ndarray) -> None:
        """The mode shapes under the balls from the last node on."""
        self.phis.append(phi.copy())
        self.seg_phase[-1] = len(self.phis) - 1

    def advanced(self, nbuf: int) -> None:
        """The kernel wrote the nodes up to ``nbuf`` (in the current phase)."""
        self.seg_phase.extend([len(self.phis) - 1] * (nbuf - self.nbuf))
        self.nbuf = nbuf

    def append(self, t: float, state: KernelState, phase: int) -> None:
        """A node at time t (s) of ``state``, in row ``phase`` of ``phis``."""
        bt, bz, bvz, bF, bd = self.bufs
        if self.nbuf >= len(bt):
            raise WorkLimitError("node buffer full at a rest declaration; shorten duration")
        i = self.nbuf
        bt[i], bz[i], bvz[i], bF[i], bd[i] = t, state.z, state.vz, state.F, state.cur[0]
        self.seg_phase.append(phase)
        self.nbuf += 1

    def nodes(self) -> tuple:
        """(t (k,), z, vz, F, delta (k, nb)): copies of the nodes written."""
        return tuple(a[: self.nbuf].copy() for a in self.bufs)

    def phases(self) -> tuple:
        """(seg_phase (k,) int, phis (phases, nb, n)) as the replay takes them."""
        seg = np.asarray(self.seg_phase[: self.nbuf], dtype=np.int64)
        return seg, np.ascontiguousarray(np.array(self.phis))
