"""What a coupled (flexible-plate) simulation returns.

The same attributes as ``tailbeam.rigid.RigidResult`` (impacts, events, rest_time, sample,
time_grid, n_steps, status, message) plus the plate: ``modal_sample`` / ``plate_sample`` give the
exact modal state and the deflection, velocity and acceleration at any points and times (closed
form between force nodes), and ``sensor_signals`` the accelerometer outputs.

The solution is stored as nodes: at each node time the ball heights, speeds and contact forces;
the force is linear in time between nodes, so the balls are cubic and the modes exact there.
"""

import math
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from tailbeam.coupled.propagator import replay
from tailbeam.errors import InputError


@dataclass(eq=False)
class CoupledResult:
    """Result of ``simulate_coupled``; see the module docstring."""

    balls: tuple
    laws: tuple
    basis: object
    duration: float
    gravity: float
    zeta: np.ndarray
    impacts: list
    events: list
    rest_time: dict
    nodes: tuple = field(repr=False)  # (t, z, vz, F, delta)
    seg_phase: np.ndarray = field(repr=False)
    phis: np.ndarray = field(repr=False)
    sensors: tuple = ()
    n_steps: int = 0
    status: int = 0
    message: str = ""
    info: dict = field(default_factory=dict)

    @property
    def nfev(self) -> int:
        """Contact-law evaluations are part of each step's Newton solve; counted as steps."""
        return self.n_steps

    def impacts_of(self, name: str) -> list:
        self._check_name(name)
        return [imp for imp in self.impacts if imp.ball == name]

    def events_of(self, name: str, kind: str | None = None) -> list:
        return [(t, k) for t, b, k in self.events if b == name and (kind is None or k == kind)]

    def _check_name(self, name):
        if name not in [b.name for b in self.balls]:
            raise InputError("name", f"no ball called {name!r}")

    def sample(self, times) -> dict:
        """Ball states at ``times`` (s, within [0, duration]): name -> {"z" (m), "vz" (m/s),
        "force" (N)} arrays; exact (cubic between force nodes, closed form in flight)."""
        t = np.atleast_1d(np.asarray(times, dtype=float))
        if t.ndim != 1 or not np.all(np.isfinite(t)):
            raise InputError("times", "must be a 1-D array of finite times in s")
        if t.size and (t.min() < 0.0 or t.max() > self.duration * (1 + 1e-12)):
            raise InputError("times", f"must lie within [0, duration = {self.duration!r}] s")
        tn, zn, vn, fn, _dn = self.nodes
        k = np.clip(np.searchsorted(tn, t, side="right") - 1, 0, len(tn) - 1)
        k1 = np.minimum(k + 1, len(tn) - 1)
        s = t - tn[k]
        span = tn[k1] - tn[k]
        out = {}
        for b, ball in enumerate(self.balls):
            f0 = fn[k, b]
            f1 = np.where(span > 0, fn[k1, b], f0)
            slope = np.where(span > 0, (f1 - f0) / np.where(span > 0, span, 1.0), 0.0)
            m = ball.mass
            # resting balls carry F = m g with zero acceleration: the same formula gives that
            z = zn[k, b] + vn[k, b] * s - 0.5 * self.gravity * s**2
            z = z + (f0 * s**2 / 2 + slope * s**3 / 6) / m
            vz = vn[k, b] - self.gravity * s + (f0 * s + slope * s**2 / 2) / m
            out[ball.name] = {"z": z, "vz": vz, "force": f0 + slope * s}
        return out

    def time_grid(self, sample_rate: float) -> np.ndarray:
        """Uniform times at sample_rate (Hz) on [0, duration] merged with every peak time."""
        if not sample_rate > 0:
            raise InputError("sample_rate", f"must be > 0, got {sample_rate!r}")
        n = int(math.floor(self.duration * sample_rate + 1e-9)) + 1
        grid = np.arange(n) / sample_rate
        peaks = [imp.t_peak for imp in self.impacts if math.isfinite(imp.t_peak)]
        return np.unique(np.concatenate([grid, np.asarray(peaks, dtype=float)]))

    def modal_sample(self, times):
        """(q, q', q'') of every mode at ``times`` (s), each (n_modes, len(times)); exact."""
        return self._replay(times, None)

    def _replay(self, times, points):
        t = np.atleast_1d(np.asarray(times, dtype=float))
        order = np.argsort(t, kind="stable")
        ts = np.ascontiguousarray(t[order])
        modal = points is None
        rows = self.basis.n_modes if modal else points.shape[0]
        if modal:
            points = np.zeros((1, self.basis.n_modes))
        q, qd, qdd = (np.empty((rows, len(t))) for _ in range(3))
        tn, _z, _v, fn, _d = self.nodes
        omega = np.ascontiguousarray(self.basis.omega, dtype=float)
        zeta = np.ascontiguousarray(self.zeta)
        fn = np.ascontiguousarray(fn)
        replay(omega, zeta, tn, fn, self.seg_phase, self.phis, ts, q, qd, qdd, points, modal)
        if np.all(order[1:] > order[:-1]):
            return q, qd, qdd
        inv = np.empty_like(order)
        inv[order] = np.arange(len(order))
        return q[:, inv], qd[:, inv], qdd[:, inv]

    def plate_sample(self, times, points) -> dict:
        """Plate deflection "w" (m, + up), velocity "v" (m/s), acceleration "a" (m/s^2) at
        points (p, 2) m and times (s): each array (p, len(times))."""
        phi = np.ascontiguousarray(self.basis.deflection(points), dtype=float)
        w, v, a = self._replay(times, phi)
        return {"w": w, "v": v, "a": a}

    def plate_energy(self, times) -> np.ndarray:
        """Vibration energy of the plate's kept modes, J, at ``times``."""
        q, qd, _ = self.modal_sample(times)
        om = np.asarray(self.basis.omega)[:, None]
        return 0.5 * np.sum(qd**2 + om**2 * q**2, axis=0)

    def true_acceleration(self, point, times) -> np.ndarray:
        """Plate acceleration normal to the plate (m/s^2) at one point (x, y), before any sensor."""
        return self.plate_sample(times, [point])["a"][0]

    @cached_property
    def sensor_outputs(self) -> dict:
        """name -> tailbeam.sensor.SensorOutput for every sensor (computed on first use)."""
        from tailbeam.sensor import measure

        return {
            s.name: measure(s, lambda t, p=s.position: self.true_acceleration(p, t), self.duration,
                            max_frequency_hz=float(np.max(self.basis.frequencies_hz)))
            for s in self.sensors
        }  # fmt: skip

    @property
    def sensor_signals(self) -> dict:
        """name -> (t array s, acceleration array m/s^2) as sampled by each sensor."""
        return {name: (out.t, out.acceleration) for name, out in self.sensor_outputs.items()}
