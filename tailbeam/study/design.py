"""The sweep file (TOML) and its expansion into cases.

A sweep file names a base scene and the axes that vary::

    scene = "base.toml"          # a scene file (relative to the sweep file), or an inline [scene]
    repeats = 2                  # independent seeds per design point (default 1)
    seed = 7                     # seed of the random design and of the case seeds (default 0)

    [labels]
    coal = ["coal"]              # materials counted as coal; every other material is gangue
                                 # (the label of each [[balls]] entry that gives none)

    [axes]
    "balls.rock.material" = ["coal", "sandstone"]                  # a list: grid values
    "balls.rock.radius" = { distribution = "uniform", low = 0.01, high = 0.1, samples = 20 }
    "balls.rock.position[2]" = { follow = "balls.rock.radius", offset = 0.001 }
    "sensors.S1.position" = [[0.0, 0.0], [0.1, 0.2]]

Axis keys are dotted scene keys: ``balls.NAME`` or ``balls[i]`` (i from 1, as in error
messages) select an entry of an array of tables, ``key[i]`` (i from 0) one component of a
vector. Grid axes form a product; random axes (``uniform``, ``loguniform``, ``choice``) share
one ``samples`` count and are drawn afresh for every grid point; ``follow`` sets a key to
``scale * value + offset`` of another swept key. Draws and case seeds are hashed from the seed
and the case's own values, so a grown sweep (more values, samples or repeats) keeps the cases
it had. Every sensor's noise seed is set to the case seed, and every stream's seed to one
drawn from it (unless ``streams.NAME.seed`` is swept), so repeats are independent. Each case
is the scene TOML (``dumps_scene``) plus a ``# case seed`` line; its SHA-256 is the case's
key. A stream is addressed by its name: ``streams.NAME.gangue_fraction``.
"""

import copy
import hashlib
import itertools
import json
import math
import re
import sys
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tailbeam.errors import InputError, require_positive
from tailbeam.io.scene_file import _check_keys, dumps_scene, parse_scene
from tailbeam.study.case import basis_signature

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

SWEEP_KEYS = ("scene", "repeats", "seed", "labels", "axes")
DISTRIBUTIONS = {
    "uniform": ("low", "high"),
    "loguniform": ("low", "high"),
    "choice": ("values",),
}
_SEGMENT = re.compile(r"^([A-Za-z_][\w-]*)(?:\[(\d+)\])?$")


@dataclass(frozen=True)
class Axis:
    """One swept key: kind "grid" (values), a distribution (params, samples) or "follow"."""

    key: str
    kind: str
    values: tuple = ()
    params: tuple = ()
    samples: int = 0
    follow: str = ""
    scale: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True)
class SweepSpec:
    """A validated sweep file: the base scene table, axes, repeats, seed, coal materials."""

    base: dict
    axes: tuple
    repeats: int = 1
    seed: int = 0
    coal: tuple = ("coal",)
    text: str = ""


@dataclass(frozen=True)
class Case:
    """One scene of the sweep: swept values, repeat, seed, scene TOML and its hash, labels,
    its modal basis key (``case.basis_signature``) and its sensors' (x, y) positions (m): what
    the client needs of the scene, so it never parses the TOML again."""

    params: dict
    repeat: int
    seed: int
    toml: str
    hash: str
    labels: dict
    basis: str = ""
    sensor_xy: tuple = ()


def _field(key: str) -> str:
    return f'axes."{key}"'


