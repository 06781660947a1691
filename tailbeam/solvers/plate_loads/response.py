"""The modal plate's exact answer to sparse load histories (``PlateLoads``), at a few points.

One-way: the loads are prescribed (a stream's contact forces and dead loads); the plate's
motion does not act back on them. Every kept mode is driven exactly by the piecewise-linear
forces (the closed-form propagation of ``tailbeam.solvers.plate_loads.propagator``, organised as in
``tailbeam.solvers.plate_loads.kernel``: a particular part that follows the force and a free
homogeneous part that jumps at load nodes), so the result is exact at the samples whatever
the node times. Optionally the truncated modes' quasi-static response is added at the points
(as ``tailbeam.solvers.coupled.replay.ModalReplay.quasi_static_sample``).

Cost: O(samples x modes x points) for the march over the output grid, O(nodes x modes) for
the load nodes (a chained step per node and mode, one damped-oscillator transition per load
and sample interval it has nodes in), O(pieces) mode-shape evaluations. Memory: the three
(points, samples) outputs, O(nodes) node tables, and the mode shapes of at most
``batch_nodes`` pieces at a time: never (modes x samples) or (nodes x pieces).
"""

import math
import time
from dataclasses import dataclass

import numpy as np

from tailbeam.errors import InputError, WorkLimitError
from tailbeam.physics.contact_patch import disc_rule
from tailbeam.plate.fe.model import check_points
from tailbeam.progress import note, task
from tailbeam.signals.sensor import SensorSpec, measure
from tailbeam.solvers.plate_loads.kernel import (
    add_particular,
    empty_outputs,
    jumps_kernel,
    march,
    transition,
)
from tailbeam.solvers.plate_loads.loads import PlateLoads
from tailbeam.solvers.plate_loads.readings import Readings

BATCH_NODES = 4096  # load nodes per batch (bounds the mode-shape table: batch x modes)
DISC_BATCH = 256  # load discs evaluated per basis call (48 points each)
MAX_BYTES = 2e9  # memory bound of plate_response (outputs + node tables + shapes)
MAX_QUASI_STATIC_S = 600.0  # time bound of the residual cross compliances
NODE_TIME_ULPS = 2.0  # see plate_response
RESIDUAL_BATCH = 256  # load points per static-deflection call


