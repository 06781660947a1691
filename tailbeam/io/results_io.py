"""Writing simulation results: impacts.csv/json, particles.csv, timeseries.csv, sensors.csv,
claims tables.

Plain CSV (comma separated, one header line, SI units, floats written with ``repr`` so they
read back bit for bit) and JSON (NaN written as null). No physics here.
"""

import csv
import json
import math
from pathlib import Path

import numpy as np

from tailbeam.results.result import (
    IMPACT_COLUMNS,
    IMPACT_TABLE_UNITS,
    IMPACT_UNITS,
    PARTICLE_UNITS,
)


def _cell(value) -> str:
    if isinstance(value, bool | np.bool_):
        return "true" if value else "false"
    if isinstance(value, float | np.floating):
        return repr(float(value))
    return str(value)


def write_csv(path, header, rows) -> Path:
    """Write ``rows`` (iterables of cells) under ``header`` to ``path``."""
    path = Path(path)
    with path.open("w", newline="") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(header)
        for row in rows:
            w.writerow([_cell(v) for v in row])
    return path


def write_impacts_csv(path, impacts) -> Path:
    """The twelve historical columns (IMPACT_COLUMNS) of single-ball ``Impact`` records, one
    row per contact (units in the manifest); the outputs write ``write_result_tables``."""
    from tailbeam.io.output import describe

    write_csv(path, IMPACT_COLUMNS, ([getattr(i, c) for c in IMPACT_COLUMNS] for i in impacts))
    return describe(path, units=IMPACT_UNITS)


def write_table_csv(path, table: dict, units: dict) -> Path:
    """A table of columns (name -> numpy array, in order) as CSV; units to the manifest."""
    from tailbeam.io.output import describe

    header = list(table)
    write_csv(path, header, zip(*(table[c] for c in header), strict=True))
    return describe(path, units={c: u for c, u in units.items() if c in table})


def write_result_tables(out_dir, result, scene_echo: dict | None = None) -> list:
    """impacts.csv (every column of ``result.impacts_table()``), particles.csv and
    impacts.json of any ``tailbeam.results.result.Result`` into the folder ``out_dir``."""
    out_dir = Path(out_dir)
    return [
        write_table_csv(out_dir / "impacts.csv", result.impacts_table(), IMPACT_TABLE_UNITS),
        write_table_csv(out_dir / "particles.csv", result.particles_table(), PARTICLE_UNITS),
        write_json(out_dir / "impacts.json", result_summary(result, scene_echo)),
    ]


def _jsonable(value):
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple | np.ndarray):
        return [_jsonable(v) for v in value]
    if isinstance(value, bool | np.bool_):
        return bool(value)
    if isinstance(value, int | np.integer):
        return int(value)
    if isinstance(value, float | np.floating):
        value = float(value)
        return value if math.isfinite(value) else None
    return value


def write_json(path, data) -> Path:
    """JSON with NaN/inf as null (strict JSON)."""
    path = Path(path)
    path.write_text(json.dumps(_jsonable(data), indent=2, allow_nan=False) + "\n")
    return path


def result_summary(result, scene_echo: dict | None = None) -> dict:
    """The content of impacts.json: scene echo, units, impacts (the rows of impacts.csv),
    leave events, rest times (single-ball solvers), solver statistics and choices."""
    table = result.impacts_table()
    out = {} if scene_echo is None else {"scene": scene_echo}
    out["units"] = IMPACT_TABLE_UNITS
    rows = zip(*table.values(), strict=True)
    out["impacts"] = [dict(zip(table, row, strict=True)) for row in rows]
    out["leaves"] = [{"ball": e.ball, "time": e.time, "edge": e.edge} for e in result.leaves]
    if result.states is not None:
        out["rest_time"] = dict(result.states.rest_time)
    out["solver"] = {**result.stats, "status": result.status, "message": result.message}
    out["automatic_choices"] = _choices(result.info)
    return out


def _choices(info: dict) -> dict:
    """What was chosen automatically, from a result's ``info`` (objects such as the rigid
    result a one-way run keeps there are left out)."""
    return {k: v for k, v in info.items() if not hasattr(v, "__dataclass_fields__")}


