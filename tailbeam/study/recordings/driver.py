"""The import run: each file read block by block, converted to m/s^2, resampled, searched for
onsets and cut into cases, written chunk by chunk into a temporary folder beside the output,
which replaces the output when everything is written (a failed run writes nothing)."""

import hashlib
import shutil
import tempfile
from pathlib import Path

import numpy as np

from tailbeam._version import __version__
from tailbeam.errors import InputError
from tailbeam.progress import task
from tailbeam.study.recordings.cut import FileCut, FixedCut, Framer, ImpactCut
from tailbeam.study.recordings.formats.readers import open_recording
from tailbeam.study.recordings.onsets import OnsetDetector
from tailbeam.study.recordings.resample import Resampler
from tailbeam.study.recordings.store import SignalWriter, json_attr, write_coordinates, write_tables

CHANNEL_RULE = (
    "WAV ch1, ch2, ...; CSV the column header; UFF 58 id3, else ch<rsp_node>; TDMS the channel "
    "name; MAT/HDF5 the variable or dataset path, name[k] for a matrix column; in the first "
    "file's order, every file with the same set"
)
RESAMPLING = (
    "scipy.signal.resample_poly by a rational factor up/down (Kaiser-window FIR low-pass, "
    "beta 5, cut-off at the lower Nyquist frequency), applied block-wise with overlap; equal "
    "to one call on the whole record"
)


class _Sink:
    """Collects the cases and onsets the cutters hand over and stages the signals."""

    def __init__(self, writer: SignalWriter, plan):
        self.writer, self.fs, self.plan = writer, plan.fs, plan
        self.cases, self.impacts = [], []
        self.source, self.given, self.file_index = None, "", 0

    def new_case(self, start: int) -> int:
        """The new case's position in the store; its id and hash are the labels' (one case
        per file, round trip of an export) or the position and a hash of its source."""
        position = len(self.cases)
        key = f"{self.source.sha256}:{start}:{self.writer.n_time}:{self.fs!r}"
        case_hash = hashlib.sha256(key.encode()).hexdigest()
        ids = self.plan.case_ids
        k = self.file_index
        self.cases.append({
            "case": ids["labels_case"][k] if "labels_case" in ids else position,
            "case_hash": ids["labels_case_hash"][k] if "labels_case_hash" in ids else case_hash,
            "source_file": self.given, "t_source": start / self.fs, "_row": self.source.row,
        })  # fmt: skip
        return position

    def put(self, case, t0, block) -> None:
        self.writer.put(case, t0, block)

    def impact(self, position, index, onset) -> None:
        info = self.cases[position]
        label = info["_row"].get("label")
        self.impacts.append({
            "case": info["case"], "case_hash": info["case_hash"], "ball": -1, "index": index,
            "material": "unknown", "class": None if label is None else str(label),
            "v_in": np.nan, "t_start": onset / self.fs, "partner": "plate",
            "t_source": info["t_source"] + onset / self.fs,
        })  # fmt: skip


def _cutter(plan, sink, src):
    if plan.cut == "file":
        return FileCut(sink, plan.n_time)
    if plan.cut == "fixed":
        return FixedCut(sink, plan.n_time, src.n_out)
    return ImpactCut(sink, plan.n_time, plan.pre, src.n_out)


def _stream(plan, src, sink, bar) -> int:
    """One file through the pipeline; returns the onsets left out (cut "impacts")."""
    rec = open_recording(src.path)
    try:
        resampler = Resampler(src.up, src.down)
        detector = OnsetDetector(plan.fs, len(plan.sensors), plan.onsets)
        framer = Framer(detector.frame_len)
        cutter = _cutter(plan, sink, src)

        def run(frames):
            for x, start in frames:
                cutter.frame(x, start, detector.frame(x, start))

        read = 0
        for block in rec.blocks():
            run(framer.push(resampler.push(block[src.order] * src.factors[:, None])))
            bar.update(block.shape[1] / src.rate)
            read += block.shape[1]
        if read != src.n_samples:  # e.g. blank lines inside a CSV file
            raise InputError(str(src.path), f"gave {read} samples, {src.n_samples} expected")
        run(framer.push(resampler.finish()))
        run(framer.finish())
        return getattr(cutter, "dropped", 0)
    finally:
        rec.close()


