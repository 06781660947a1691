"""Sensor records as UFF 58 files (Universal File Format, dataset 58: a function at a nodal
degree of freedom), written with pyuff, and the ``labels.csv`` that goes beside them.

One file holds one record set (a simulation run or one case of a dataset): one dataset 58 per
sensor, in the sensors' order. Each is a time response (``func_type`` 1) of the acceleration
normal to the impact face (+Z: ``rsp_dir`` 3) at node ``rsp_node`` = sensor index + 1, without
a reference (``ref_node``, ``ref_dir`` 0), on an even time grid from ``abscissa_min`` (s) with
step ``abscissa_inc`` = 1 / sample rate (s). ID lines: ``id1`` "tailbeam <version>", ``id2`` the
record set (case), ``id3`` the sensor name, ``id4`` the label (e.g. coal, gangue, mixed).

Precision. The samples are the float32 values of the signal (as a sweep dataset stores them),
written as real double precision (``ord_data_type`` 4, 12 significant digits): they read back
exactly. pyuff writes single precision (``ord_data_type`` 2) with 6 significant digits, less
than float32 holds, so it is not used. The header of a dataset 58 holds ``abscissa_inc`` with
6 significant digits (format E13.5): 1/51200 s is written 1.95313e-05 s and reads back as
51199.87 Hz (``interval_as_written``). Files are ASCII.

No physics and no Result here: the callers pass arrays and names.
"""

import math
from pathlib import Path

import numpy as np

from tailbeam._version import __version__
from tailbeam.errors import InputError
from tailbeam.progress import note

ID_LINE_CHARS = 80  # UFF ID lines are Format(80A1)
UNIT = "m/s^2"
FUNC_TIME_RESPONSE = 1
DIR_PLUS_Z = 3  # +Z translation: the normal of the impact face
DATA_TIME = 17  # abscissa specific data type: time
DATA_ACCELERATION = 12  # ordinate specific data type: acceleration
REAL_DOUBLE = 4


def interval_as_written(sample_rate: float) -> float:
    """The sample interval (s) as a dataset 58 header holds it: 1 / ``sample_rate`` rounded to
    6 significant digits (E13.5)."""
    return float(f"{1.0 / sample_rate:13.5e}")


def note_interval(sample_rate: float) -> None:
    """Say (stderr) when a dataset 58 header cannot hold 1 / ``sample_rate`` (Hz) exactly."""
    written = interval_as_written(sample_rate)
    if written != 1.0 / sample_rate:
        note(
            f"UFF 58: the sample interval 1/{sample_rate:g} s is written {written:.5e} s "
            f"(6 digits, the format's own): read back as {1.0 / written:.7g} Hz"
        )


def _id_line(field: str, text: str) -> str:
    text = str(text)
    if len(text) > ID_LINE_CHARS or "\n" in text or "\r" in text:
        raise InputError(field, f"must be one line of at most {ID_LINE_CHARS} characters")
    return text


def _dataset(index: int, name: str, values, sample_rate: float, *, case, label, t0) -> dict:
    import pyuff

    data = np.asarray(values, dtype=np.float32).astype(np.float64)  # exact float32 values
    if data.ndim != 1 or len(data) < 2:
        raise InputError(f"sensors[{name}]", "needs a 1-D record of at least 2 samples")
    if not (math.isfinite(sample_rate) and sample_rate > 0):
        raise InputError(f"sensors[{name}].sample_rate", f"must be > 0, got {sample_rate}")
    return pyuff.prepare_58(
        binary=0,
        id1=f"tailbeam {__version__}",
        id2=_id_line("case", case),
        id3=_id_line(f"sensors[{name}]", name),
        id4=_id_line("label", label),
        id5="NONE",
        func_type=FUNC_TIME_RESPONSE,
        rsp_node=index + 1,
        rsp_dir=DIR_PLUS_Z,
        ref_node=0,
        ref_dir=0,
        ord_data_type=REAL_DOUBLE,
        num_pts=len(data),
        abscissa_spacing=1,
        abscissa_min=t0,
        abscissa_inc=1.0 / sample_rate,
        abscissa_spec_data_type=DATA_TIME,
        abscissa_len_unit_exp=0,
        abscissa_force_unit_exp=0,
        abscissa_temp_unit_exp=0,
        abscissa_axis_units_lab="s",
        ordinate_spec_data_type=DATA_ACCELERATION,
        ordinate_len_unit_exp=1,  # length / time^2: UFF exponents count length, force, temp
        ordinate_force_unit_exp=0,
        ordinate_temp_unit_exp=0,
        ordinate_axis_units_lab=UNIT,
        orddenom_spec_data_type=0,
        z_axis_spec_data_type=0,
        data=data,
        x=t0 + np.arange(len(data)) / sample_rate,
    )


def write_uff58(path, signals: dict, sample_rate, *, case: str, label: str = "", t0=0.0) -> Path:
    """Write one record set as a UFF 58 file (ASCII) with one dataset per sensor.

    Parameters
    ----------
    path : path-like
        The file to write (replaced if it exists).
    signals : dict
        Sensor name -> 1-D acceleration record (m/s^2), in the sensors' order.
    sample_rate : float or dict
        Sample rate (Hz) of every record, or sensor name -> sample rate.
    case : str
        The record set's identifier (``id2``), e.g. the scene's or the case's name.
    label : str
        The record set's class (``id4``), e.g. coal, gangue or mixed.
    t0 : float
        Time of the first sample (s).
    """
    if not signals:
        raise InputError("sensors", "no sensor record to write")
    rates = sample_rate if isinstance(sample_rate, dict) else dict.fromkeys(signals, sample_rate)
    sets = [
        _dataset(i, name, values, float(rates[name]), case=case, label=label, t0=float(t0))
        for i, (name, values) in enumerate(signals.items())
    ]
    import pyuff

    path = Path(path)
    path.unlink(missing_ok=True)
    pyuff.UFF(str(path)).write_sets(sets, mode="overwrite")
    return path


def write_labels_csv(path, rows: list) -> Path:
    """``labels.csv`` beside UFF files: one row per file (dicts with ``file`` relative to the
    labels file's folder, ``label``, then the record set's other values, which a reader keeps
    as coordinates); columns in the order of the first row."""
    from tailbeam.io.results_io import write_csv

    header = list(rows[0]) if rows else ["file", "label"]
    return write_csv(path, header, ([row.get(c, "") for c in header] for row in rows))
