"""The labels file of ``tailbeam import``: one row per recording file.

Columns: ``file`` (required: the recording's path, relative to the labels file's folder or
absolute); ``label`` (the class); ``sample_rate`` (Hz), ``unit`` and ``full_scale`` (the
value, in ``unit``, of an integer WAV file's digital full scale; default 1) fill in what the
file does not say; ``sensor_x``, ``sensor_y`` (m) place every sensor of the row's cases;
every other column becomes a coordinate of ``case`` unchanged. A column named like one the
import writes itself (``case``, ``case_hash``, ``source_file``, ``t_source``, ``sensor``,
``time``; e.g. in the labels.csv of ``tailbeam export``) is kept as ``labels_<name>``; with
one case per file, ``labels_case`` and ``labels_case_hash`` become the cases' ids and hashes
(tailbeam.study.recordings.plan). Rows are numbered from 1 after the header, as in error
messages (``labels.csv row 3: unit``).
"""

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tailbeam.errors import InputError

RESERVED = ("file", "sample_rate", "unit", "full_scale", "sensor_x", "sensor_y")
# coordinates the import writes itself: a labels column may not take their names
WRITTEN = ("case", "case_hash", "source_file", "t_source", "sensor", "time")
PREFIX = "labels_"  # what a labels column named like one of WRITTEN is kept as


@dataclass
class Row:
    """One row: its number (from 1), the file it names (resolved), and its values."""

    number: int
    file: Path
    values: dict

    def field(self, labels_name: str, column: str) -> str:
        return f"{labels_name} row {self.number}: {column}"

    def get(self, column: str):
        """The row's value of ``column``, or None when the column is absent or the cell empty."""
        value = self.values.get(column)
        if value is None or (isinstance(value, float) and np.isnan(value)) or value == "":
            return None
        return value


def read_labels(path) -> tuple:
    """(rows, coordinate columns) of the labels file at ``path``; InputError (one line) for a
    file without a ``file`` column, an empty cell in it, a missing file or a file named
    twice."""
    import pandas as pd

    path = Path(path)
    try:
        table = pd.read_csv(path)
    except (ValueError, pd.errors.ParserError) as err:
        raise InputError(str(path), f"not a readable CSV file ({err})") from None
    name = path.name
    if "file" not in table.columns:
        raise InputError(str(path), "needs a 'file' column (see docs/recordings.md)")
    table = table.rename(columns={c: PREFIX + c for c in WRITTEN})
    taken = [c for c in table.columns if c.startswith(PREFIX) and c[len(PREFIX) :] not in WRITTEN]
    if taken:
        raise InputError(f"{name}: {taken[0]}", f"the prefix {PREFIX!r} is the import's own")
    rows, seen = [], {}
    for i, record in enumerate(table.to_dict("records"), start=1):
        cell = record["file"]
        if not isinstance(cell, str) or not cell.strip():
            raise InputError(f"{name} row {i}: file", "is empty")
        file = (path.parent / cell.strip()).resolve()
        if not file.is_file():
            raise InputError(f"{name} row {i}: file", f"no such file {cell.strip()!r}")
        if file in seen:
            raise InputError(f"{name} row {i}: file", f"names the file of row {seen[file]} again")
        seen[file] = i
        rows.append(Row(i, file, record))
    return rows, [c for c in table.columns if c not in RESERVED]
