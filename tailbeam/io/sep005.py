"""Sensor records as SEP005 channels: the time-series convention of the SDyPy structural
dynamics packages (a list of dicts, one per channel, with ``data``, ``fs``, ``name`` and
``unit_str``), to hand a simulation's signals to those packages in Python.

SEP005 defines no file: these are Python objects, not an export format.
"""

import numpy as np


def sep005_channels(result, *, group: str | None = None) -> list:
    """SEP005 channels of a simulation's sensor records.

    Parameters
    ----------
    result : tailbeam.Result
        A run on a modal plate with sensors (``result.sensor_outputs``; none on a rigid plate).
    group : str, optional
        The channels' ``group`` (e.g. the scene or case name).

    Returns
    -------
    list of dict
        One dict per sensor, in the scene's order: ``name``, ``data`` (float64, m/s^2, the
        samples of ``result.sensor_signals``), ``fs`` (the sensor's sample rate, Hz),
        ``unit_str`` "m/s^2", ``quantity`` "a" (acceleration), and ``group`` if given.
    """
    out = []
    for name, sensor in result.sensor_outputs.items():
        channel = {
            "name": str(name),
            "data": np.asarray(sensor.acceleration, dtype=np.float64),
            "fs": float(sensor.chain.sample_rate),
            "unit_str": "m/s^2",
            "quantity": "a",
        }
        if group is not None:
            channel["group"] = group
        out.append(channel)
    return out
