"""Universal File Format, dataset 58 and 58b (pyuff; the file is read whole). Each dataset 58
that is a time response (``func_type`` 1, abscissa type 17 or 0) is a channel, named by its
``id3`` (the sensor name tailbeam writes), or ``ch<rsp_node>`` when ``id3`` is empty or
``NONE`` (``ch<rsp_node>.<rsp_dir>`` when two channels share a node). The rate is
1 / ``abscissa_inc``; the unit is ``ordinate_axis_units_lab`` (empty or ``NONE``: not given).
All channels must share the rate and the length."""

from pathlib import Path

import numpy as np

from tailbeam.errors import InputError
from tailbeam.study.recordings.formats.recording import Recording, check_channels

TIME_ABSCISSA = (0, 17)  # unknown, time


def _name(s: dict) -> str:
    name = str(s.get("id3") or "").strip()
    return name if name and name.upper() != "NONE" else ""


def _names(sets: list) -> list:
    nodes = [int(s.get("rsp_node", 0)) for s in sets]
    out = []
    for s, node in zip(sets, nodes, strict=True):
        fallback = f"ch{node}" if nodes.count(node) == 1 else f"ch{node}.{s.get('rsp_dir', 0)}"
        out.append(_name(s) or fallback)
    return out


def _time_sets(path: Path) -> list:
    import pyuff

    try:
        uff = pyuff.UFF(str(path))
        types = list(uff.get_set_types())
        sets = [uff.read_sets(i) for i, t in enumerate(types) if int(t) == 58]
    except Exception as err:  # pyuff raises bare Exceptions on malformed files
        raise InputError(str(path), f"not a readable UFF file ({err})") from None
    time = [
        s
        for s in sets
        if int(s.get("func_type", 0)) == 1
        and int(s.get("abscissa_spec_data_type", 0)) in TIME_ABSCISSA
    ]
    if not time:
        raise InputError(str(path), "holds no dataset 58 time response (func_type 1)")
    return time


def open_uff(path: Path) -> Recording:
    sets = _time_sets(path)
    names = _names(sets)
    data = [np.asarray(s["data"], dtype=float) for s in sets]
    check_channels(path, names, [len(d) for d in data])
    incs = {float(s.get("abscissa_inc", 0.0)) for s in sets}
    if len(incs) > 1:
        raise InputError(str(path), f"channels differ in abscissa_inc: {sorted(incs)}")
    inc = incs.pop()
    if not inc > 0:
        raise InputError(str(path), f"abscissa_inc must be > 0 s, got {inc}")
    if any(np.iscomplexobj(s["data"]) for s in sets):
        raise InputError(str(path), "holds complex data, not a time record")
    labs = [str(s.get("ordinate_axis_units_lab") or "").strip() for s in sets]
    units = [u if u and u.upper() != "NONE" else None for u in labs]
    stacked = np.stack(data)
    return Recording(
        path=path,
        reader="uff 58 (pyuff)",
        channels=names,
        sample_rate=1.0 / inc,
        units=units,
        n_samples=stacked.shape[1],
        read=lambda start, stop: stacked[:, start:stop],
        details={"binary": [int(s.get("binary", 0)) for s in sets]},
    )
