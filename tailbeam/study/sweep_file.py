"""The sweep file (TOML): its keys, axes and validation (``SweepSpec``).

A sweep file names a base scene and the axes that vary::

    scene = "base.toml"          # a scene file (relative to the sweep file), or an inline [scene]
    repeats = 2                  # independent seeds per design point (default 1)
    seed = 7                     # seed of the random design and of the case seeds (default 0)
    band_accuracy = 0.005        # a case whose band check estimates a larger peak-force error
                                 # is flagged invalid (default: the band check's own 0.5 %)

    [labels]
    coal = ["coal"]              # materials counted as coal; every other material is gangue
                                 # (the label of each [[balls]] entry that gives none)

    [axes]
    "balls.rock.material" = ["coal", "sandstone"]                  # a list: grid values
    "balls.rock.radius" = { distribution = "uniform", low = 0.01, high = 0.1, samples = 20 }
    "balls.rock.position[2]" = { follow = "balls.rock.radius", offset = 0.001 }
    "sensors.S1.position" = [[0.0, 0.0], [0.1, 0.2]]

Axis keys are dotted scene keys (``tailbeam.study.scene_keys``): ``balls.NAME`` or
``balls[i]`` (i from 1, as in error messages) select an entry of an array of tables,
``key[i]`` (i from 0) one component of a vector; a stream is addressed by its name:
``streams.NAME.gangue_fraction``. Grid axes form a product; random axes (``uniform``,
``loguniform``, ``choice``) share one ``samples`` count; ``follow`` sets a key to
``scale * value + offset`` of another swept key. The design and its expansion into cases
(draws, seeds, labels): ``tailbeam.study.design``.
"""

import copy
import math
import sys
from dataclasses import dataclass
from pathlib import Path

from tailbeam.errors import InputError, require_positive
from tailbeam.io.scene_file import _check_keys
from tailbeam.solvers.modal_setup.band import BAND_ACCURACY
from tailbeam.study.scene_keys import _field, _segments, set_value

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

SWEEP_KEYS = ("scene", "repeats", "seed", "labels", "axes", "band_accuracy")
DISTRIBUTIONS = {
    "uniform": ("low", "high"),
    "loguniform": ("low", "high"),
    "choice": ("values",),
}


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
    """A validated sweep file: the base scene table, axes, repeats, seed, coal materials,
    the largest band-check estimate of a case's peak-force error it accepts as valid, and
    the folder the cases' paths (``plate.mesh``) are relative to: the base scene file's, or
    the sweep file's for an inline scene."""

    base: dict
    axes: tuple
    repeats: int = 1
    seed: int = 0
    coal: tuple = ("coal",)
    text: str = ""
    band_accuracy: float = BAND_ACCURACY
    base_dir: str = "."


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
    scene_dir = Path(base_dir)
    if isinstance(data["scene"], str):  # the scene's own paths are relative to its file
        scene_dir = (scene_dir / data["scene"]).parent
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
        band_accuracy=_accuracy(data.get("band_accuracy", BAND_ACCURACY)),
        base_dir=str(scene_dir),
    )


def _accuracy(value) -> float:
    ok = isinstance(value, int | float) and not isinstance(value, bool)
    if not ok or not math.isfinite(value) or value <= 0.0:
        raise InputError("band_accuracy", f"must be a number > 0 (0.005: 0.5 %), got {value!r}")
    return float(value)


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
