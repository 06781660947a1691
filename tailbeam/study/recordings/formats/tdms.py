"""NI TDMS files (npTDMS, streamed). Every channel with data is a channel, named by its
channel name (``group/channel`` when two groups use one name). The rate is 1 /
``wf_increment`` (s); the unit is the ``unit_string`` property. All channels must share the
rate and the length."""

from pathlib import Path

from tailbeam.errors import InputError
from tailbeam.study.recordings.formats.recording import Recording, check_channels


def _channels(tdms) -> list:
    chans = [c for g in tdms.groups() for c in g.channels() if len(c) > 0]
    short = [c.name for c in chans]
    return [(c.name if short.count(c.name) == 1 else f"{c.group_name}/{c.name}", c) for c in chans]


def _rate(path, chans) -> float | None:
    incs = {c.properties.get("wf_increment") for _n, c in chans}
    if incs == {None}:
        return None
    if len(incs) > 1:
        raise InputError(str(path), f"channels differ in wf_increment: {sorted(map(str, incs))}")
    inc = float(incs.pop())
    if not inc > 0:
        raise InputError(str(path), f"wf_increment must be > 0 s, got {inc}")
    return 1.0 / inc


def open_tdms(path: Path) -> Recording:
    from nptdms import TdmsFile

    try:
        tdms = TdmsFile.open(path)
        chans = _channels(tdms)
    except Exception as err:  # npTDMS raises ValueError, KeyError, struct errors
        raise InputError(str(path), f"not a readable TDMS file ({err})") from None
    names = [n for n, _c in chans]
    lengths = [len(c) for _n, c in chans]
    check_channels(path, names, lengths)
    units = [str(c.properties.get("unit_string", "") or "").strip() or None for _n, c in chans]

    def read(start, stop):
        import numpy as np

        return np.stack([c.read_data(start, stop - start) for _n, c in chans])

    return Recording(
        path=path,
        reader="tdms (npTDMS)",
        channels=names,
        sample_rate=_rate(path, chans),
        units=units,
        n_samples=lengths[0] if lengths else 0,
        read=read,
        close=tdms.close,
    )
