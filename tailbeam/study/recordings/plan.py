"""Every check of ``tailbeam import`` made before anything is written, and what it chose: the
files and their labels rows, each file's rate, units and channel order, the common rate, the
cut and the case length."""

import hashlib
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from tailbeam.errors import InputError
from tailbeam.study.recordings.cut import CUTS
from tailbeam.study.recordings.formats.readers import open_recording
from tailbeam.study.recordings.labels import Row, read_labels
from tailbeam.study.recordings.onsets import OnsetOptions
from tailbeam.study.recordings.resample import ratio
from tailbeam.study.recordings.units import factor, same_unit

MIN_WINDOW = 16  # samples: the shortest case `features` accepts


@dataclass
class Source:
    """One file as it will be read: its labels row, what the file said, the factors to m/s^2
    and the sensor order."""

    path: Path
    row: Row
    reader: str
    channels: list
    rate: float
    units: list  # the unit of each channel, from the file or the labels row
    factors: np.ndarray  # per channel of ``order``: to m/s^2 (and digital full scale)
    order: list  # channel index of each sensor
    n_samples: int
    up: int = 1
    down: int = 1
    n_out: int = 0
    sha256: str = ""
    details: dict = field(default_factory=dict)

    def provenance(self, given: str) -> dict:
        return {
            "file": given,
            "sha256": self.sha256,
            "reader": self.reader,
            "channels": self.channels,
            "sample_rate_hz": self.rate,
            "units": self.units,
            "samples": self.n_samples,
            "resample_up_down": [self.up, self.down],
            **self.details,
        }


@dataclass
class Plan:
    """What the import will do (see tailbeam.study.recordings.driver)."""

    sources: list
    sensors: list
    fs: float
    cut: str
    n_time: int  # samples per case
    pre: int  # samples before an onset (cut "impacts")
    onsets: OnsetOptions
    coords: list  # labels columns that become coordinates of case
    labels_path: Path
    notes: list
    case_ids: dict = field(default_factory=dict)  # labels column -> one value per source


def sha256(path: Path) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 22), b""):
            digest.update(chunk)
    return digest.hexdigest()


def _rate(rec, row, labels_name) -> float:
    given = row.get("sample_rate")
    where = row.field(labels_name, "sample_rate")
    if given is not None:
        try:
            given = float(given)
        except ValueError:
            raise InputError(where, f"must be a number, got {given!r}") from None
        if not given > 0:
            raise InputError(where, f"must be > 0 Hz, got {given}")
    if rec.sample_rate is None and given is None:
        raise InputError(str(rec.path), "does not say its sample rate; give it in the labels "
                         "file's sample_rate column")  # fmt: skip
    if rec.sample_rate is not None and given is not None:
        if abs(rec.sample_rate - given) > 1e-6 * given:
            raise InputError(where, f"{given:g} Hz disagrees with the file's {rec.sample_rate:g}")
    return rec.sample_rate if rec.sample_rate is not None else given


def _units(rec, row, labels_name) -> tuple:
    """(unit of each channel, factor of each channel to m/s^2)."""
    given = row.get("unit")
    where = row.field(labels_name, "unit")
    if given is not None:
        factor(str(given), where)
    units = []
    for channel, unit in zip(rec.channels, rec.units, strict=True):
        if unit is None and given is None:
            raise InputError(str(rec.path), f"channel {channel!r} does not say its unit; give "
                             "it in the labels file's unit column")  # fmt: skip
        if unit is not None:
            factor(unit, f"{rec.path}: channel {channel!r} unit")
            if given is not None and not same_unit(unit, str(given)):
                raise InputError(where, f"{given!r} disagrees with the file's {unit!r}")
        units.append(unit if unit is not None else str(given))
    scale = 1.0
    if rec.full_scale:
        fs_cell = row.get("full_scale")
        if given is None:
            raise InputError(str(rec.path), "holds integer samples; the labels file's unit "
                             "column must say the unit of full scale")  # fmt: skip
        scale = _positive(fs_cell, row.field(labels_name, "full_scale")) if fs_cell else 1.0
    return units, np.array([factor(u, "unit") * scale for u in units])


def _positive(value, where) -> float:
    try:
        value = float(value)
    except ValueError:
        raise InputError(where, f"must be a number, got {value!r}") from None
    if not value > 0:
        raise InputError(where, f"must be > 0, got {value}")
    return value


def _source(given: str, rows_by_file: dict, labels_name: str) -> Source:
    path = Path(given)
    rec = open_recording(path)  # unknown extension, missing file, unreadable: one line
    try:
        row = rows_by_file.get(path.resolve())
        if row is None:
            raise InputError(given, f"has no row in {labels_name} (its 'file' column)")
        if rec.n_samples < 1:
            raise InputError(given, "holds no samples")
        rate = _rate(rec, row, labels_name)
        units, factors = _units(rec, row, labels_name)
        order = list(range(len(rec.channels)))
        return Source(path, row, rec.reader, list(rec.channels), rate, units, factors, order,
                      rec.n_samples, details=rec.details)  # fmt: skip
    finally:
        rec.close()


