"""CSV files (pandas, read in chunks). The first row names the columns. A column named
``time``, ``t``, ``time_s`` or ``time [s]`` (any case) holds the time in s and gives the rate
(evenly spaced); every other column is one channel, named by its header. A unit may follow a
channel name in brackets or parentheses, ``ax [g]`` or ``ax (m/s^2)``; the channel is then
named ``ax``. Without a time column the rate comes from the labels file."""

import re
from pathlib import Path

import numpy as np

from tailbeam.errors import InputError
from tailbeam.study.recordings.formats.recording import Recording, check_channels, rate_from_times

TIME_NAMES = ("time", "t", "time_s", "time[s]", "time(s)")
UNIT_IN_NAME = re.compile(r"^(.*?)\s*[\[(]\s*([^\])]+?)\s*[\])]\s*$")
HEAD_ROWS = 1000  # rows read to find the rate from the time column


def _split(header: str):
    match = UNIT_IN_NAME.match(header)
    return (match.group(1), match.group(2)) if match else (header.strip(), None)


def _count_rows(path: Path, n_columns: int) -> int:
    """Data rows of the file (lines after the header, blank ones at the end left out);
    refuses a last row with fewer fields than the header (a file cut short)."""
    lines, tail = 0, b""
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 22), b""):
            lines += chunk.count(b"\n")
            tail = (tail + chunk)[-4096:]
    body = tail.rstrip(b"\r\n \t")
    blank_end = tail.count(b"\n") - body.count(b"\n")  # newlines after the last row
    rows = lines + 1 - blank_end - 1  # lines, plus an unterminated last one, less the header
    last = body.rsplit(b"\n", 1)[-1]
    if rows > 0 and last.count(b",") + 1 != n_columns:
        raise InputError(str(path), f"row {rows} has fewer fields than the header (cut short?)")
    return max(rows, 0)


def open_csv(path: Path) -> Recording:
    import pandas as pd

    try:
        head = pd.read_csv(path, nrows=HEAD_ROWS)
    except (ValueError, pd.errors.ParserError) as err:
        raise InputError(str(path), f"not a readable CSV file ({err})") from None
    columns = [str(c) for c in head.columns]
    is_time = [c.strip().lower().replace(" ", "") in TIME_NAMES for c in columns]
    if sum(is_time) > 1:
        raise InputError(str(path), "has more than one time column")
    keep = [c for c, t in zip(columns, is_time, strict=True) if not t]
    names, units = zip(*(_split(c) for c in keep), strict=True) if keep else ((), ())
    n = _count_rows(path, len(columns))
    check_channels(path, list(names), [n] * len(names))
    non_numeric = [c for c in columns if not pd.api.types.is_numeric_dtype(head[c])]
    if non_numeric:
        raise InputError(str(path), f"column {non_numeric[0]!r} is not numeric")
    rate = rate_from_times(head[columns[is_time.index(True)]], str(path)) if any(is_time) else None

    def read(start: int, stop: int) -> np.ndarray:
        frame = pd.read_csv(path, skiprows=range(1, start + 1), nrows=stop - start, usecols=keep)
        return frame[keep].to_numpy(float).T

    return Recording(
        path=path,
        reader="csv (pandas)",
        channels=list(names),
        sample_rate=rate,
        units=list(units),
        n_samples=n,
        read=read,
        stream=lambda size: _chunks(path, keep, min(size, 1 << 16)),
    )


def _chunks(path, keep, size):
    import pandas as pd

    with pd.read_csv(path, usecols=keep, chunksize=size) as reader:
        for frame in reader:
            block = frame[keep].to_numpy(float).T
            if not np.all(np.isfinite(block)):
                raise InputError(str(path), "holds an empty or non-numeric value")
            yield block