def _table(plan, sink):
    import pandas as pd

    rows = []
    for info in sink.cases:
        row = info["_row"]
        rows.append({**{k: v for k, v in info.items() if k != "_row"},
                     **{c: row.values.get(c) for c in plan.coords}})  # fmt: skip
    table = pd.DataFrame(rows)
    for col in plan.coords:  # numbers stay numbers; text stays text
        if table[col].dtype == object:
            table[col] = table[col].map(lambda v: "" if pd.isna(v) else str(v))
    return table


def _positions(plan, sink) -> tuple:
    n, s = len(sink.cases), len(plan.sensors)
    out = []
    for col in ("sensor_x", "sensor_y"):
        values = [info["_row"].get(col) for info in sink.cases]
        column = np.array([np.nan if v is None else float(v) for v in values]).reshape(n, 1)
        out.append(np.broadcast_to(column, (n, s)).copy())
    return out


def _sensor_map(src, sensors) -> dict:
    """channel name in the file -> sensor name."""
    return dict(zip([src.channels[i] for i in src.order], sensors, strict=True))


def _attrs(plan, command: str, files: list) -> dict:
    pairs = list(zip(plan.sources, files, strict=True))
    return {
        "title": "tailbeam import: measured vibration records, labelled",
        "tailbeam_version": __version__,
        "sample_rate_hz": plan.fs,
        "duration_s": plan.n_time / plan.fs,
        "units": "acceleration m/s^2, time s, positions m",
        "sensor_positions_m": "{}",
        "sweep_file": "",
        "case_scenes": {},
        "import_command": command,
        "import_labels_file": str(plan.labels_path),
        "import_sources": json_attr([s.provenance(f) for s, f in pairs]),
        "import_channel_rule": CHANNEL_RULE,
        "import_sensor_map": json_attr({f: _sensor_map(s, plan.sensors) for s, f in pairs}),
        "import_resampling": RESAMPLING,
        "import_cut": json_attr({"cut": plan.cut, "length_s": plan.n_time / plan.fs,
                                 "pre_s": plan.pre / plan.fs, **vars(plan.onsets)}),
        "import_gravity_m_s2": 9.80665,
    }  # fmt: skip


def run_import(plan, out, command: str, files: list) -> dict:
    """Write the dataset of ``plan`` into the folder ``out``; a summary dict."""
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}.import-", dir=out.parent))
    try:
        writer = SignalWriter(tmp / "dataset.zarr", plan.sensors, plan.n_time, plan.fs)
        sink = _Sink(writer, plan)
        total = sum(s.n_samples / s.rate for s in plan.sources)
        dropped = 0
        with task(f"importing {len(files)} files", total=total, unit="s of record") as bar:
            for k, (src, given) in enumerate(zip(plan.sources, files, strict=True)):
                sink.source, sink.given, sink.file_index = src, given, k
                dropped += _stream(plan, src, sink, bar)
        if not sink.cases:
            raise InputError("--cut", "impacts: no onset found above --threshold in any file")
        writer.close(len(sink.cases))
        cases = _table(plan, sink)
        write_coordinates(tmp / "dataset.zarr", cases, plan.sensors, _positions(plan, sink),
                          _attrs(plan, command, files))  # fmt: skip
        write_tables(tmp, cases, sink.impacts)
        _replace(out, tmp)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return {"cases": len(sink.cases), "impacts": len(sink.impacts), "dropped": dropped}


def _replace(out: Path, tmp: Path) -> None:
    if out.exists():
        shutil.rmtree(out)
    tmp.rename(out)


def check_out(out) -> None:
    """``--out`` must be a new folder, an empty one, or an earlier import's output."""
    out = Path(out)
    if not out.exists():
        return
    if not out.is_dir():
        raise InputError("--out", f"{str(out)!r} is a file, not a folder")
    entries = list(out.iterdir())
    if not entries or _is_import(out):
        return
    raise InputError("--out", f"{str(out)!r} is not empty and not an earlier tailbeam import")


def _is_import(out: Path) -> bool:
    try:
        import zarr

        return "import_command" in zarr.open_group(out / "dataset.zarr", mode="r").attrs
    except Exception:  # not a Zarr group: not an import
        return False
