"""Writing a Scene back as scene-file TOML (the inverse of ``tailbeam.io.scene_file``).

``scene_to_dict`` gives the table with the scene-file keys (echoed into impacts.json and the
sweep's provenance); ``dumps_scene`` its TOML text, with ``loads_scene(dumps_scene(s)) == s``.
"""

import math

from tailbeam.physics.materials import BUILTIN_MATERIALS
from tailbeam.scene import Scene
from tailbeam.streams.generator import default_label

MATERIAL_KEYS = ("density", "youngs_modulus", "poisson_ratio")


def _structure(plate: dict, m) -> None:
    """A structure from a mesh: its keys replace the flat plate's (size, boundary, theory,
    mesh_divisions), which the scene reader refuses beside ``mesh``."""
    for key in ("size", "boundary", "theory", "mesh_divisions"):
        plate.pop(key, None)
    plate.update(mesh=m.mesh, impact_face=m.impact_face)
    keys = ("kind", "group", "region", "stiffness", "direction", "axis")
    plate["supports"] = [
        {k: _plain(getattr(s, k)) for k in keys if getattr(s, k) is not None} for s in m.supports
    ]


def _plain(value):
    """Tuples (of tuples) as lists, for TOML."""
    return [_plain(v) for v in value] if isinstance(value, tuple) else value


def scene_to_dict(scene: Scene) -> dict:
    """The scene as a table with the scene-file keys (for echoing into results, or dumping)."""
    c = scene.contact
    p = scene.plate
    plate = {
        "model": scene.plate_model,
        "material": p.material.name,
        "size": [p.size_x, p.size_y, p.thickness],
    }
    if scene.inclination != 0.0:  # written only when set: earlier scenes echo as before
        plate["inclination"] = scene.inclination
    if scene.plate_model == "modal" and scene.modal is not None:
        m = scene.modal
        plate.update(
            boundary=m.boundary,
            theory=m.theory,
            damping_ratio=m.damping_ratio,
            residual_flexibility=m.residual_flexibility,
            coupling=m.coupling,
        )
        if m.rayleigh is not None:
            plate["rayleigh"] = list(m.rayleigh)
        if m.fmax_hz is not None:
            plate["fmax"] = m.fmax_hz
        if m.mesh_divisions is not None:
            plate["mesh_divisions"] = m.mesh_divisions
        # always written: the default changed ("quasi-static" -> "auto") and a dumped scene
        # (a sweep case, impacts.json) must mean the same run whatever the default is
        plate.update(tail=m.tail, tail_modes=m.tail_modes_for(scene.needs_stream_solver))
        if m.mesh is not None:
            _structure(plate, m)
    used = {b.material for b in scene.balls} | {p.material}
    used |= {m for s in scene.streams for m in (s.coal_material, s.gangue_material)}
    materials = {
        m.name: {k: getattr(m, k) for k in MATERIAL_KEYS}
        for m in sorted(used, key=lambda m: m.name)
        if BUILTIN_MATERIALS.get(m.name) != m
    }
    out = {"duration": scene.duration, "sample_rate": scene.sample_rate, "gravity": scene.gravity}
    out["contact"] = {
        "exponent": c.exponent,
        "damping": c.damping,
        "penetration": c.penetration,
        "clamp": c.clamp,
    }
    if scene.friction is not None:  # written only when set: frictionless scenes echo as before
        out["contact"]["friction"] = scene.friction.values()
    out["plate"] = plate
    if materials:
        out["materials"] = materials
    out["balls"] = [_ball(b, label) for b, label in zip(scene.balls, scene.labels, strict=True)]
    sensors = []
    for s in scene.sensors:
        d = {"name": s.name, "position": list(s.position), "sample_rate": s.sample_rate}
        if s.bandwidth_hz is not None:
            d["bandwidth"] = s.bandwidth_hz
        if s.mounted_resonance_hz is not None:
            d["mounted_resonance"] = s.mounted_resonance_hz
        if s.noise is not None:
            n = s.noise
            d["noise"] = {"rms": n.rms, "background": n.background, "band": list(n.band_hz)}
            d["noise"]["seed"] = n.seed
        if s.direction is not None:
            d["direction"] = list(s.direction)
        if s.axes is not None:
            d["axes"] = s.axes
        sensors.append(d)
    if sensors:
        out["sensors"] = sensors
    if scene.streams:
        out["streams"] = [stream_to_dict(s) for s in scene.streams]
    return out


def _ball(ball, label: str) -> dict:
    d = {
        "name": ball.name,
        "material": ball.material.name,
        "radius": ball.radius,
        "position": list(ball.position),
        "velocity": list(ball.velocity),
    }
    if any(ball.angular_velocity):  # written only when set
        d["angular_velocity"] = list(ball.angular_velocity)
    if label != default_label(ball):  # written only when not the default
        d["label"] = label
    return d


def stream_to_dict(s) -> dict:
    """The ``[[streams]]`` keys of validated settings (tailbeam.streams.generator)."""
    from tailbeam.streams.generator import DISTRIBUTIONS

    d = {
        "name": s.name,
        "rate": s.rate,
        "start": s.start,
        "stop": s.stop,
        "gangue_fraction": s.gangue_fraction,
        "coal_material": s.coal_material.name,
        "gangue_material": s.gangue_material.name,
        "radius": list(s.radius),
        "size_distribution": s.size_distribution,
    }
    d.update(zip(DISTRIBUTIONS[s.size_distribution], s.size_parameters, strict=True))
    d["area"] = [list(s.area[0]), list(s.area[1])]
    d["height"] = s.height[0] if s.height[0] == s.height[1] else list(s.height)
    d.update(velocity=list(s.velocity), velocity_spread=s.velocity_spread, seed=s.seed)
    d["max_tries"] = s.max_tries
    if s.angular_velocity_spread > 0.0:  # written only when set
        d["angular_velocity_spread"] = s.angular_velocity_spread
    return d


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else ("nan" if v != v else ("inf" if v > 0 else "-inf"))
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {_toml_value(x)}" for k, x in v.items()) + " }"
    return "[" + ", ".join(_toml_value(x) for x in v) + "]"


def dumps_scene(scene: Scene) -> str:
    """The scene as scene-file TOML text (``loads_scene(dumps_scene(s)) == s``)."""
    d = scene_to_dict(scene)
    lines = [f"{k} = {_toml_value(d[k])}" for k in ("duration", "sample_rate", "gravity")]
    for section in ("contact", "plate"):
        lines += ["", f"[{section}]"] + [f"{k} = {_toml_value(v)}" for k, v in d[section].items()]
    for name, props in d.get("materials", {}).items():
        lines += ["", f"[materials.{name}]"] + [f"{k} = {_toml_value(v)}" for k, v in props.items()]
    for array in ("balls", "sensors", "streams"):
        for entry in d.get(array, []):
            lines += ["", f"[[{array}]]"] + [f"{k} = {_toml_value(v)}" for k, v in entry.items()]
    return "\n".join(lines) + "\n"