def plate_response(
    basis,
    zeta,
    loads,
    points,
    times,
    *,
    load_radius: float = 0.0,
    quasi_static: bool = True,
    node_time_ulps: float = NODE_TIME_ULPS,
    batch_nodes: int = BATCH_NODES,
    max_bytes: float = MAX_BYTES,
    modal: bool = False,
    readings=None,
) -> dict:
    """Plate deflection "w" (m, + up), velocity "v" (m/s) and acceleration "a" (m/s^2) at
    ``points`` under ``loads``, each (p, len(times)); with ``modal`` the kept modes'
    coordinates q, q', q'' instead (sqrt(kg) m and its rates, each (n_modes, len(times));
    ``points`` and ``quasi_static`` are then ignored).

    Parameters
    ----------
    basis : ModalBasis
        The plate's kept modes (frequencies, mass-normalised shapes).
    zeta : float or (n_modes,) array
        Modal damping ratios, each in [0, 1).
    loads : PlateLoads
        The load pieces (N, pressing down); the plate is at rest before the first one.
    points : (p, 2) array
        Where the plate is observed, m (plate frame, centred on the origin).
    times : (N,) array
        Uniform sample times, s (spacing equal to 1e-9 relative; taken as t0 + j dt).
    load_radius : float
        Radius (m) of the disc a piece without its own radius is spread over (0: a point
        load, the Kirchhoff model; see tailbeam.physics.contact_patch).
    quasi_static : bool
        Add the truncated modes' quasi-static response -R F(t) at the points (R: the
        basis' residual cross compliance; velocity and acceleration as central differences
        at the sample spacing, as ``ModalReplay.quasi_static_sample``). Ignored, with a
        note, if the basis has no static cross compliance.
    node_time_ulps : float
        A load's nodes inside one sample interval are chained with one transition matrix per
        node step; steps equal to ``node_time_ulps`` ulps of the node time (uniform steps
        whose times were rounded) share it, which places each node's jump within that many
        ulps of its time (at t = 5 s, 2 ulps = 1.8e-15 s: a phase of 1e-10 rad at 10 kHz).
        0: every node at its own time (exact to rounding; slower with many nodes per sample).
    batch_nodes, max_bytes : int, float
        Load nodes per batch of mode shapes; memory bound (bytes, WorkLimitError above it).
    readings : Readings, optional
        Also observe these sensor channels (``tailbeam.solvers.plate_loads.readings``: any
        surface point and direction): their rows follow those of ``points`` (None or empty:
        the channels only).
    """
    omega = np.ascontiguousarray(basis.omega, dtype=float)
    if modal:  # the identity as the "shapes at the points": the outputs are q, q', q''
        pts, phi_pts, quasi_static = None, np.eye(omega.shape[0]), False
    else:
        pts, phi_pts = _observed(basis, points, readings)
    t0, dt, n_samples = uniform_times(times)
    zeta = _zeta(zeta, omega.shape[0])
    xyr = _load_points(basis, loads, load_radius)
    _check_batching(node_time_ulps, batch_nodes)
    _check_memory(len(phi_pts), n_samples, loads, omega.shape[0], batch_nodes, max_bytes)
    nodes = node_jumps(loads, t0, dt, n_samples)
    out = empty_outputs(len(phi_pts), n_samples)
    grid = (t0, dt, n_samples)
    batching = (int(batch_nodes), float(node_time_ulps))
    what = "modal coordinates" if modal else "plate response at the sensors"
    split = 0 if pts is None else len(pts)  # the points' rows, then the channels'
    g, h, seen = _march_all(basis, omega, zeta, xyr, loads, nodes, phi_pts, grid, batching, out,
                            what, split)  # fmt: skip
    r = np.zeros_like(g)
    if quasi_static:
        r = _residual(basis, xyr, pts, seen, g, readings)
    _add_particular_all(loads, nodes, t0, dt, g, h, r, out)
    return dict(zip(("w", "v", "a"), out, strict=True))


def _observed(basis, points, readings) -> tuple:
    """(points (p, 2) m checked, or None; shapes (p + c, n_modes)): the deflection at the
    points, then the channels of ``readings`` (if any), each read along its direction."""
    if readings is None:
        pts = check_points(basis.plate, points, "points")
        return pts, np.ascontiguousarray(basis.deflection(pts), dtype=float)
    rows, pts = [], None
    if points is not None and len(points):
        pts = check_points(basis.plate, points, "points")
        rows.append(basis.deflection(pts))
    rows.append(readings.shapes())
    return pts, np.ascontiguousarray(np.vstack(rows), dtype=float)


def _check_batching(node_time_ulps, batch_nodes):
    """InputError naming ``node_time_ulps`` (>= 0) or ``batch_nodes`` (>= 1) if invalid."""
    if not (math.isfinite(node_time_ulps) and node_time_ulps >= 0):
        raise InputError("node_time_ulps", f"must be >= 0, got {node_time_ulps!r}")
    if not batch_nodes >= 1:
        raise InputError("batch_nodes", f"must be >= 1, got {batch_nodes!r}")


def _add_particular_all(loads, nodes, t0, dt, g, h, r, out):
    """Add every load's particular response inside its sample intervals to out (w, v, a)."""
    target = nodes["target"]
    span = target[nodes["last"]] - target[loads.first]
    buf = np.empty(int(np.max(span, initial=0)) + 4)
    add_particular(t0, dt, loads.t, loads.force, loads.first, nodes["last"], target, g, h, r, buf,
                   *out)  # fmt: skip


def uniform_times(times) -> tuple:
    """(t0 s, dt s, N) of uniform sorted ``times`` (N >= 2, spacing equal to 1e-9 relative)."""
    t = np.asarray(times, dtype=float)
    if t.ndim != 1 or t.size < 2 or not np.all(np.isfinite(t)):
        raise InputError("times", "must be a 1-D array of >= 2 finite times in s")
    dt = (t[-1] - t[0]) / (t.size - 1)
    if not dt > 0 or np.max(np.abs(np.diff(t) - dt)) > 1e-9 * dt:
        raise InputError("times", "must be uniform and increasing (the sensor grid)")
    return float(t[0]), float(dt), int(t.size)


