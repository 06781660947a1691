"""A sweep's design and its expansion into cases (the sweep file: ``tailbeam.study.sweep_file``).

Grid axes form a product; random axes are drawn afresh for every grid point; ``follow`` axes
are set from the key they follow. Draws and case seeds are hashed from the seed and the
case's own values, so a grown sweep (more values, samples or repeats) keeps the cases it
had. Every sensor's noise seed is set to the case seed, and every stream's seed to one drawn
from it (unless ``streams.NAME.seed`` is swept), so repeats are independent. Each case is the
scene TOML (``dumps_scene``) plus a ``# case seed`` line; its SHA-256 is the case's key; its
labels come from ``tailbeam.study.labels``.

``load_sweep``, ``parse_sweep``, ``SweepSpec``, ``Axis``, ``set_value`` and the label
functions stay importable from here.
"""

import copy
import hashlib
import itertools
import json
import zlib
from dataclasses import dataclass

import numpy as np

from tailbeam.errors import InputError
from tailbeam.io.scene_dump import dumps_scene
from tailbeam.io.scene_file import parse_scene
from tailbeam.study.case import basis_signature
from tailbeam.study.labels import case_labels, label_balls, stream_labels
from tailbeam.study.scene_keys import set_value
from tailbeam.study.sweep_file import DISTRIBUTIONS, Axis, SweepSpec, load_sweep, parse_sweep

__all__ = [
    "Axis",
    "Case",
    "SweepSpec",
    "case_labels",
    "design_points",
    "expand",
    "label_balls",
    "load_sweep",
    "make_case",
    "parse_sweep",
    "set_value",
    "stream_labels",
]


@dataclass(frozen=True)
class Case:
    """One scene of the sweep: swept values, repeat, seed, scene TOML and its hash, labels,
    its modal basis key (``case.basis_signature``), and per output signal (a sensor, or each
    axis of a three-axis one: ``SensorSpec.channels``) its point (x, y, z) m and unit
    direction: what the client needs of the scene, so it never parses the TOML again."""

    params: dict
    repeat: int
    seed: int
    toml: str
    hash: str
    labels: dict
    basis: str = ""
    sensor_points: tuple = ()
    sensor_directions: tuple = ()


def _hash_int(*parts) -> int:
    digest = hashlib.sha256(json.dumps(parts, sort_keys=True, default=str).encode()).digest()
    return int.from_bytes(digest[:4], "little") & 0x7FFFFFFF


def _draw(axis: Axis, seed: int, point: dict) -> list:
    rng = np.random.default_rng((seed, zlib.crc32(axis.key.encode()), _hash_int(point)))
    if axis.kind == "uniform":
        return list(rng.uniform(*axis.params, axis.samples))
    if axis.kind == "loguniform":
        lo, hi = np.log(axis.params)
        return list(np.exp(rng.uniform(lo, hi, axis.samples)))
    idx = rng.integers(0, len(axis.params), axis.samples)
    return [axis.params[i] for i in idx]


def design_points(spec: SweepSpec) -> list:
    """The parameter dicts (axis key -> value) of the design, without repeats."""
    grid = [a for a in spec.axes if a.kind == "grid"]
    rand = [a for a in spec.axes if a.kind in DISTRIBUTIONS]
    follow = [a for a in spec.axes if a.kind == "follow"]
    n = rand[0].samples if rand else 1
    points = []
    for combo in itertools.product(*(a.values for a in grid)):
        point = {a.key: v for a, v in zip(grid, combo, strict=True)}
        draws = {a.key: _draw(a, spec.seed, point) for a in rand}
        for s in range(n):
            p = dict(point)
            p.update({k: _plain(v[s]) for k, v in draws.items()})
            points.append(p)
    for p in points:
        for a in follow:
            p[a.key] = a.scale * p[a.follow] + a.offset
    return points


def _plain(v):
    return v.item() if isinstance(v, np.generic) else v


def _seed_streams(data: dict, seed: int, params: dict) -> None:
    """Give every stream a seed drawn from the case seed (so repeats and design points draw
    independent particles), unless its seed is a swept axis."""
    streams = data.get("streams")
    for i, stream in enumerate(streams if isinstance(streams, list) else [], start=1):
        if not isinstance(stream, dict):
            continue
        keys = {f"streams[{i}].seed", f"streams.{stream.get('name')}.seed"}
        if not keys & set(params):
            stream["seed"] = _hash_int(seed, "stream", i)


def _seed_noise(data: dict, seed: int) -> None:
    """Set the noise seed of every sensor that has noise to the case seed."""
    sensors = data.get("sensors")
    for sensor in sensors if isinstance(sensors, list) else []:
        if isinstance(sensor, dict) and "noise" in sensor:
            noise = sensor["noise"]
            table = dict(noise) if isinstance(noise, dict) else {"rms": noise}
            sensor["noise"] = {**table, "seed": seed}


def make_case(spec: SweepSpec, params: dict, repeat: int, number: int):
    """(Case, Scene) of one design point and repeat; InputError names the case (numbered
    from 1) and the scene field."""
    seed = _hash_int(spec.seed, params, repeat)
    data = copy.deepcopy(spec.base)
    for key, value in params.items():
        set_value(data, key, value)
    _seed_noise(data, seed)
    _seed_streams(data, seed, params)
    label_balls(data, spec.coal)
    shown = ", ".join(f"{k} = {v!r}" for k, v in params.items())
    try:
        scene = parse_scene(data, base_dir=spec.base_dir)
    except InputError as err:
        raise InputError(f"case {number} ({shown}): {err.field}", err.rule) from None
    toml = dumps_scene(scene) + f"# case seed = {seed}\n"
    digest = hashlib.sha256(toml.encode()).hexdigest()
    labels = case_labels(scene)
    points, directions = _channel_places(scene.sensors)
    basis = basis_signature(scene)
    return Case(params, repeat, seed, toml, digest, labels, basis, points, directions), scene


def _channel_places(sensors) -> tuple:
    """((x, y, z) m, (dx, dy, dz)) of every output signal: a point (x, y) is (x, y, 0) on the
    impact face, the direction by default its normal +z."""
    points, directions = [], []
    for c in (c for s in sensors for c in s.channels()):
        points.append(tuple(float(v) for v in (*c.position, 0.0)[:3]))
        directions.append(c.direction if c.direction is not None else (0.0, 0.0, 1.0))
    return tuple(points), tuple(directions)


def expand(spec: SweepSpec) -> list:
    """Every case of the sweep, validated: all must share duration, sensor names and sample
    rates (the dataset's time axis) and have at least one sensor."""
    cases, first = [], None
    for params in design_points(spec):
        for r in range(spec.repeats):
            case, scene = make_case(spec, params, r, len(cases) + 1)
            signals = tuple((c.name, c.sample_rate) for s in scene.sensors for c in s.channels())
            shape = (scene.duration, signals)
            if first is None:
                first = shape
                if not scene.sensors:
                    raise InputError("scene.sensors", "a sweep needs at least one [[sensors]]")
            elif shape != first:
                raise InputError(
                    f"case {len(cases) + 1}",
                    "changes the duration, sensor signal names (sensors, axes) or sample "
                    "rates; every case of a dataset shares one time axis",
                )
            cases.append(case)
    return cases
