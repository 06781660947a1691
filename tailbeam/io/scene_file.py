"""Scene files (TOML): read, validate and write back.

The keys are a contract with users (docs/scene-files.md): they may be extended, never renamed.
Every problem becomes ``InputError(field, rule)`` naming the offending key (``balls[2].radius``,
balls counted from 1) and the rule; misspelled keys get the closest valid key as a suggestion.
Omitted optional keys take the defaults of ``tailbeam.scene``.
"""

import difflib
import re
import sys
from pathlib import Path

from tailbeam.errors import (
    InputError,
    require_nonnegative,
    require_positive,
    require_real,
    require_vector,
)

# writing back lives in tailbeam.io.scene_dump; re-exported so existing imports keep working
from tailbeam.io.scene_dump import MATERIAL_KEYS
from tailbeam.physics.bodies import Ball, Plate, check_ball_above_plate
from tailbeam.physics.friction import KEYS as FRICTION_VALUE_KEYS
from tailbeam.physics.friction import FrictionModel, FrictionSettings
from tailbeam.physics.incline import InclinedPlate
from tailbeam.physics.materials import Material, get_material
from tailbeam.plate.solid.held import held_structure
from tailbeam.plate.solid.supports import Support, check_support
from tailbeam.preflight import check_scene
from tailbeam.preflight import magnitudes as plausible
from tailbeam.scene import (
    LABELS,
    ContactSettings,
    ModalPlateSettings,
    Scene,
    SensorSpec,
)
from tailbeam.signals.noise import NoiseSpec
from tailbeam.streams.generator import default_label, parse_stream

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

TOP_KEYS = (
    "duration",
    "sample_rate",
    "gravity",
    "contact",
    "plate",
    "materials",
    "balls",
    "sensors",
    "streams",
)
SENSOR_NAME = re.compile(r"[A-Za-z0-9_.+-]+")  # used in file names (sensor_<name>.png)
CONTACT_KEYS = ("exponent", "damping", "penetration", "clamp", "friction")
FRICTION_KEYS = FRICTION_VALUE_KEYS + ("pairs",)
FRICTION_PAIR_KEYS = ("materials",) + FRICTION_VALUE_KEYS
PLATE_KEYS = ("model", "material", "size", "inclination")
MODAL_KEYS = (
    "boundary",
    "theory",
    "damping_ratio",
    "rayleigh",
    "fmax",
    "mesh_divisions",
    "residual_flexibility",
    "coupling",
    "tail",
    "tail_modes",
    "mesh",
    "impact_face",
    "supports",
)
FLAT_ONLY = ("size", "boundary", "theory", "mesh_divisions")  # the flat plate's, not a mesh's
FREE_HINT = "add supports, or ask for a free structure"  # the library's words, not a scene's
SUPPORT_KEYS = ("kind", "group", "region", "stiffness", "direction", "axis")
BALL_KEYS = ("name", "material", "radius", "position", "velocity", "label", "angular_velocity")
SENSOR_KEYS = ("name", "position", "sample_rate", "bandwidth", "mounted_resonance", "noise",
               "direction", "axes")  # fmt: skip
FLAT_SURFACE_TOLERANCE = 1e-3  # of the thickness: a flat plate's point (x, y, z) off a face
NOISE_KEYS = ("rms", "background", "band", "seed")
REQUIRED = ("duration", "balls")  # or duration and streams


def load_scene(path) -> Scene:
    """Read and validate the scene file at ``path``. OSError if it cannot be read."""
    path = Path(path)
    data = path.read_bytes()
    try:
        text = data.decode("utf-8-sig")  # a UTF-8 byte-order mark (Windows editors) is fine
    except UnicodeDecodeError as err:
        line = data[: err.start].count(b"\n") + 1
        raise InputError(
            path.name, f"is not UTF-8 text (invalid byte 0x{data[err.start]:02x} at line {line})"
        ) from None
    return loads_scene(text, source=path.name, base_dir=path.parent)


