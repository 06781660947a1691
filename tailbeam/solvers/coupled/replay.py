"""The solution of a single-ball run on the modal plate, replayed exactly at any time: the
balls' states (``NodeStates``) and the plate's response (``ModalReplay``), the two parts of
its ``tailbeam.Result``.

The solution is stored as nodes: at each node time the ball heights, speeds and contact forces;
the force is linear in time between nodes, so the balls are cubic and the modes exact there.
"""

from dataclasses import dataclass, field

import numpy as np

from tailbeam.signals.sensor import SensorSpec, measure
from tailbeam.solvers.plate_loads.propagator import replay
from tailbeam.solvers.plate_loads.readings import Readings


@dataclass(frozen=True, eq=False)
class NodeStates:
    """The balls' states between force nodes, and when each came to rest.

    Parameters
    ----------
    balls : tuple
        The ``Ball``s, in the column order of the nodes.
    gravity : float
        m/s^2.
    nodes : tuple
        (t (k,) s, z (k, nb) m, vz (k, nb) m/s, F (k, nb) N, delta (k, nb) m).
    rest_time : dict
        Ball name -> time (s) it came to rest, nan if it did not.
    """

    balls: tuple
    gravity: float
    nodes: tuple = field(repr=False)
    rest_time: dict = field(default_factory=dict)

    def sample(self, times) -> dict:
        """Ball states at ``times`` (s): name -> {"z" (m), "vz" (m/s), "force" (N)} arrays;
        exact (cubic between force nodes, closed form in flight)."""
        t = np.asarray(times, dtype=float)
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


