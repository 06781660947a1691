"""What a coupled (flexible-plate) simulation returns.

A ``tailbeam.results.result.Result`` with the same attributes as ``tailbeam.solvers.rigid.RigidResult``
(impacts, events, rest_time, sample, time_grid, n_steps, status, message, impacts_table,
particles_table) plus the plate: ``modal_sample`` / ``plate_sample`` give the
exact modal state and the deflection, velocity and acceleration at any points and times (closed
form between force nodes), and ``sensor_signals`` the accelerometer outputs.

The solution is stored as nodes: at each node time the ball heights, speeds and contact forces;
the force is linear in time between nodes, so the balls are cubic and the modes exact there.
"""

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from tailbeam.results.result import BallsResult
from tailbeam.solvers.plate_loads.propagator import replay


@dataclass(eq=False)
class CoupledResult(BallsResult):
    """Result of ``simulate_coupled``; see the module docstring. labels: coal / gangue per
    ball (empty: ``tailbeam.scene.default_label``)."""

    plate_model = "modal"

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
    contact_points: tuple = ()  # (t_start s, ball index, x m, y m, load radius m) per contact
    n_steps: int = 0
    status: int = 0
    message: str = ""
    info: dict = field(default_factory=dict)
    _cross: dict = field(default_factory=dict, repr=False)  # residual cross compliances
    labels: tuple = ()

    @property
    def nfev(self) -> int:
        """Contact-law evaluations are part of each step's Newton solve; counted as steps."""
        return self.n_steps

    def _plate(self):
        return self.basis.plate

    def sample(self, times) -> dict:
        """Ball states at ``times`` (s, within [0, duration]): name -> {"z" (m), "vz" (m/s),
        "force" (N)} arrays; exact (cubic between force nodes, closed form in flight)."""
        t = self._times(times, slack=1e-12)
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

    def plate_sample(self, times, points, *, quasi_static: bool = True) -> dict:
        """Plate deflection "w" (m, + up), velocity "v" (m/s), acceleration "a" (m/s^2) at
        points (p, 2) m and times (s): each array (p, len(times)). The kept modes exactly,
        plus (quasi_static, with residual flexibility on) the truncated modes' quasi-static
        response (``quasi_static_sample``)."""
        points = np.atleast_2d(np.asarray(points, dtype=float))
        phi = np.ascontiguousarray(self.basis.deflection(points), dtype=float)
        w, v, a = self._replay(times, phi)
        if quasi_static and self.has_quasi_static:
            qs = self.quasi_static_sample(times, points)
            w, v, a = w + qs["w"], v + qs["v"], a + qs["a"]
        return {"w": w, "v": v, "a": a}

    @property
    def has_quasi_static(self) -> bool:
        """True if the truncated modes' quasi-static response is added at points (residual
        flexibility on and a basis that knows its static cross compliance)."""
        return bool(
            self.info.get("residual_flexibility")
            and self.contact_points
            and getattr(self.basis, "static_deflection_at", None) is not None
        )

    def quasi_static_sample(self, times, points) -> dict:
        """The truncated modes' quasi-static (mode-acceleration) response at points (p, 2) m:
        w = -G_res F(t) (F pushes the plate down), G_res the residual cross compliance between
        the ball's contact and each point (ModalBasis.residual_cross_compliance, with the
        contact's load model).
        v and a are its central differences over +-h: h is the spacing of uniform ``times``
        (so a sampled record is the exact second difference of the sampled force: gain
        sinc^2(f h), no aliasing of the force's kinks), else 1/(8 f_top). Arrays (p, len)."""
        t = np.atleast_1d(np.asarray(times, dtype=float))
        points = np.atleast_2d(np.asarray(points, dtype=float))
        out = {k: np.zeros((len(points), len(t))) for k in ("w", "v", "a")}
        h = _difference_step(t, float(np.max(self.basis.frequencies_hz)))
        tn, _z, _v, fn, _d = self.nodes
        for b in range(len(self.balls)):
            mine = [c for c in self.contact_points if c[1] == b]
            if not mine:
                continue
            # each time belongs to the last contact started by t + h (its differences use it)
            which = np.searchsorted([c[0] for c in mine], t + h, side="right") - 1
            which = np.maximum(which, 0)
            f = [np.interp(t + s, tn, fn[:, b], left=0.0) for s in (-h, 0.0, h)]
            parts = (f[1], (f[2] - f[0]) / (2 * h), (f[2] - 2 * f[1] + f[0]) / h**2)
            for k, (_ts, _b, x, y, r) in enumerate(mine):
                sel = which == k
                if not sel.any():
                    continue
                g = -self._cross_compliance(x, y, r, points)  # the ball pushes the plate down
                for key, part in zip(("w", "v", "a"), parts, strict=True):
                    out[key][:, sel] += g[:, None] * part[sel]
        return out

    def _cross_compliance(self, x, y, r, points):
        key = (x, y, r, points.tobytes())
        if key not in self._cross:
            self._cross[key] = self.basis.residual_cross_compliance((x, y), points, r)
        return self._cross[key]

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
        """name -> tailbeam.signals.sensor.SensorOutput for every sensor (computed on first use)."""
        from tailbeam.signals.sensor import measure

        return {
            s.name: measure(s, lambda t, p=s.position: self.true_acceleration(p, t), self.duration,
                            max_frequency_hz=float(np.max(self.basis.frequencies_hz)))
            for s in self.sensors
        }  # fmt: skip


def _difference_step(t, f_top):
    """Spacing of uniform times t (s), else 1/(8 f_top) s (see quasi_static_sample)."""
    if len(t) >= 3:
        d = np.diff(t)
        if d[0] > 0 and np.all(np.abs(d - d[0]) <= 1e-6 * d[0]):
            return float(d[0])
    return 1.0 / (8.0 * f_top)