def _whole(field: str, value, low: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < low:
        raise InputError(field, f"must be a whole number >= {low}, got {value!r}")
    return value


def load_sweep(path) -> SweepSpec:
    """Read and validate the sweep file at ``path`` (OSError if unreadable)."""
    path = Path(path)
    text = path.read_bytes().decode("utf-8", errors="replace")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise InputError(path.name, f"is not valid TOML: {err}") from None
    return parse_sweep(data, base_dir=path.parent, text=text)


def parse_sweep(data: dict, *, base_dir=".", text: str = "") -> SweepSpec:
    """Validate the parsed sweep table ``data``; a scene path is relative to ``base_dir``."""
    _check_keys("", data, SWEEP_KEYS, required=("scene", "axes"))
    base = _base_scene(data["scene"], Path(base_dir))
    labels = data.get("labels", {})
    if not isinstance(labels, dict):
        raise InputError("labels", "must be a table ([labels])")
    _check_keys("labels", labels, ("coal",))
    coal = labels.get("coal", ["coal"])
    if not isinstance(coal, list) or not all(isinstance(c, str) for c in coal):
        raise InputError("labels.coal", f"must be a list of material names, got {coal!r}")
    axes = _parse_axes(data["axes"], base)
    return SweepSpec(
        base=base,
        axes=axes,
        repeats=_whole("repeats", data.get("repeats", 1), 1),
        seed=_whole("seed", data.get("seed", 0), 0),
        coal=tuple(coal),
        text=text,
    )


def _base_scene(value, base_dir: Path) -> dict:
    if isinstance(value, dict):
        return value
    if not isinstance(value, str) or not value:
        raise InputError("scene", "must be a scene file path or an inline [scene] table")
    path = base_dir / value
    try:
        text = path.read_bytes().decode("utf-8", errors="replace")
    except OSError as err:
        raise InputError("scene", f"cannot read {str(path)!r}: {err.strerror or err}") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise InputError("scene", f"{value!r} is not valid TOML: {err}") from None


def _parse_axes(table, base: dict) -> tuple:
    if not isinstance(table, dict) or not table:
        raise InputError("axes", "must be a table ([axes]) with at least one swept key")
    axes = [_parse_axis(key, value) for key, value in table.items()]
    for axis in axes:
        probe = axis.values[0] if axis.kind == "grid" else 1.0
        set_value(copy.deepcopy(base), axis.key, probe)  # the path must exist in the scene
        if axis.kind == "follow" and axis.follow not in table:
            raise InputError(_field(axis.key), f"follows {axis.follow!r}, which is not an axis")
    counts = {a.samples for a in axes if a.samples}
    if len(counts) > 1:
        raise InputError("axes", f"random axes must share one samples count, got {sorted(counts)}")
    return tuple(axes)


def _parse_axis(key: str, value) -> Axis:
    field = _field(key)
    _segments(key)
    if isinstance(value, list):
        if not value:
            raise InputError(field, "a grid needs at least one value")
        return Axis(key, "grid", values=tuple(value))
    if not isinstance(value, dict):
        raise InputError(field, "must be a list of values or a table (distribution or follow)")
    if "follow" in value:
        _check_keys(field, value, ("follow", "scale", "offset"))
        scale = value.get("scale", 1.0)
        offset = value.get("offset", 0.0)
        for name, v in (("scale", scale), ("offset", offset)):
            if isinstance(v, bool) or not isinstance(v, int | float):
                raise InputError(f"{field}.{name}", f"must be a number, got {v!r}")
        return Axis(key, "follow", follow=value["follow"], scale=scale, offset=offset)
    kind = value.get("distribution")
    if kind not in DISTRIBUTIONS:
        raise InputError(
            f"{field}.distribution", f"must be one of {sorted(DISTRIBUTIONS)}, got {kind!r}"
        )
    names = DISTRIBUTIONS[kind]
    _check_keys(field, value, ("distribution", "samples", *names), required=("samples", *names))
    samples = _whole(f"{field}.samples", value["samples"], 1)
    if kind == "choice":
        if not isinstance(value["values"], list) or not value["values"]:
            raise InputError(f"{field}.values", "must be a non-empty list")
        return Axis(key, kind, params=tuple(value["values"]), samples=samples)
    low = value["low"]
    high = value["high"]
    for name, v in (("low", low), ("high", high)):
        if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
            raise InputError(f"{field}.{name}", f"must be a finite number, got {v!r}")
    if not low < high:
        raise InputError(f"{field}.high", f"must be above low = {low!r}, got {high!r}")
    if kind == "loguniform":
        require_positive(f"{field}.low", low)
    return Axis(key, kind, params=(float(low), float(high)), samples=samples)


# -- dotted keys ----------------------------------------------------------------------------------


def _segments(key: str) -> list:
    if not isinstance(key, str) or not key:
        raise InputError("axes", "axis keys must be non-empty strings")
    out = []
    for seg in key.split("."):
        m = _SEGMENT.match(seg)
        if not m:
            raise InputError(_field(key), f"{seg!r} is not a key or key[index]")
        out.append((m.group(1), None if m.group(2) is None else int(m.group(2))))
    return out


def _entry(key: str, tables: list, name: str, index):
    if index is not None:
        if not 1 <= index <= len(tables):
            raise InputError(_field(key), f"index {index} is outside 1..{len(tables)}")
        return tables[index - 1]
    for t in tables:
        if t.get("name") == name:
            return t
    raise InputError(_field(key), f"no entry named {name!r}")


def set_value(data: dict, key: str, value) -> None:
    """Set the dotted scene key ``key`` in the raw scene table ``data`` (in place)."""
    segs = _segments(key)
    node = data
    for i, (name, index) in enumerate(segs):
        last = i == len(segs) - 1
        if isinstance(node, list):  # an array of tables: the segment is an entry's name
            if last:
                raise InputError(_field(key), "names a whole table, not a value")
            node = _entry(key, node, name, index)
            continue
        if not isinstance(node, dict):
            raise InputError(_field(key), f"{name!r} is inside a value, not a table")
        if index is None:
            if last:
                node[name] = value
                return
            node = node.setdefault(name, {})
            continue
        child = node.get(name)
        if isinstance(child, list) and child and all(isinstance(t, dict) for t in child):
            if last:
                raise InputError(_field(key), "names a whole table, not a value")
            node = _entry(key, child, name, index)
        elif isinstance(child, list) and last:
            if index >= len(child):
                raise InputError(_field(key), f"index {index} is outside 0..{len(child) - 1}")
            child[index] = value
            return
        else:
            raise InputError(
                _field(key), f"{name!r} must be a list in the base scene to sweep one component"
            )


# -- expansion ------------------------------------------------------------------------------------


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


def case_labels(scene) -> dict:
    """Labels of a scene: class of the balls ("coal", "gangue" or "mixed"), gangue mass
    fraction, numbers of coal and gangue balls, from the scene's ball labels (the sweep sets
    them from ``labels.coal``: ``label_balls``; stream scenes: stream_labels)."""
    if scene.streams:
        return stream_labels(scene)
    is_coal = [label == "coal" for label in scene.labels]
    mass = sum(b.mass for b in scene.balls)
    gangue_mass = sum(b.mass for b, c in zip(scene.balls, is_coal, strict=True) if not c)
    n_coal = sum(is_coal)
    n_gangue = len(is_coal) - n_coal
    label = "mixed" if n_coal and n_gangue else ("coal" if n_coal else "gangue")
    return {
        "label": label,
        "gangue_fraction": gangue_mass / mass,
        "n_coal": n_coal,
        "n_gangue": n_gangue,
    }


def label_balls(data: dict, coal: tuple) -> None:
    """Give every ``[[balls]]`` table of the raw scene ``data`` that has no ``label`` the
    label of its material: coal if it is in ``coal``, else gangue (in place). The scene
    TOML then carries it where it differs from the default (tailbeam.scene.default_label),
    and every output (impacts.csv's ``label``) agrees with the sweep's labels."""
    balls = data.get("balls")
    for ball in balls if isinstance(balls, list) else []:
        if isinstance(ball, dict) and "label" not in ball and isinstance(ball.get("material"), str):
            ball["label"] = "coal" if ball["material"] in coal else "gangue"


def stream_labels(scene) -> dict:
    """Labels of a scene with streams, from its particles (each labelled coal or gangue by
    its stream, [[balls]] by their label): ``label`` (coal, gangue or mixed), ``gangue_fraction``
    = the streams' declared gangue_fraction (the probability that a particle is gangue;
    several streams: weighted by their expected particle counts; [[balls]] not included),
    ``gangue_mass_fraction`` (realised, by mass, all particles released before the end),
    ``n_coal``, ``n_gangue``, ``n_particles`` (particles, [[balls]] included)."""
    parts = scene.particles
    gangue = [p for p in parts if p.label == "gangue"]
    expected = [max(n, 0.0) for n in scene.expected_particles()]
    declared = sum(n * s.gangue_fraction for n, s in zip(expected, scene.streams, strict=True))
    mass = sum(p.mass for p in parts)
    n_gangue = len(gangue)
    n_coal = len(parts) - n_gangue
    return {
        "label": "mixed" if n_coal and n_gangue else ("gangue" if n_gangue else "coal"),
        "gangue_fraction": declared / sum(expected) if sum(expected) > 0 else math.nan,
        "n_coal": n_coal,
        "n_gangue": n_gangue,
        "gangue_mass_fraction": sum(p.mass for p in gangue) / mass if mass > 0 else math.nan,
        "n_particles": len(parts),
    }


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
        scene = parse_scene(data)
    except InputError as err:
        raise InputError(f"case {number} ({shown}): {err.field}", err.rule) from None
    toml = dumps_scene(scene) + f"# case seed = {seed}\n"
    digest = hashlib.sha256(toml.encode()).hexdigest()
    labels = case_labels(scene)
    xy = tuple((float(s.position[0]), float(s.position[1])) for s in scene.sensors)
    return Case(params, repeat, seed, toml, digest, labels, basis_signature(scene), xy), scene


def expand(spec: SweepSpec) -> list:
    """Every case of the sweep, validated: all must share duration, sensor names and sample
    rates (the dataset's time axis) and have at least one sensor."""
    cases, first = [], None
    for params in design_points(spec):
        for r in range(spec.repeats):
            case, scene = make_case(spec, params, r, len(cases) + 1)
            shape = (scene.duration, tuple((s.name, s.sample_rate) for s in scene.sensors))
            if first is None:
                first = shape
                if not scene.sensors:
                    raise InputError("scene.sensors", "a sweep needs at least one [[sensors]]")
            elif shape != first:
                raise InputError(
                    f"case {len(cases) + 1}",
                    "changes the duration, sensor names or sensor sample rates; every case "
                    "of a dataset shares one time axis",
                )
            cases.append(case)
    return cases