@dataclass(eq=False)
class ModalReplay:
    """The modal plate under the balls' contact forces, exact at any time.

    ``modal_sample`` and ``sample`` give the exact modal state and the deflection, velocity
    and acceleration at any points and times (closed form between force nodes); with
    residual flexibility the truncated modes' quasi-static response is added at points.

    Parameters
    ----------
    basis : tailbeam.plate.basis.ModalBasis
        The kept modes.
    zeta : ndarray
        Damping ratio of each mode.
    nodes : tuple
        The force nodes, as ``NodeStates.nodes``.
    seg_phase : ndarray
        Per node, the row of ``phis`` (the balls' mode shapes) valid from it.
    phis : ndarray
        (phases, nb, n) the mode shapes under each ball's load, per phase.
    contact_points : tuple
        (t_start s, ball index, x m, y m, load radius m) per contact.
    residual_flexibility : bool
        Add the truncated modes' quasi-static response at points.
    """

    basis: object
    zeta: np.ndarray
    nodes: tuple = field(repr=False)
    seg_phase: np.ndarray = field(repr=False)
    phis: np.ndarray = field(repr=False)
    contact_points: tuple = ()
    residual_flexibility: bool = False
    _cross: dict = field(default_factory=dict, repr=False)  # residual cross compliances
    _readings: dict = field(default_factory=dict, repr=False)  # plain points on a structure

    def modal_sample(self, times):
        """(q, q', q'') of every mode at ``times`` (s), each (n_modes, len(times)); exact."""
        return self._replay(times, None)

    def modal_coordinates(self, times) -> np.ndarray:
        """(n_modes, len(times)) modal coordinates q (sqrt(kg) m) at ``times`` (s); exact."""
        return self.modal_sample(times)[0]

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

    def sample(self, times, points, *, quasi_static: bool = True) -> dict:
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
            self.residual_flexibility
            and self.contact_points
            and getattr(self.basis, "static_deflection_at", None) is not None
        )

    def channel_sample(self, times, channels, *, quasi_static: bool = True) -> dict:
        """As ``sample``, at sensor channels (single-direction SensorSpecs: any surface point
        and direction, ``tailbeam.solvers.plate_loads.readings``) instead of points."""
        readings = Readings(self.basis, channels)
        w, v, a = self._replay(times, np.ascontiguousarray(readings.shapes(), dtype=float))
        if quasi_static and self.has_quasi_static:
            qs = self.quasi_static_sample(times, channels, cross=readings.residual_cross)
            w, v, a = w + qs["w"], v + qs["v"], a + qs["a"]
        return {"w": w, "v": v, "a": a}

    def quasi_static_sample(self, times, points, *, cross=None) -> dict:
        """The truncated modes' quasi-static (mode-acceleration) response at points (p, 2) m:
        w = -G_res F(t) (F pushes the plate down), G_res the residual cross compliance between
        the ball's contact and each point (ModalBasis.residual_cross_compliance, with the
        contact's load model; on a structure ``Readings.residual_cross`` of the points as
        plain channels, from the cached sensor influences).
        v and a are its central differences over +-h: h is the spacing of uniform ``times``
        (so a sampled record is the exact second difference of the sampled force: gain
        sinc^2(f h), no aliasing of the force's kinks), else 1/(8 f_top). Arrays (p, len).
        ``cross`` (load point (2,), radius -> (p,)) replaces the residual cross compliance
        at points by that of sensor channels (``Readings.residual_cross``; ``points`` then
        lists the channels)."""
        t = np.atleast_1d(np.asarray(times, dtype=float))
        if cross is None:
            points = np.atleast_2d(np.asarray(points, dtype=float))

            def cross(point, r):
                return self._cross_compliance(point[0], point[1], r, points)

        out = {k: np.zeros((len(points), len(t))) for k in ("w", "v", "a")}
        h = _difference_step(t, float(np.max(self.basis.frequencies_hz)))
        tn, _z, _v, fn, _d = self.nodes
        for b in range(fn.shape[1]):
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
                g = -np.asarray(cross((x, y), r))  # the ball pushes the plate down
                for key, part in zip(("w", "v", "a"), parts, strict=True):
                    out[key][:, sel] += g[:, None] * part[sel]
        return out

    def _cross_compliance(self, x, y, r, points):
        key = (x, y, r, points.tobytes())
        if key not in self._cross:
            if getattr(self.basis, "model", None) is None:
                cross = self.basis.residual_cross_compliance((x, y), points, r)
            else:
                cross = self._point_readings(points).residual_cross((x, y), r)
            self._cross[key] = cross
        return self._cross[key]

    def _point_readings(self, points):
        """The plain points (p, 2) m of a structure's impact face as channels (``Readings``):
        their static part from the sensor influences cached beside the basis, so a run whose
        points were solved before factorises nothing for them."""
        key = points.tobytes()
        if key not in self._readings:
            plain = [
                SensorSpec(f"points[{i}]", (float(x), float(y))) for i, (x, y) in enumerate(points)
            ]
            self._readings[key] = Readings(self.basis, plain)
        return self._readings[key]

    def energy(self, times) -> np.ndarray:
        """Vibration energy of the plate's kept modes, J, at ``times``."""
        q, qd, _ = self.modal_sample(times)
        om = np.asarray(self.basis.omega)[:, None]
        return 0.5 * np.sum(qd**2 + om**2 * q**2, axis=0)

    def acceleration(self, point, times) -> np.ndarray:
        """Plate acceleration normal to the plate (m/s^2) at one point (x, y), before any
        sensor."""
        return self.sample(times, [point])["a"][0]

    def sensor_outputs(self, sensors, duration: float) -> dict:
        """name -> ``tailbeam.signals.sensor.SensorOutput`` of each ``SensorSpec`` of
        ``sensors`` over [0, duration] s, one per channel (``SensorSpec.channels``)."""
        top = float(np.max(self.basis.frequencies_hz))
        out = {}
        for s in sensors:
            if s.plain:
                out[s.name] = measure(s, lambda t, p=s.position: self.acceleration(p, t),
                                      duration, max_frequency_hz=top)  # fmt: skip
                continue
            for c in s.channels():
                out[c.name] = measure(c, lambda t, c=c: self.channel_sample(t, [c])["a"][0],
                                      duration, max_frequency_hz=top)  # fmt: skip
        return out


def _difference_step(t, f_top):
    """Spacing of uniform times t (s), else 1/(8 f_top) s (see quasi_static_sample)."""
    if len(t) >= 3:
        d = np.diff(t)
        if d[0] > 0 and np.all(np.abs(d - d[0]) <= 1e-6 * d[0]):
            return float(d[0])
    return 1.0 / (8.0 * f_top)
