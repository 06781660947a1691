"""Recordings into cases: the whole file, consecutive fixed windows, or a window around each
impact onset. A cutter is fed the resampled record frame by frame (``frame(x, start,
onsets)``, ``x`` (sensor, k) in m/s^2, ``start`` its first sample, ``onsets`` the onsets
found in it) and hands cases and their onsets to a sink: ``new_case(start)`` -> the case's
id, ``put(case, t0, block)``, ``impact(case, index, onset)`` (onset in samples from the
case's start)."""

import numpy as np

CUTS = ("file", "fixed", "impacts")


class FileCut:
    """The first ``n_time`` samples of the record are one case; its onsets are its impacts."""

    def __init__(self, sink, n_time: int):
        self.sink, self.n_time = sink, n_time
        self.case = sink.new_case(0)
        self.count = 0

    def frame(self, x, start, onsets) -> None:
        if start < self.n_time:
            self.sink.put(self.case, start, x[:, : self.n_time - start])
        for onset in onsets:
            if onset < self.n_time:
                self.count += 1
                self.sink.impact(self.case, self.count, onset)

    def finish(self) -> None:
        pass


class FixedCut:
    """Consecutive windows of ``length`` samples; the incomplete last one is left out."""

    def __init__(self, sink, length: int, n_record: int):
        self.sink, self.length = sink, length
        self.n_cases = n_record // length
        self.ids = [sink.new_case(k * length) for k in range(self.n_cases)]
        self.counts = [0] * self.n_cases

    def frame(self, x, start, onsets) -> None:
        stop = min(start + x.shape[1], self.n_cases * self.length)
        t = start
        while t < stop:
            k = t // self.length
            hi = min(stop, (k + 1) * self.length)
            self.sink.put(self.ids[k], t - k * self.length, x[:, t - start : hi - start])
            t = hi
        for onset in onsets:
            k = onset // self.length
            if k < self.n_cases:
                self.counts[k] += 1
                self.sink.impact(self.ids[k], self.counts[k], onset - k * self.length)

    def finish(self) -> None:
        pass


class ImpactCut:
    """A window of ``length`` samples starting ``pre`` samples before each onset; onsets whose
    window would run past either end of the record are left out (counted in ``dropped``)."""

    def __init__(self, sink, length: int, pre: int, n_record: int):
        self.sink, self.length, self.pre, self.n_record = sink, length, pre, n_record
        self.history = None  # the record from sample self.h0 on
        self.h0 = 0
        self.pending = []  # onsets whose window is not complete yet
        self.dropped = 0

    def frame(self, x, start, onsets) -> None:
        if self.history is None:
            self.history, self.h0 = x, start
        else:
            self.history = np.concatenate([self.history, x], axis=1)
        for onset in onsets:
            lo = onset - self.pre
            if lo < 0 or lo + self.length > self.n_record:
                self.dropped += 1
            else:
                self.pending.append(onset)
        end = self.h0 + self.history.shape[1]
        while self.pending and self.pending[0] - self.pre + self.length <= end:
            self._emit(self.pending.pop(0))
        keep_from = min([end - self.pre, *(o - self.pre for o in self.pending)])
        if keep_from > self.h0:
            self.history = self.history[:, keep_from - self.h0 :]
            self.h0 = keep_from

    def _emit(self, onset: int) -> None:
        lo = onset - self.pre - self.h0
        case = self.sink.new_case(onset - self.pre)
        self.sink.put(case, 0, self.history[:, lo : lo + self.length])
        self.sink.impact(case, 1, self.pre)

    def finish(self) -> None:
        pass


class Framer:
    """Re-cuts blocks of any size into frames of ``size`` samples: ``push`` returns the
    complete frames as (frame, start) pairs, ``finish`` the last, shorter one."""

    def __init__(self, size: int):
        self.size, self.buf, self.start = size, None, 0

    def push(self, block: np.ndarray) -> list:
        self.buf = block if self.buf is None else np.concatenate([self.buf, block], axis=1)
        out = []
        while self.buf.shape[1] >= self.size:
            out.append((self.buf[:, : self.size], self.start))
            self.buf = self.buf[:, self.size :]
            self.start += self.size
        return out

    def finish(self) -> list:
        if self.buf is None or self.buf.shape[1] == 0:
            return []
        out = [(self.buf, self.start)]
        self.start += self.buf.shape[1]
        self.buf = None
        return out