def _zeta(zeta, n):
    z = np.ascontiguousarray(np.broadcast_to(np.asarray(zeta, dtype=float), (n,)))
    if not np.all((z >= 0.0) & (z < 1.0)):
        raise InputError("zeta", "modal damping ratios must lie in [0, 1)")
    return z


def _load_points(basis, loads, load_radius) -> np.ndarray:
    """(pieces, 3) x, y, radius (m) of every piece, default radius filled in; checked."""
    if not (math.isfinite(load_radius) and load_radius >= 0.0):
        raise InputError("load_radius", f"must be >= 0 m, got {load_radius!r}")
    xyr = np.column_stack([loads.x, loads.y, loads.radius])
    xyr[np.isnan(xyr[:, 2]), 2] = load_radius
    if len(xyr):
        half = 0.5 * np.array([basis.plate.size_x, basis.plate.size_y]) * (1 + 1e-9)
        off = np.flatnonzero(np.any(np.abs(xyr[:, :2]) > half, axis=1))
        if off.size:
            i = int(off[0])
            raise InputError(
                f"loads[{i}]", f"point ({xyr[i, 0]:.6g}, {xyr[i, 1]:.6g}) m is not on the plate"
            )
    return xyr


def node_jumps(loads, t0: float, dt: float, n_samples: int) -> dict:
    """Per load node: the jump of the load's value "df" (N) and slope "ds" (N/s) there and its
    "target" sample (the first at or after it; 0 for nodes before t0; n_samples after the
    last); per piece its "last" node (tailbeam.solvers.plate_loads.kernel.jumps_kernel)."""
    n = loads.n_nodes
    last = np.append(loads.first[1:], n).astype(np.int64)[: len(loads)] - 1
    df, ds, target = np.empty(n), np.empty(n), np.empty(n, dtype=np.int64)
    jumps_kernel(loads.t, loads.force, loads.first, last, t0, dt, n_samples, df, ds, target)
    return {"df": df, "ds": ds, "target": target, "last": last}


def _march_all(basis, omega, zeta, xyr, loads, nodes, phi_pts, times, batching, out, what,
               split=0):  # fmt: skip
    """Run ``march`` over all samples, the nodes in batches of ``batch_nodes`` (their pieces'
    mode shapes evaluated per batch); times = (t0 s, dt s, N), batching = (batch_nodes,
    node_time_ulps); ``what`` names the progress; ``split``: the rows of the points, before
    the channels' (``_by_block``). Returns G, H (pieces, p) and which pieces were seen."""
    n_pieces = xyr.shape[0]
    t0, dt, n_samples = times
    batch_nodes, ulps = batching
    t_nodes, first = loads.t, loads.first
    g = np.zeros((n_pieces, phi_pts.shape[0]))
    h = np.zeros_like(g)
    seen = np.zeros(n_pieces, dtype=bool)
    mu = omega * np.sqrt(1.0 - zeta**2)
    zw = zeta * omega
    w2 = omega**2
    pdt = np.empty((4, omega.shape[0]))
    transition(mu, zw, w2, dt, pdt)
    qh, vh = np.zeros(omega.shape[0]), np.zeros(omega.shape[0])
    g_pts = (phi_pts / w2).T
    h_pts = (phi_pts * (2.0 * zeta / omega**3)).T
    evaluate = shape_reader(basis)
    order = np.argsort(nodes["target"], kind="stable")
    n_act = int(np.searchsorted(nodes["target"], n_samples, sorter=order))
    done = -1
    with task(what, total=max(n_act, 1), unit="load nodes") as bar:
        start = 0
        while start < n_act:
            stop = min(start + batch_nodes, n_act)
            last_j = int(nodes["target"][order[stop - 1]])
            while stop < n_act and nodes["target"][order[stop]] == last_j:  # whole samples
                stop += 1
            sel = order[start:stop]
            pieces = np.searchsorted(first, sel, side="right") - 1
            uniq, rows = np.unique(pieces, return_inverse=True)
            phi_tab = load_shapes(basis, xyr[uniq], evaluate)
            g[uniq], h[uniq] = _by_block(phi_tab, g_pts, split), _by_block(phi_tab, h_pts, split)
            seen[uniq] = True
            march(done + 1, last_j, t0, dt, pdt, mu, zw, w2, qh, vh, phi_pts,
                  nodes["target"][sel], t_nodes[sel], rows.ravel().astype(np.int64),
                  nodes["df"][sel], nodes["ds"][sel], phi_tab, ulps, *out)  # fmt: skip
            done = last_j
            bar.update(stop - start)
            start = stop
        empty_i, empty_f = np.zeros(0, dtype=np.int64), np.zeros(0)
        march(done + 1, n_samples - 1, t0, dt, pdt, mu, zw, w2, qh, vh, phi_pts, empty_i,
              empty_f, empty_i, empty_f, empty_f, np.zeros((1, omega.shape[0])), ulps,
              *out)  # fmt: skip
    return g, h, seen


