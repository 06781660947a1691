"""Dotted scene keys of a sweep (``balls.rock.radius``, ``balls[2].position[0]``) and setting
their values in a raw scene table.

``balls.NAME`` or ``balls[i]`` (i from 1, as in error messages) select an entry of an array of
tables (by its ``name``; an entry without one, a support, by its ``group``:
``plate.supports.jack.stiffness``), ``key[i]`` (i from 0) one component of a vector; errors
name the axis as the sweep file writes it (``axes."KEY"``).
"""

import re

from tailbeam.errors import InputError

_SEGMENT = re.compile(r"^([A-Za-z_][\w-]*)(?:\[(\d+)\])?$")


def _field(key: str) -> str:
    return f'axes."{key}"'


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
        if t.get("name", t.get("group")) == name:
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