def _match_sensors(sources: list, files: list, notes: list) -> list:
    """The first file's channels are the sensors; every file must have the same set (a file
    whose order differs is said in ``notes``)."""
    sensors = sources[0].channels
    for src, given in zip(sources, files, strict=True):
        if sorted(src.channels) != sorted(sensors):
            raise InputError(given, f"channels {src.channels} differ from the sensors {sensors} "
                             f"of {files[0]}; every file needs the same channel names")  # fmt: skip
        src.order = [src.channels.index(s) for s in sensors]
        src.factors = src.factors[src.order]
        if src.order != sorted(src.order):
            notes.append(f"{given}: channels {src.channels} taken as sensors {sensors}")
    return sensors


def build_plan(files, labels, *, sample_rate=None, cut="file", length=None, pre=0.005,
               onsets=None) -> Plan:  # fmt: skip
    """Check everything; the Plan of the import, or InputError (one line). ``onsets``:
    OnsetOptions (default: its defaults)."""
    onsets = onsets or OnsetOptions()
    if cut not in CUTS:
        raise InputError("--cut", f"must be one of {', '.join(CUTS)}, got {cut!r}")
    if sample_rate is not None and not sample_rate > 0:
        raise InputError("--sample-rate", f"must be > 0 Hz, got {sample_rate}")
    rows, coords = read_labels(labels)
    name = Path(labels).name
    by_file = {r.file: r for r in rows}
    sources = [_source(str(f), by_file, name) for f in files]
    seen = {}
    for f, src in zip(files, sources, strict=True):
        if src.path.resolve() in seen:
            raise InputError(str(f), f"is given twice (also as {seen[src.path.resolve()]})")
        seen[src.path.resolve()] = str(f)
    notes = []
    sensors = _match_sensors(sources, [str(f) for f in files], notes)
    fs = float(sample_rate) if sample_rate else min(s.rate for s in sources)
    _resampling(sources, fs, notes)
    onsets.check(fs)
    n_time, n_pre = _case_length(sources, fs, cut, length, pre, onsets, [str(f) for f in files],
                                 notes)  # fmt: skip
    ids = _case_ids(sources, coords, cut, name)
    for src in sources:
        src.sha256 = sha256(src.path)
    return Plan(sources, sensors, fs, cut, n_time, n_pre, onsets, coords, Path(labels), notes, ids)


def _case_ids(sources, coords, cut, labels_name) -> dict:
    """With one case per file, the labels' ``case`` (unique integers) and ``case_hash``
    (unique) columns are the cases' ids and hashes; they leave ``coords``."""
    out = {}
    if cut != "file":
        return out
    for column, kind in (("labels_case", int), ("labels_case_hash", str)):
        if column not in coords:
            continue
        values = []
        for src in sources:
            value = src.row.get(column)
            where = src.row.field(labels_name, column[len("labels_") :])
            if value is None or (kind is int and float(value) != int(float(value))):
                raise InputError(where, f"must be {'an integer' if kind is int else 'given'}")
            values.append(kind(int(float(value))) if kind is int else str(value))
        if len(set(values)) != len(values):
            raise InputError(f"{labels_name}: {column[len('labels_') :]}", "values must differ")
        coords.remove(column)
        out[column] = values
    return out


def _resampling(sources, fs, notes) -> None:
    for src in sources:
        src.up, src.down = ratio(src.rate, fs, "--sample-rate")
        src.n_out = math.ceil(src.n_samples * src.up / src.down)
        got = src.rate * src.up / src.down
        if abs(got - fs) > 1e-9 * fs:
            notes.append(f"{src.path}: {src.rate:g} Hz x {src.up}/{src.down} gives {got:.6f} Hz, "
                         f"{(got - fs) / fs * 1e6:+.2f} ppm off {fs:g} Hz")  # fmt: skip
    rates = sorted({s.rate for s in sources})
    if len(rates) > 1 or rates[0] != fs:
        notes.append(f"resampled to {fs:g} Hz (from {', '.join(f'{r:g}' for r in rates)} Hz) "
                     "with scipy.signal.resample_poly")  # fmt: skip


def _case_length(sources, fs, cut, length, pre, onsets, files, notes) -> tuple:
    if cut == "file":
        if length is not None:
            raise InputError("--length", "applies to --cut fixed or impacts only")
        n_time = min(s.n_out for s in sources)
        longer = [f for f, s in zip(files, sources, strict=True) if s.n_out > n_time]
        if longer:
            notes.append(f"cases cut to the shortest record, {n_time / fs:g} s: {len(longer)} "
                         f"longer file(s) lose their end, e.g. {longer[0]}")  # fmt: skip
        if n_time < MIN_WINDOW:
            raise InputError(files[0], f"is shorter than {MIN_WINDOW} samples")
        return n_time, 0
    if length is None:
        length = 0.1 if cut == "impacts" else None
        if length is None:
            raise InputError("--length", "is required with --cut fixed (the window, s)")
        notes.append(f"impact windows of {length:g} s (--length), {pre:g} s before each onset")
    n_time = int(round(length * fs))
    if n_time < MIN_WINDOW:
        raise InputError(
            "--length", f"must span at least {MIN_WINDOW} samples, {MIN_WINDOW / fs:g} s"
        )
    for f, s in zip(files, sources, strict=True):
        if s.n_out < n_time:
            raise InputError(f, f"is shorter than --length, {s.n_out / fs:g} s")
    n_pre = 0
    if cut == "impacts":
        n_pre = int(round(pre * fs))
        if not 0 <= n_pre < n_time:
            raise InputError("--pre", f"must be >= 0 s and below --length, got {pre}")
    return n_time, n_pre