def uniform_grid(duration: float, sample_rate: float) -> np.ndarray:
    """Times k / sample_rate (s) for k = 0, 1, ... up to ``duration`` (s) inclusive."""
    n = int(math.floor(duration * sample_rate * (1.0 + 1e-12))) + 1
    t = np.arange(n, dtype=float) / sample_rate
    return t[t <= duration]


TIMESERIES_UNITS = {"t": "s", "z": "m", "vz": "m/s", "force": "N"}


def timeseries(result, sample_rate: float):
    """(header, columns) of the time series: t, then z_, vz_, force_ per ball.

    On the uniform grid k / sample_rate, so an FFT of a column is valid; the exact force
    peaks are in impacts.csv (peak_force, t_peak), not in this file.
    """
    t = uniform_grid(result.duration, sample_rate)
    states = result.sample(t)
    header, cols = ["t"], [t]
    for name, s in states.items():
        header += [f"z_{name}", f"vz_{name}", f"force_{name}"]
        cols += [s["z"], s["vz"], s["force"]]
    return header, cols


def write_timeseries_csv(path, result, sample_rate: float) -> Path:
    """timeseries.csv on the uniform grid; its units and sample rate go to the manifest."""
    from tailbeam.io.output import describe

    header, cols = timeseries(result, sample_rate)
    write_csv(path, header, zip(*(np.asarray(c, dtype=float) for c in cols), strict=True))
    units = {h: TIMESERIES_UNITS[h.split("_", 1)[0]] for h in header}
    return describe(path, sample_rate_hz=sample_rate, grid="uniform", units=units)


def write_sensors_csv(path, sensor_signals: dict) -> Path:
    """t, then one column per sensor (m/s^2). Sensors sharing a sample rate share the t column;
    if their time bases differ each sensor gets its own t_<name> column."""
    names = list(sensor_signals)
    times = [np.asarray(sensor_signals[n][0], dtype=float) for n in names]
    accs = [np.asarray(sensor_signals[n][1], dtype=float) for n in names]
    if all(t.shape == times[0].shape and np.array_equal(t, times[0]) for t in times):
        header = ["t"] + names
        cols = [times[0]] + accs
        return write_csv(path, header, zip(*cols, strict=True))
    n = max(len(t) for t in times)
    header, cols = [], []
    for name, t, a in zip(names, times, accs, strict=True):
        header += [f"t_{name}", name]
        pad = np.full(n - len(t), np.nan)
        cols += [np.concatenate([t, pad]), np.concatenate([a, pad])]
    return write_csv(path, header, zip(*cols, strict=True))


def write_sensor_spectra_csv(path, sensor_outputs: dict) -> Path:
    """One-sided amplitude spectra (m/s^2 peak) of every sensor: columns freq_<name>,
    amp_<name> per sensor (their frequency grids differ with sample rate and length)."""
    header, cols = [], []
    n = max(len(out.freq) for out in sensor_outputs.values())
    for name, out in sensor_outputs.items():
        pad = np.full(n - len(out.freq), np.nan)
        header += [f"freq_{name}", f"amp_{name}"]
        cols += [np.concatenate([out.freq, pad]), np.concatenate([out.amplitude, pad])]
    return write_csv(path, header, zip(*cols, strict=True))


def write_claims(out_dir, claims, *, stem: str = "claims") -> tuple[Path, Path]:
    """<stem>.csv and <stem>.md: one row per claim with PASS/FAIL and the numbers behind it."""
    out_dir = Path(out_dir)
    header = ("id", "section", "verdict", "statement", "quantity", "threshold", "numbers")
    rows = [
        (
            c.id,
            c.section,
            "PASS" if c.passed else "FAIL",
            c.statement,
            c.quantity,
            c.threshold,
            c.numbers(),
        )
        for c in claims
    ]
    csv_path = write_csv(out_dir / f"{stem}.csv", header, rows)
    md = [
        "| claim | section | verdict | paper (paraphrase) | threshold | numbers |",
        "|---|---|---|---|---|---|",
    ]
    for c in claims:
        cells = [
            c.id,
            c.section,
            "PASS" if c.passed else "**FAIL**",
            c.statement,
            c.threshold,
            c.numbers(3),
        ]
        md.append("| " + " | ".join(s.replace("|", "\\|") for s in cells) + " |")
    md_path = out_dir / f"{stem}.md"
    md_path.write_text("\n".join(md) + "\n")
    return csv_path, md_path
