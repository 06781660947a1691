"""Progress and automatic choices on stderr: a bar on a terminal, sparse lines in a log.

Long work (numba compilation, eigen-solves, simulations, sensor replays, sweeps) runs inside
``task(...)``; nothing is shown for work shorter than ``DELAY_S``. On a terminal the bar is
drawn by tqdm; when stderr is a file or a pipe (CI logs, batch jobs) a plain line is written
at most every ``LOG_INTERVAL_S`` seconds and one when the work ends. ``note(...)`` prints one
line, e.g. what was chosen automatically. ``set_quiet(True)`` (the CLI's ``--quiet``) silences
both; errors are never silenced.

>>> with task("eigen-solve", total=3, unit="blocks") as bar:
...     for _ in range(3):
...         bar.update(1)
"""

import contextlib
import sys
import time

DELAY_S = 2.0  # show nothing for work shorter than this (s)
LOG_INTERVAL_S = 10.0  # a line at most this often when stderr is not a terminal (s)

_state = {"quiet": False}


def set_quiet(quiet: bool = True) -> None:
    """Silence (or re-enable) progress and notes for this process."""
    _state["quiet"] = bool(quiet)


def is_quiet() -> bool:
    """True when progress and notes are silenced."""
    return _state["quiet"]


@contextlib.contextmanager
def quiet():
    """Silence progress and notes inside the block (e.g. a sweep's cases), then restore."""
    before = _state["quiet"]
    _state["quiet"] = True
    try:
        yield
    finally:
        _state["quiet"] = before


def note(message: str) -> None:
    """One line on stderr, prefixed ``tailbeam:``, unless quiet."""
    if not _state["quiet"]:
        print(f"tailbeam: {message}", file=sys.stderr, flush=True)


class _LogBar:
    """Sparse progress lines for a non-terminal stderr, shown only after ``DELAY_S``."""

    def __init__(self, description, total, unit):
        self.description, self.total, self.unit = description, total, unit
        self.n = 0
        self.start = time.monotonic()
        self.last = None  # time of the last line written
        self.extra = ""  # set_postfix text, e.g. "3 failed"

    def _line(self, final=False):
        elapsed = time.monotonic() - self.start
        done = f"{self.n:.4g}" + (f"/{self.total:.4g}" if self.total else "")
        unit = f" {self.unit}" if self.unit else ""
        if not self.total and not self.n:  # nothing counted: elapsed time only
            done = unit = ""
        else:
            unit += (f" ({self.extra})" if self.extra else "") + ","
        tail = "done" if final else "..."
        eta = ""
        if not final and self.total and 0 < self.n < self.total:
            eta = f", ~{elapsed * (self.total - self.n) / self.n:.0f} s left"
        print(
            f"tailbeam: {self.description}: {done}{unit} {elapsed:.1f} s{eta} {tail}".replace(
                ":  ", ": "
            ),
            file=sys.stderr,
            flush=True,
        )
        self.last = time.monotonic()

    def update(self, n=1):
        self.n += n
        now = time.monotonic()
        if now - self.start < DELAY_S:
            return
        if self.last is None or now - self.last >= LOG_INTERVAL_S:
            self._line()

    def set_total(self, total):
        self.total = total

    def set_postfix(self, text: str):
        self.extra = text

    def close(self):
        if self.last is not None or time.monotonic() - self.start >= DELAY_S:
            self._line(final=True)


class _TqdmBar:
    """tqdm on a terminal, shown only after ``DELAY_S``."""

    def __init__(self, description, total, unit):
        from tqdm import tqdm

        self._bar = tqdm(
            total=total,
            desc=f"tailbeam: {description}",
            unit=f" {unit}" if unit else "it",
            delay=DELAY_S,
            file=sys.stderr,
            leave=False,
            dynamic_ncols=True,
        )

    def update(self, n=1):
        self._bar.update(n)

    def set_total(self, total):
        self._bar.total = total
        self._bar.refresh()

    def set_postfix(self, text: str):
        self._bar.set_postfix_str(text)

    def close(self):
        self._bar.close()


class _NoBar:
    def update(self, n=1):
        pass

    def set_total(self, total):
        pass

    def set_postfix(self, text: str):
        pass

    def close(self):
        pass


@contextlib.contextmanager
def task(description: str, total: float | None = None, unit: str = ""):
    """Context manager yielding a bar with ``update(n)``, ``set_total(total)`` and
    ``set_postfix(text)`` (a short status shown after the count, e.g. "2 failed").

    Parameters
    ----------
    description : str
        What is being done, e.g. ``"simulating 1.0 s"``.
    total : float, optional
        Amount of work (same unit as ``update``); None when unknown.
    unit : str
        Unit of the work, e.g. ``"ms simulated"``, ``"cases"``.
    """
    if _state["quiet"]:
        bar = _NoBar()
    elif sys.stderr is not None and sys.stderr.isatty():
        bar = _TqdmBar(description, total, unit)
    else:
        bar = _LogBar(description, total, unit)
    try:
        yield bar
    finally:
        bar.close()