def _by_block(left, right, split):
    """left @ right as two products, right's columns [:split] and [split:] (the points' and
    the channels'), so each block's values do not depend on the other block: a plain sensor
    reads the same, bit for bit, beside other channels."""
    if 0 < split < right.shape[1]:
        return np.hstack([left @ right[:, :split], left @ right[:, split:]])
    return left @ right


def load_shapes(basis, xyr, evaluate=None) -> np.ndarray:
    """(k, n_modes) mode shapes under the loads xyr (k, 3) (x, y m; radius m: 0 a point,
    else the mean over the disc, as ModalBasis.load_deflection); each distinct load once.
    ``evaluate``: the mode shapes at points (``shape_reader``; default the basis')."""
    return disc_average(basis.plate, xyr, evaluate or basis.deflection)


def shape_reader(basis):
    """points (q, 2) m -> (q, n_modes) mode shapes: on a structure whose impact face has
    fast readings, their interpolation of the mode vectors (``FaceReadings.modal``: the
    probe's values to round-off, without a sparse product with the whole basis per call);
    else ``basis.deflection``."""
    model, vectors = getattr(basis, "model", None), getattr(basis, "mode_vectors", None)
    readings = None if model is None or vectors is None else model.face_readings()
    if readings is None:
        return basis.deflection
    face = readings.modal(np.asarray(vectors)[:, : basis.n_modes])

    def evaluate(points):
        return face(check_points(basis.plate, points, "points"))

    return evaluate


def disc_average(plate, xyr, evaluate) -> np.ndarray:
    """(k, m) values of ``evaluate`` (points (q, 2) m -> (q, m)) under the loads xyr (k, 3):
    at the point for radius 0, else averaged over the load disc (contact_patch.disc_rule);
    each distinct load evaluated once, discs DISC_BATCH at a time."""
    uniq, inv = np.unique(xyr, axis=0, return_inverse=True)
    groups = []
    point = np.flatnonzero(uniq[:, 2] == 0.0)
    if point.size:
        groups.append((point, np.asarray(evaluate(uniq[point, :2]))))
    disc = np.flatnonzero(uniq[:, 2] != 0.0)
    for k in range(0, disc.size, DISC_BATCH):
        rows = disc[k : k + DISC_BATCH]
        rules = [disc_rule(plate, uniq[i, :2], uniq[i, 2]) for i in rows]
        pts = np.concatenate([rule[0] for rule in rules])
        wts = np.concatenate([rule[1] for rule in rules])
        starts = np.cumsum([0] + [len(rule[1]) for rule in rules[:-1]])
        groups.append((rows, np.add.reduceat(evaluate(pts) * wts[:, None], starts, axis=0)))
    out = np.empty((uniq.shape[0], groups[0][1].shape[1] if groups else 0))
    for rows, values in groups:
        out[rows] = values
    return np.ascontiguousarray(out[inv.ravel()])