def loads_scene(text: str, *, source: str = "scene", base_dir=None) -> Scene:
    """Parse TOML ``text``; ``source`` names it in the error of unparseable TOML; paths in
    it (``plate.mesh``) are relative to ``base_dir`` (default the working directory)."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        # The message carries "(at line L, column C)".
        raise InputError(source, f"is not valid TOML: {err}") from None
    return parse_scene(data, base_dir=base_dir)


def parse_scene(data: dict, *, base_dir=None) -> Scene:
    """Build a Scene from the parsed TOML table ``data`` (paths relative to ``base_dir``)."""
    _check_keys("", data, TOP_KEYS, required=("duration",) if "streams" in data else REQUIRED)
    materials = _parse_materials(data.get("materials", {}))
    contact_table = _table("contact", data.get("contact", {}))
    contact = _parse_contact(contact_table)
    plate_table = _table("plate", data.get("plate", {}))
    plate, model, modal = _parse_plate(plate_table, materials, base_dir)
    friction = _parse_friction(contact_table, materials, plate)
    kwargs = {}
    if "inclination" in _table("plate", data.get("plate", {})):
        kwargs["inclination"] = data["plate"]["inclination"]
    if "gravity" in data:
        kwargs["gravity"] = require_nonnegative("gravity", data["gravity"])
        plausible.check_gravity(kwargs["gravity"])
    incline = InclinedPlate(plate, **kwargs)  # validates plate.inclination
    duration = require_positive("duration", data["duration"])
    balls, labels = _parse_balls(data.get("balls", []), materials, plate, "streams" in data)
    streams = _parse_streams(data.get("streams", []), incline, materials)
    sensors = _parse_sensors(data.get("sensors", []), plate, modal)
    if sensors and model != "modal":
        raise InputError("sensors", "need plate.model = 'modal' (a rigid plate does not vibrate)")
    if "sample_rate" in data:
        kwargs["sample_rate"] = require_positive("sample_rate", data["sample_rate"])
    scene = Scene(
        balls,
        plate,
        contact,
        duration,
        plate_model=model,
        modal=modal,
        sensors=sensors,
        streams=streams,
        labels=labels,
        friction=friction,
        **kwargs,
    )
    check_scene(scene)
    return scene


# -- helpers --------------------------------------------------------------------------------------


def _join(prefix: str, key: str) -> str:
    return f"{prefix}.{key}" if prefix else key


def _check_keys(prefix: str, table: dict, allowed, *, required=()) -> None:
    for key in table:
        if key not in allowed:
            close = difflib.get_close_matches(key, allowed, n=1, cutoff=0.6)
            hint = (
                f"; did you mean {close[0]!r}?" if close else f"; valid keys: {', '.join(allowed)}"
            )
            raise InputError(_join(prefix, key), f"unknown key{hint}")
    for key in required:
        if key not in table:
            raise InputError(_join(prefix, key), "is required but missing")


def _table(field: str, value) -> dict:
    if not isinstance(value, dict):
        raise InputError(field, f"must be a table ([{field}]), got {type(value).__name__}")
    return value


def _string(field: str, value) -> str:
    if not isinstance(value, str) or not value:
        raise InputError(field, f"must be a non-empty string, got {value!r}")
    return value


def _bool(field: str, value) -> bool:
    if not isinstance(value, bool):
        raise InputError(field, f"must be true or false, got {value!r}")
    return value


def _whole(field: str, value) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise InputError(field, f"must be a whole number >= 1, got {value!r}")
    return value


def _array_of_tables(field: str, value) -> list:
    if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
        raise InputError(field, f"must be an array of tables ([[{field}]])")
    return value


# -- sections -------------------------------------------------------------------------------------


def _parse_materials(value) -> dict:
    out = {}
    for name, props in _table("materials", value).items():
        field = f"materials.{name}"
        _check_keys(field, _table(field, props), MATERIAL_KEYS, required=MATERIAL_KEYS)
        vals = {k: require_real(f"{field}.{k}", props[k]) for k in MATERIAL_KEYS}
        out[name] = Material(name, **vals)
        plausible.check_material(out[name], field)
    return out


def _parse_contact(table: dict) -> ContactSettings:
    _check_keys("contact", table, CONTACT_KEYS)
    kwargs = {k: require_real(f"contact.{k}", table[k]) for k in CONTACT_KEYS[:3] if k in table}
    if "clamp" in table:
        kwargs["clamp"] = _bool("contact.clamp", table["clamp"])
    return ContactSettings(**kwargs)


def _parse_friction(contact: dict, materials: dict, plate: Plate) -> FrictionModel | None:
    """``[contact.friction]`` and its ``[[contact.friction.pairs]]`` (None if absent)."""
    if "friction" not in contact:
        return None
    table = _table("contact.friction", contact["friction"])
    _check_keys("contact.friction", table, FRICTION_KEYS, required=("static", "dynamic"))
    values = {k: table[k] for k in FRICTION_VALUE_KEYS if k in table}
    model = FrictionModel(FrictionSettings(**values))
    pairs = []
    for k, t in enumerate(_array_of_tables("contact.friction.pairs", table.get("pairs", [])), 1):
        field = f"contact.friction.pairs[{k}]"
        _check_keys(field, t, FRICTION_PAIR_KEYS, required=("materials",))
        names = t["materials"]
        if not isinstance(names, list) or len(names) != 2:
            raise InputError(
                f"{field}.materials", f"must be a list of 2 material names, got {names!r}"
            )
        for name in names:  # built-in, [materials.NAME] or the plate's
            if _string(f"{field}.materials", name) != plate.material.name:
                get_material(name, materials, field=f"{field}.materials")
        values = {key: t[key] for key in FRICTION_VALUE_KEYS if key in t}
        pairs.append(model.pair_settings(k, names, values))
    return FrictionModel(model.default, tuple(pairs))


def _parse_plate(table: dict, materials: dict, base_dir=None):
    model = table.get("model", "rigid")
    allowed = PLATE_KEYS + MODAL_KEYS if model == "modal" else PLATE_KEYS
    for key in table:
        if key in MODAL_KEYS and model != "modal":
            raise InputError(f"plate.{key}", "is only valid with model = 'modal'")
    _check_keys("plate", table, allowed)
    if model not in ("rigid", "modal"):
        raise InputError("plate.model", f"must be 'rigid' or 'modal', got {model!r}")
    kwargs = {}
    if "material" in table:
        name = _string("plate.material", table["material"])
        kwargs["material"] = get_material(name, materials, field="plate.material")
    if "size" in table:
        a, b, h = require_vector("plate.size", table["size"], 3)
        for i, v in enumerate((a, b, h)):
            require_positive(f"plate.size[{i}]", v)
        kwargs.update(size_x=a, size_y=b, thickness=h)
    plate = Plate(**kwargs)
    plausible.check_plate(plate)
    modal = None
    if model == "modal":
        m = {}
        for key in ("boundary", "theory", "coupling", "tail"):
            if key in table:
                m[key] = _string(f"plate.{key}", table[key])
        if "damping_ratio" in table:
            m["damping_ratio"] = require_real("plate.damping_ratio", table["damping_ratio"])
        if "rayleigh" in table:
            m["rayleigh"] = require_vector("plate.rayleigh", table["rayleigh"], 2)
        if "fmax" in table:
            m["fmax_hz"] = require_real("plate.fmax", table["fmax"])
        if "mesh_divisions" in table:
            m["mesh_divisions"] = _whole("plate.mesh_divisions", table["mesh_divisions"])
        if "residual_flexibility" in table:
            m["residual_flexibility"] = _bool(
                "plate.residual_flexibility", table["residual_flexibility"]
            )
        if "tail_modes" in table:
            m["tail_modes"] = table["tail_modes"]  # "auto" or a whole number, checked there
        if "mesh" in table:
            m.update(_parse_structure(table, base_dir))
        for key in ("impact_face", "supports"):
            if key in table and "mesh" not in table:
                raise InputError(f"plate.{key}", "needs plate.mesh (a structure's mesh file)")
        modal = ModalPlateSettings(**m)
        if modal.mesh is not None:  # built now: every check before any work
            plate = _structure_plate(modal, plate.material)
    return plate, model, modal


def _structure_plate(modal: ModalPlateSettings, material) -> Plate:
    """The impact face's rectangle (thickness of material below its centre) of the scene's
    structure, which is built here so that every check of it comes first."""
    try:
        model = held_structure(modal.mesh, modal.impact_face, modal.supports, material)
    except InputError as err:  # a scene has no free structures: say what to add
        raise InputError(err.field, err.rule.replace(FREE_HINT, "add [[plate.supports]]")) from None
    return model.plate


def _parse_structure(table: dict, base_dir) -> dict:
    """``plate.mesh`` (relative to the scene file), ``impact_face`` and ``supports``."""
    for key in FLAT_ONLY:
        if key in table:
            raise InputError(
                f"plate.{key}",
                "is the flat plate's; a structure from plate.mesh takes its shape from the "
                "mesh and is held by plate.supports",
            )
    path = Path(_string("plate.mesh", table["mesh"]))
    if not path.is_absolute():
        path = Path(base_dir or ".") / path
    out = {"mesh": str(path.resolve())}
    if "impact_face" in table:
        out["impact_face"] = _string("plate.impact_face", table["impact_face"])
    rows = _array_of_tables("plate.supports", table.get("supports", []))
    out["supports"] = tuple(_parse_support(f"plate.supports[{i}]", t)
                            for i, t in enumerate(rows, start=1))  # fmt: skip
    return out


def _parse_support(field: str, table: dict) -> Support:
    _check_keys(field, table, SUPPORT_KEYS, required=("kind",))
    kwargs = {"kind": _string(f"{field}.kind", table["kind"])}
    if kwargs["kind"] == "spring" and "stiffness" not in table:
        raise InputError(f"{field}.stiffness", "a spring support needs its stiffness, N/m")
    if "group" in table:
        kwargs["group"] = _string(f"{field}.group", table["group"])
    if "stiffness" in table:
        kwargs["stiffness"] = require_real(f"{field}.stiffness", table["stiffness"])
    for key in ("direction", "axis"):
        if key in table:
            kwargs[key] = tuple(require_vector(f"{field}.{key}", table[key], 3))
    if "region" in table:
        box = table["region"]
        if not (isinstance(box, list) and len(box) == 3):
            raise InputError(f"{field}.region", "must be [[x0, x1], [y0, y1], [z0, z1]] m")
        kwargs["region"] = tuple(
            tuple(require_vector(f"{field}.region[{i}]", r, 2)) for i, r in enumerate(box, 1)
        )
    return check_support(Support(**kwargs), field)


def _parse_balls(value, materials: dict, plate: Plate, has_streams: bool) -> tuple:
    """The balls and their labels (``label`` or the default of tailbeam.scene)."""
    tables = _array_of_tables("balls", value)
    if not tables and not has_streams:
        raise InputError("balls", "a scene needs at least one [[balls]] entry")
    balls, labels = [], []
    for i, t in enumerate(tables, start=1):
        field = f"balls[{i}]"
        _check_keys(field, t, BALL_KEYS, required=("name", "material", "radius", "position"))
        name = _string(f"{field}.name", t["name"])
        material = get_material(
            _string(f"{field}.material", t["material"]), materials, field=f"{field}.material"
        )
        radius = require_positive(f"{field}.radius", t["radius"])
        plausible.check_radius(f"{field}.radius", radius, plate)
        position = require_vector(f"{field}.position", t["position"], 3)
        plausible.check_height(f"{field}.position", position[2], plate)
        velocity = require_vector(f"{field}.velocity", t.get("velocity", (0.0, 0.0, 0.0)), 3)
        plausible.check_speed(f"{field}.velocity", velocity)
        spin = require_vector(f"{field}.angular_velocity", t.get("angular_velocity", (0, 0, 0)), 3)
        ball = Ball(name, material, radius, position, velocity, spin)
        try:
            check_ball_above_plate(ball, plate)
        except InputError as err:
            raise InputError(f"{field}.position", err.rule) from None
        if not plate.contains(position[0], position[1]):
            raise InputError(
                f"{field}.position",
                f"the centre (x, y) = ({position[0]!r}, {position[1]!r}) m must lie over the "
                f"plate, |x| <= {plate.size_x / 2!r}, |y| <= {plate.size_y / 2!r}"
                + _metres_hint(position[0], position[1], plate),
            )
        balls.append(ball)
        labels.append(default_label(ball))
        if "label" in t:
            labels[-1] = _string(f"{field}.label", t["label"])
            if labels[-1] not in LABELS:
                raise InputError(f"{field}.label", f"must be one of {LABELS}, got {labels[-1]!r}")
    return tuple(balls), tuple(labels)


def _parse_streams(value, incline: InclinedPlate, materials: dict) -> tuple:
    """Validated ``[[streams]]`` settings (tailbeam.streams.generator.parse_stream)."""
    tables = _array_of_tables("streams", value)
    if not tables:
        return ()
    streams = tuple(parse_stream(t, i, incline, materials) for i, t in enumerate(tables, 1))
    for s in streams:
        plausible.check_stream(s, incline.plate)
    return streams


def _metres_hint(x: float, y: float, plate: Plate) -> str:
    """'; positions are in metres (...)' when (x, y) read as millimetres lies over the plate."""
    if plate.contains(x / 1000.0, y / 1000.0):
        return f"; positions are in metres ({x:g} mm = {x / 1000.0:g}, {y:g} mm = {y / 1000.0:g})"
    return ""


def _parse_sensors(value, plate: Plate, modal: ModalPlateSettings | None = None) -> tuple:
    from tailbeam.signals.sensor import (
        resolve,  # scipy.signal: imported only for scenes with sensors
    )

    sensors = []
    for i, t in enumerate(_array_of_tables("sensors", value), start=1):
        field = f"sensors[{i}]"
        _check_keys(field, t, SENSOR_KEYS, required=("name", "position"))
        name = _string(f"{field}.name", t["name"])
        if not SENSOR_NAME.fullmatch(name):
            raise InputError(
                f"{field}.name",
                f"{name!r} may hold only letters, digits and _ . + - (it names output files)",
            )
        kwargs = {}
        for key, arg in (
            ("sample_rate", "sample_rate"),
            ("bandwidth", "bandwidth_hz"),
            ("mounted_resonance", "mounted_resonance_hz"),
        ):
            if key in t:
                kwargs[arg] = require_real(f"{field}.{key}", t[key])
        if "noise" in t:
            kwargs["noise"] = _parse_noise(f"{field}.noise", t["noise"])
        if "direction" in t:
            kwargs["direction"] = t["direction"]
        if "axes" in t:
            kwargs["axes"] = t["axes"]
        try:
            sensors.append(SensorSpec(name, t["position"], **kwargs))
            resolve(sensors[-1])  # the chain's own rules (mounted resonance above the band)
        except InputError as err:  # SensorSpec names itself sensors[<name>]; the file counts
            raise InputError(err.field.replace(f"sensors[{name}]", field), err.rule) from None
        _check_sensor_place(field, sensors[-1], plate, modal)
    _check_sensor_names(sensors)
    return tuple(sensors)


def _check_sensor_names(sensors) -> None:
    """Sensor names, and the signal names of their axes (``<name>_x``...), are unique."""
    seen = set()
    for i, s in enumerate(sensors, start=1):
        if s.name in seen:
            raise InputError(f"sensors[{i}].name", f"{s.name!r} is used by an earlier sensor")
        for c in s.channels():
            if c.name in seen:
                raise InputError(
                    f"sensors[{i}].name", f"signal {c.name!r} is named by an earlier sensor"
                )
            seen.add(c.name)
        seen.add(s.name)


def _check_sensor_place(field: str, spec: SensorSpec, plate: Plate, modal) -> None:
    """A sensor's point lies on the plate or structure; on the flat plate a point (x, y, z)
    lies on its top (z = 0) or bottom (z = -thickness) face."""
    x, y = spec.position[:2]
    structure = modal is not None and modal.mesh is not None
    if len(spec.position) == 3 and structure:
        model = held_structure(modal.mesh, modal.impact_face, modal.supports, plate.material)
        model.surface().locate([spec.position], f"{field}.position")
        return
    if not plate.contains(x, y):
        raise InputError(f"{field}.position", f"({x!r}, {y!r}) m is not on the plate")
    if len(spec.position) == 3:
        z, h = spec.position[2], plate.thickness
        off = min(abs(z), abs(z + h))
        if off > FLAT_SURFACE_TOLERANCE * h:
            raise InputError(
                f"{field}.position",
                f"z = {z!r} m is {off:.3g} m off the flat plate's surface: a point of its top "
                f"face has z = 0, of its bottom face z = {-h!r} m",
            )


def _parse_noise(field: str, value) -> NoiseSpec:
    """``noise = RMS`` (white, m/s^2) or a table with NOISE_KEYS (tailbeam.signals.noise)."""
    table = value if isinstance(value, dict) else {"rms": value}
    _check_keys(field, table, NOISE_KEYS)
    kwargs = {k: table[k] for k in ("rms", "background", "seed") if k in table}
    if "band" in table:
        kwargs["band_hz"] = table["band"]
    try:
        return NoiseSpec(**kwargs)
    except InputError as err:  # NoiseSpec names its fields noise.<key>
        inner = err.field[len("noise") :] if table is value else ""
        raise InputError(field + inner, err.rule) from None
