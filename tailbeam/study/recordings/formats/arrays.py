"""The rule that turns the variables of a MAT or HDF5 file into channels.

Names are matched without regard to case:
- ``fs``, ``sample_rate``, ``sampling_rate``, ``sample_rate_hz`` (a number, Hz) or ``dt``,
  ``wf_increment`` (a number, s): the rate, as a variable or an attribute (HDF5: of the
  channel's dataset, a group above it or the file);
- ``t``, ``time``, ``time_s``: a time vector (s), evenly spaced, which also gives the rate;
- ``unit``, ``units``: text, the unit (of every channel, or of one dataset as its attribute);
- every other numeric vector is one channel, named by the variable (HDF5: its path without
  the leading ``/``); a numeric matrix gives one channel per column, ``name[1]``,
  ``name[2]``, ..., with time along its longer dimension. Numbers with one element are not
  channels, nor are structs, cells or text.
"""

from dataclasses import dataclass, field

import numpy as np

from tailbeam.errors import InputError
from tailbeam.study.recordings.formats.recording import check_channels, rate_from_times

RATE_NAMES = ("fs", "sample_rate", "sampling_rate", "sample_rate_hz")
STEP_NAMES = ("dt", "wf_increment")
TIME_NAMES = ("t", "time", "time_s")
UNIT_NAMES = ("unit", "units")
HEAD = 1000  # samples of a time vector read to check its spacing


@dataclass
class Variable:
    """A named array of a file: ``data`` has ``shape``, ``dtype`` and slicing (a numpy array
    or an h5py Dataset); ``text`` is set for text; ``attrs`` holds its (and its parents')
    attributes, nearest first."""

    name: str
    data: object = None
    text: str | None = None
    attrs: list = field(default_factory=list)


def _leaf(name: str) -> str:
    return name.rsplit("/", 1)[-1].lower()


def _lookup(attrs: list, names: tuple):
    for scope in attrs:
        for key, value in scope.items():
            if key.lower() in names:
                return value
    return None


def _number(value, field_name) -> float:
    try:
        return float(np.asarray(value, dtype=float).ravel()[0])
    except (TypeError, ValueError, IndexError):
        raise InputError(field_name, f"must be a number, got {value!r}") from None


def _rate_of(path, variables, attrs) -> float | None:
    """Rates every source in the file gives; refused when they disagree."""
    found = {}
    for v in variables:
        leaf, numeric = _leaf(v.name), v.data is not None and np.prod(v.data.shape) >= 1
        if numeric and leaf in RATE_NAMES and np.prod(v.data.shape) == 1:
            found[v.name] = _number(v.data[()], f"{path}: {v.name}")
        elif numeric and leaf in STEP_NAMES and np.prod(v.data.shape) == 1:
            found[v.name] = 1.0 / _number(v.data[()], f"{path}: {v.name}")
        elif numeric and leaf in TIME_NAMES and np.prod(v.data.shape) > 1:
            found[v.name] = _rate_of_time(path, v)
    for names, invert in ((RATE_NAMES, False), (STEP_NAMES, True)):
        value = _lookup(attrs, names)
        if value is not None:
            rate = _number(value, f"{path}: attribute {names[0]}")
            found[f"attribute {names[0]}"] = 1.0 / rate if invert else rate
    rates = sorted(set(found.values()))
    if rates and rates[-1] - rates[0] > 1e-6 * rates[-1]:
        raise InputError(str(path), f"its sample rates disagree: {found}")
    return rates[0] if rates else None


def _rate_of_time(path, v) -> float:
    n = int(np.prod(v.data.shape))
    flat = v.data[()] if n <= HEAD else None
    t = np.ravel(flat) if flat is not None else np.ravel(_head(v.data, HEAD))
    rate = rate_from_times(t, f"{path}: {v.name}")
    if flat is None:  # the last value must sit on the same grid
        last = float(np.ravel(_tail(v.data))[-1])
        if abs((last - t[0]) * rate - (n - 1)) > 0.1:
            raise InputError(f"{path}: {v.name}", "time values must be evenly spaced")
    return rate


def _head(data, k):
    return data[:k] if len(data.shape) == 1 else (data[:k, 0] if data.shape[0] > 1 else data[0, :k])


def _tail(data):
    return (
        data[-1:] if len(data.shape) == 1 else (data[-1:, 0] if data.shape[0] > 1 else data[0, -1:])
    )


def _is_channel(v) -> bool:
    if v.data is None or v.data.dtype.kind not in "iuf" or len(v.data.shape) > 2:
        return False
    leaf = _leaf(v.name)
    special = RATE_NAMES + STEP_NAMES + TIME_NAMES
    return leaf not in special and np.prod(v.data.shape) > 1


def _columns(v) -> list:
    """(channel name, reader(start, stop)) of a vector or matrix, time along its longer axis."""
    shape = v.data.shape
    if len(shape) == 1:
        return [(v.name, lambda a, b, d=v.data: d[a:b])]
    if min(shape) == 1:
        along0 = shape[0] > 1
        return [(v.name, lambda a, b, d=v.data, t=along0: d[a:b, 0] if t else d[0, a:b])]
    if shape[0] >= shape[1]:
        return [
            (f"{v.name}[{k + 1}]", lambda a, b, d=v.data, k=k: d[a:b, k]) for k in range(shape[1])
        ]
    return [(f"{v.name}[{k + 1}]", lambda a, b, d=v.data, k=k: d[k, a:b]) for k in range(shape[0])]


def _unit_of(v, file_unit):
    unit = _lookup(v.attrs, UNIT_NAMES) if v.attrs else None
    unit = _text(unit) if unit is not None else None
    return unit or file_unit


def _text(value) -> str:
    if isinstance(value, bytes):
        return value.decode(errors="replace").strip()
    if isinstance(value, np.ndarray):
        return "".join(_text(x) for x in value.ravel())
    return str(value).strip()


def channels(path, variables: list, file_attrs: list):
    """(names, rate or None, units, n_samples, read) of a file's variables (module rule)."""
    texts = [v for v in variables if v.text is not None and _leaf(v.name) in UNIT_NAMES]
    file_unit = texts[0].text if texts else None
    attr_unit = _lookup(file_attrs, UNIT_NAMES)
    file_unit = file_unit or (_text(attr_unit) if attr_unit is not None else None)
    rate = _rate_of(path, variables, file_attrs)
    cols, units = [], []
    for v in filter(_is_channel, variables):
        scoped = _rate_of(path, [], v.attrs) if v.attrs else None
        if scoped is not None and rate is not None and abs(scoped - rate) > 1e-6 * rate:
            raise InputError(str(path), f"{v.name}: its sample rate {scoped} differs from {rate}")
        rate = rate if rate is not None else scoped
        for name, reader in _columns(v):
            cols.append((name, reader))
            units.append(_unit_of(v, file_unit))
    names = [n for n, _r in cols]
    lengths = [max(v.data.shape) for v in filter(_is_channel, variables) for _c in _columns(v)]
    check_channels(path, names, lengths)

    def read(start, stop):
        return np.stack([np.asarray(r(start, stop), dtype=float) for _n, r in cols])

    return names, rate, units, lengths[0], read