def _residual(basis, xyr, pts, seen, g, readings=None) -> np.ndarray:
    """R (pieces, p): the residual cross compliance (m/N) between each seen piece's load and
    the points: the full model's static deflection minus the kept modes' part g (as
    ModalBasis.residual_cross_compliance). The static part is taken by Maxwell-Betti
    reciprocity as the deflection at the load (disc-averaged) under a unit point load at
    each point: p static solutions, evaluated at the load points in batches. Zeros (with a
    note) if the basis has no static deflection; WorkLimitError if the estimated time (from
    the first batch) exceeds MAX_QUASI_STATIC_S. With ``readings`` its channels follow the
    points (``pts`` None: none) and their static part is theirs (``Readings.static``)."""
    r = np.zeros_like(g)
    if getattr(basis, "static_deflection_at", None) is None:
        note(f"no quasi-static correction: the {basis.theory} basis has no static deflection")
        return r
    idx = np.flatnonzero(seen)
    uniq, inv = np.unique(xyr[idx], axis=0, return_inverse=True)
    full = np.empty((uniq.shape[0], g.shape[1]))

    at_points = _point_statics(basis, pts)

    def static(q):
        if readings is None:
            return at_points(q)
        return readings.static(q) if pts is None else np.hstack([at_points(q), readings.static(q)])

    with task("quasi-static correction", total=uniq.shape[0], unit="load points") as bar:
        for k in range(0, uniq.shape[0], RESIDUAL_BATCH):
            start = time.perf_counter()
            full[k : k + RESIDUAL_BATCH] = disc_average(
                basis.plate, uniq[k : k + RESIDUAL_BATCH], static
            )
            if k == 0 and uniq.shape[0] > RESIDUAL_BATCH:
                per_point = (time.perf_counter() - start) / RESIDUAL_BATCH
                _check_residual_time(per_point, uniq.shape[0])
            bar.update(min(RESIDUAL_BATCH, uniq.shape[0] - k))
    r[idx] = full[inv.ravel()] - g[idx]
    return r


def _point_statics(basis, pts):
    """load points (q, 2) m -> (q, p): the static deflection (m/N) at the points ``pts``
    under 1 N at each load point: by reciprocity, from the basis' static solves at the
    points, or on a structure from the influences cached beside its basis (the points as
    plain sensors, ``Readings``)."""
    if pts is None:
        return None
    if getattr(basis, "model", None) is not None:
        plain = [SensorSpec(f"points[{i}]", (float(x), float(y))) for i, (x, y) in enumerate(pts)]
        return Readings(basis, plain).static

    def static(q):
        return np.column_stack([basis.static_deflection_at(p, q, 0.0) for p in pts])

    return static


def _check_residual_time(seconds_one, count):
    estimate = seconds_one * count
    if estimate > MAX_QUASI_STATIC_S:
        raise WorkLimitError(
            f"quasi_static: the static deflection at {count} distinct load points would take "
            f"~{estimate:.0f} s ({seconds_one * 1e3:.2f} ms each with this basis, limit "
            f"{MAX_QUASI_STATIC_S:.0f} s); set plate.residual_flexibility = false (the kept modes "
            "only; quasi_static=False in Python)"
        )


def _check_memory(n_points, n_samples, loads, n_modes, batch_nodes, max_bytes):
    # outputs; per node df, ds, target, sort order (+ argsort scratch); two shape tables
    need = 8 * (3 * n_points * n_samples + 5 * loads.n_nodes + 2 * batch_nodes * n_modes)
    if need > max_bytes:
        raise WorkLimitError(
            f"max_bytes: the plate response needs ~{need / 1e9:.2f} GB ({n_points} points x "
            f"{n_samples} samples, {loads.n_nodes} load nodes), above {max_bytes / 1e9:.2f} GB;"
            " lower sensors[i].sample_rate or duration"
        )


def sensor_outputs(basis, zeta, loads, sensors, duration, *, load_radius=0.0, quasi_static=True):
    """name -> tailbeam.signals.sensor.SensorOutput for every channel of every sensor
    (``SensorSpec.channels``) under ``loads``: the chain of ``ModalReplay.sensor_outputs``
    (true acceleration on the sensor's fine grid, mounted resonance, anti-alias FIR, sampling,
    noise) over [0, duration] s, driven by ``plate_response``. All channels whose fine grids
    coincide share one plate response (one march of the modes over the load nodes and the
    samples; each channel a row of mode shapes): plain sensors (a point (x, y) read along
    +z) through the basis' deflection, the other channels through
    ``tailbeam.solvers.plate_loads.readings``. ``sensor_signals(outputs)`` gives what
    ``write_sensors_csv`` takes."""
    f_top = float(np.max(basis.frequencies_hz))
    rows, plain, other = _sensor_rows(sensors)
    positions = np.array([s.position for s in plain], dtype=float).reshape(-1, 2)
    readings = Readings(basis, other) if other else None
    done = {}

    def acceleration(times, row):
        key = (len(times), float(times[1] - times[0]))
        if key not in done:
            response = plate_response(
                basis, zeta, loads, positions, times,
                load_radius=load_radius, quasi_static=quasi_static, readings=readings,
            )  # fmt: skip
            done[key] = response["a"]
        return done[key][row]

    out = {}
    for c, row in rows:
        out[c.name] = measure(
            c, lambda t, row=row: acceleration(t, row), duration, max_frequency_hz=f_top
        )
    return out


def _sensor_rows(sensors) -> tuple:
    """([(channel, its row of the plate response)], the plain sensors, read by the basis'
    deflection at their points, the other channels, read by ``Readings``, after them)."""
    plain = [s for s in sensors if s.plain]
    other = [c for s in sensors if not s.plain for c in s.channels()]
    rows = []
    for s in sensors:
        if s.plain:
            rows.append((s, plain.index(s)))
            continue
        rows += [(c, len(plain) + other.index(c)) for c in s.channels()]
    return rows, plain, other


@dataclass(frozen=True, eq=False)
class LoadResponse:
    """The modal plate's response to the loads a run recorded: a ``Result``'s ``plate`` part
    for the stream solvers.

    Parameters
    ----------
    basis : tailbeam.plate.basis.ModalBasis
        The kept modes.
    zeta : ndarray
        Damping ratio of each mode.
    loads : PlateLoads
        The plate's contact force histories and dead loads (N, pressing down).
    quasi_static : bool
        Add the truncated modes' quasi-static response at the sensors (residual flexibility).
    """

    basis: object
    zeta: np.ndarray
    loads: PlateLoads
    quasi_static: bool = True

    @classmethod
    def from_records(cls, basis, zeta, contacts, dead, *, quasi_static=True) -> "LoadResponse":
        """From a stream run's records: ``contacts`` (x m, y m, t_nodes s, forces N) piecewise
        linear force histories and ``dead`` (x, y, t_from, t_to, force N) constant loads."""
        loads = PlateLoads()
        for x, y, t, f in contacts:
            loads.add_contact(x, y, t, f)
        for x, y, t0, t1, f in dead:
            loads.add_dead_load(x, y, t0, t1, f)
        return cls(basis, zeta, loads, quasi_static)

    def modal_coordinates(self, times) -> np.ndarray:
        """(n_modes, len(times)) modal coordinates q (sqrt(kg) m) at uniform ``times`` (s),
        exact for the recorded loads (``plate_response`` with ``modal``)."""
        t = np.asarray(times, dtype=float)
        if t.size == 1:  # one time: a grid of two, the second one step later
            return self.modal_coordinates(np.array([t[0], t[0] + 1e-3]))[:, :1]
        response = plate_response(self.basis, self.zeta, self.loads, None, t, modal=True)
        return response["w"]

    def sensor_outputs(self, sensors, duration: float) -> dict:
        """name -> ``tailbeam.signals.sensor.SensorOutput`` of each ``SensorSpec`` of
        ``sensors`` over [0, duration] s (``sensor_outputs``)."""
        with task(f"sensor signals, {len(sensors)} sensors, {self.loads.n_nodes} load nodes"):
            return sensor_outputs(self.basis, self.zeta, self.loads, sensors, duration,
                                  quasi_static=self.quasi_static)  # fmt: skip


def sensor_signals(outputs: dict) -> dict:
    """name -> (t s, acceleration m/s^2) of ``sensor_outputs`` (for write_sensors_csv)."""
    return {name: (out.t, out.acceleration) for name, out in outputs.items()}
