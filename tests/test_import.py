"""`tailbeam import` and tailbeam.study.recordings: each reader against files written by an
independent writer (scipy.io.wavfile, pandas, pyuff, npTDMS, scipy.io.savemat, h5py), units
against the definition of g, resampling against the analytic sine and against one
resample_poly call on the whole record, onsets against the times they were planted at, the
whole chain import -> features -> learn on two classes, and bad input refused in one line
with nothing written."""

import hashlib
import json

import numpy as np
import pytest

pytest.importorskip("xarray")
pytest.importorskip("pyuff")
pytest.importorskip("nptdms")
pytest.importorskip("h5py")

from tailbeam.cli.main import main  # noqa: E402
from tailbeam.errors import InputError  # noqa: E402
from tailbeam.study.recordings.formats.readers import open_recording  # noqa: E402
from tailbeam.study.recordings.onsets import OnsetDetector, OnsetOptions  # noqa: E402
from tailbeam.study.recordings.resample import Resampler, ratio  # noqa: E402

G = 9.80665
FS = 2000.0
N = 1000


def _signals(n=N, fs=FS):
    """Two channels: 50 Hz and 130 Hz sines (g)."""
    t = np.arange(n) / fs
    return np.stack([np.sin(2 * np.pi * 50 * t), 0.5 * np.cos(2 * np.pi * 130 * t)])


# -- independent writers, one per format ---------------------------------------------------------


def write_wav_float(path, x, fs=FS):
    from scipy.io import wavfile

    wavfile.write(path, int(fs), x.T.astype(np.float32))


def write_csv(path, x, fs=FS):
    import pandas as pd

    t = np.arange(x.shape[1]) / fs
    pd.DataFrame({"time": t, "ax [g]": x[0], "ay [g]": x[1]}).to_csv(path, index=False)


def _uff58(name, node, data, fs):
    import pyuff

    zeros = dict.fromkeys(("ver_num", "load_case_id", "ref_node", "ref_dir",
                           "abscissa_len_unit_exp", "abscissa_force_unit_exp",
                           "abscissa_temp_unit_exp", "ordinate_force_unit_exp",
                           "ordinate_temp_unit_exp", "orddenom_spec_data_type",
                           "orddenom_len_unit_exp", "orddenom_force_unit_exp",
                           "orddenom_temp_unit_exp", "z_axis_spec_data_type",
                           "z_axis_len_unit_exp", "z_axis_force_unit_exp",
                           "z_axis_temp_unit_exp"), 0)  # fmt: skip
    return pyuff.prepare_58(
        binary=0,
        z_axis_value=0.0,
        id1="test",
        id2="case 0",
        id3=name,
        id4="coal",
        id5="",
        func_type=1,
        rsp_ent_name=name,
        rsp_node=node,
        rsp_dir=3,
        ref_ent_name="none",
        ord_data_type=4,
        num_pts=len(data),
        abscissa_spacing=1,
        abscissa_min=0.0,
        abscissa_inc=1.0 / fs,
        abscissa_spec_data_type=17,
        abscissa_axis_units_lab="s",
        ordinate_spec_data_type=12,
        ordinate_len_unit_exp=1,
        ordinate_axis_units_lab="g",
        orddenom_axis_units_lab="",
        z_axis_axis_units_lab="",
        data=data,
        x=np.arange(len(data)) / fs,
        **zeros,
    )


def write_uff(path, x, fs=FS, names=("ax", "ay")):
    import pyuff

    sets = [_uff58(n, i + 1, x[i], fs) for i, n in enumerate(names)]
    pyuff.UFF(str(path)).write_sets(sets, mode="overwrite")


def write_tdms(path, x, fs=FS, names=("ax", "ay")):
    from nptdms import ChannelObject, TdmsWriter

    props = {"wf_increment": 1.0 / fs, "unit_string": "g"}
    with TdmsWriter(path) as writer:
        writer.write_segment([ChannelObject("acc", n, d, properties=props)
                              for n, d in zip(names, x, strict=True)])  # fmt: skip


def write_mat(path, x, fs=FS):
    from scipy.io import savemat

    savemat(path, {"fs": fs, "unit": "g", "acc": x.T})  # one column per channel


def write_mat73(path, x, fs=FS):
    """The layout MATLAB's -v7.3 writes: HDF5 after a 512-byte user block, matrices stored
    transposed, text as uint16 with MATLAB_class 'char'."""
    import h5py

    with h5py.File(path, "w", userblock_size=512) as h5:
        h5["acc"] = x  # (channels, samples): MATLAB's samples x channels matrix
        h5["acc"].attrs["MATLAB_class"] = np.bytes_("double")
        h5["fs"] = np.array([[fs]])
        h5["unit"] = np.array([[ord(c)] for c in "g"], dtype=np.uint16)
        h5["unit"].attrs["MATLAB_class"] = np.bytes_("char")


def write_hdf5(path, x, fs=FS):
    import h5py

    with h5py.File(path, "w") as h5:
        h5.attrs["sample_rate"] = fs
        group = h5.create_group("acc")
        group.attrs["unit"] = "g"
        group["ax"], group["ay"] = x[0], x[1]


FORMATS = {  # writer, file name, channel names, unit the file states
    "wav": (write_wav_float, "r.wav", ["ch1", "ch2"], None),
    "csv": (write_csv, "r.csv", ["ax", "ay"], "g"),
    "uff": (write_uff, "r.uff", ["ax", "ay"], "g"),
    "tdms": (write_tdms, "r.tdms", ["ax", "ay"], "g"),
    "mat": (write_mat, "r.mat", ["acc[1]", "acc[2]"], "g"),
    "mat73": (write_mat73, "r.mat", ["acc[1]", "acc[2]"], "g"),
    "hdf5": (write_hdf5, "r.h5", ["acc/ax", "acc/ay"], "g"),
}


@pytest.mark.parametrize("fmt", list(FORMATS))
def test_each_reader_reads_what_an_independent_writer_wrote(tmp_path, fmt):
    writer, name, channels, unit = FORMATS[fmt]
    x = _signals()
    writer(tmp_path / name, x)
    rec = open_recording(tmp_path / name)
    assert rec.channels == channels
    assert rec.sample_rate == pytest.approx(FS, rel=1e-9)
    assert rec.units == [unit, unit]
    assert rec.n_samples == N
    got = np.concatenate(list(rec.blocks(300)), axis=1)  # blocks of unequal sizes
    tol = 1e-6 if fmt == "wav" else 1e-12  # float32 WAV
    np.testing.assert_allclose(got, x, atol=tol)
    rec.close()


def test_integer_wav_is_a_fraction_of_full_scale(tmp_path):
    from scipy.io import wavfile

    ints = (np.array([[1000, -32768, 32767], [5, 0, -7]]).T).astype(np.int16)
    wavfile.write(tmp_path / "i.wav", 8000, ints)
    rec = open_recording(tmp_path / "i.wav")
    assert rec.full_scale and rec.units == [None, None]
    np.testing.assert_array_equal(rec.read(0, 3), ints.T / 32768.0)


# -- resampling and onsets -----------------------------------------------------------------------


def test_blockwise_resampling_equals_one_resample_poly_call():
    from scipy.signal import resample_poly

    x = np.random.default_rng(3).standard_normal((2, 20011))
    for source, target in ((25600, 20000), (44100, 25600), (8000, 12000)):
        up, down = ratio(source, target, "test")
        r = Resampler(up, down)
        pieces, i = [], 0
        for k in (1, 77, 5000, 3, 9000, 20011):
            pieces.append(r.push(x[:, i : i + k]))
            i += k
        pieces.append(r.finish())
        whole = resample_poly(x, up, down, axis=1)
        np.testing.assert_allclose(np.concatenate(pieces, axis=1), whole, rtol=0, atol=1e-12)


def test_onsets_are_found_where_they_were_planted():
    fs = 10000.0
    rng = np.random.default_rng(5)
    x = 0.01 * rng.standard_normal((2, 30000))
    planted = [2500, 9000, 9200, 21000]  # 9200 falls in the dead time of 9000
    for k in planted:
        tt = np.arange(x.shape[1] - k) / fs
        x[1, k:] += np.exp(-tt * 300) * np.sin(2 * np.pi * 700 * tt)
    det = OnsetDetector(fs, 2, OnsetOptions(threshold=8, dead_time=0.05, floor_window=0.5))
    found = []
    for lo in range(0, x.shape[1], 5000):  # frames of floor_window
        found += det.frame(x[:, lo : lo + 5000], lo)
    assert len(found) == 3
    # the envelope crosses 8x the floor within a fraction of its 0.5 ms time constant
    np.testing.assert_array_less(np.abs(np.array(found) - [2500, 9000, 21000]), 6)


# -- the command ---------------------------------------------------------------------------------


def _labels(path, rows):
    import pandas as pd

    pd.DataFrame(rows).to_csv(path, index=False)


def _open(out):
    import xarray as xr

    return xr.open_zarr(out / "dataset.zarr")


def test_units_resampling_and_provenance(tmp_path, capsys):
    # a 3 kHz CSV in g and a 2 kHz TDMS in g of the same analytic sines
    n3 = 3000
    write_csv(tmp_path / "fast.csv", _signals(n3, 3000.0), fs=3000.0)
    # the TDMS file holds its channels in the other order: they are matched by name
    write_tdms(tmp_path / "slow.tdms", _signals(2000, 2000.0)[::-1], fs=2000.0, names=("ay", "ax"))
    rows = [{"file": "fast.csv", "label": "coal", "size": 1},
            {"file": "slow.tdms", "label": "gangue", "size": 2}]  # fmt: skip
    _labels(tmp_path / "labels.csv", rows)
    out = tmp_path / "ds"
    argv = ["import", str(tmp_path / "fast.csv"), str(tmp_path / "slow.tdms"), "--labels",
            str(tmp_path / "labels.csv"), "--out", str(out)]  # fmt: skip
    assert main(argv) == 0
    printed = capsys.readouterr()
    assert "sensors: ax, ay" in printed.out
    assert "resampled to 2000 Hz" in printed.err
    assert "slow.tdms: channels ['ay', 'ax'] taken as sensors ['ax', 'ay']" in printed.err
    ds = _open(out)
    assert ds.attrs["sample_rate_hz"] == 2000.0
    assert ds["acceleration"].shape == (2, 2, 2000)
    assert list(ds["label"].values) == ["coal", "gangue"]
    assert ds["size"].dtype.kind == "i"  # numbers stay numbers
    t = ds["time"].values
    truth = G * _signals(2000, 2000.0)  # the sines in m/s^2 on the common time axis
    acc = ds["acceleration"].values
    np.testing.assert_allclose(acc[1], truth, rtol=1e-6, atol=1e-5)  # not resampled: exact
    inner = (t > 0.05) & (t < 0.95)  # away from the zero-padded ends of resample_poly
    err = np.abs(acc[0][:, inner] - truth[:, inner]).max()
    assert err < 2e-3 * G, err  # the Kaiser filter's pass-band ripple at 50 and 130 Hz
    sources = json.loads(ds.attrs["import_sources"])
    digest = hashlib.sha256((tmp_path / "fast.csv").read_bytes()).hexdigest()
    assert sources[0]["sha256"] == digest and sources[0]["reader"] == "csv (pandas)"
    assert sources[0]["sample_rate_hz"] == pytest.approx(3000.0)
    assert sources[0]["resample_up_down"] == [2, 3] and sources[1]["units"] == ["g", "g"]
    assert ds.attrs["import_command"].startswith("tailbeam import ")
    assert json.loads(ds.attrs["import_sensor_map"])[str(tmp_path / "slow.tdms")] == {
        "ax": "ax", "ay": "ay"}  # fmt: skip


def test_integer_wav_full_scale_and_unit_from_the_labels(tmp_path):
    from scipy.io import wavfile

    ints = np.array([[16384, -8192, 0, 32767] * 8]).T.astype(np.int16)  # 32 samples, mono
    wavfile.write(tmp_path / "i.wav", 1000, ints)
    _labels(tmp_path / "l.csv", [{"file": "i.wav", "unit": "g", "full_scale": 4.0}])
    assert main(["import", str(tmp_path / "i.wav"), "--labels", str(tmp_path / "l.csv"),
                 "--out", str(tmp_path / "ds")]) == 0  # fmt: skip
    acc = _open(tmp_path / "ds")["acceleration"].values[0, 0]
    np.testing.assert_allclose(acc, ints[:, 0] / 32768.0 * 4.0 * G, rtol=1e-6)


def _two_class_recordings(folder, n_files=10, fs=8000.0, seconds=1.5):
    """Mono WAV files in g: noise and three decaying rings, 600 Hz (coal) or 1800 Hz (gangue)."""
    from scipy.io import wavfile

    rng = np.random.default_rng(11)
    rows, n = [], int(seconds * fs)
    t = np.arange(n) / fs
    for i in range(n_files):
        label, f0 = ("coal", 600.0) if i % 2 == 0 else ("gangue", 1800.0)
        x = 0.005 * rng.standard_normal(n)
        for t0 in (0.2 + 0.05 * rng.random(), 0.7, 1.2):
            on = t >= t0
            x[on] += np.exp(-(t[on] - t0) * 80) * np.sin(2 * np.pi * f0 * (t[on] - t0))
        wavfile.write(folder / f"r{i}.wav", int(fs), x.astype(np.float32))
        rows.append({"file": f"r{i}.wav", "label": label, "unit": "g"})
    _labels(folder / "labels.csv", rows)
    return [str(folder / r["file"]) for r in rows]


def test_import_then_features_then_learn(tmp_path, capsys):
    files = _two_class_recordings(tmp_path)
    out = str(tmp_path / "ds")
    assert main(["import", *files, "--labels", str(tmp_path / "labels.csv"), "--out", out]) == 0
    import pandas as pd

    impacts = pd.read_parquet(tmp_path / "ds" / "impacts.parquet")
    assert len(impacts) == 30  # three rings a file, each found once
    assert set(impacts["class"]) == {"coal", "gangue"}
    assert main(["features", out]) == 0
    assert main(["learn", out, "--folds", "5"]) == 0
    scores = json.loads((tmp_path / "ds" / "learn" / "learn.json").read_text())
    assert scores["n_rows"] == 30 and scores["n_cases"] == 10
    assert scores["accuracy"] > scores["dummy"]["accuracy"] + 0.3


def test_fixed_and_impact_cuts(tmp_path):
    import pandas as pd

    files = _two_class_recordings(tmp_path, n_files=2)
    labels = str(tmp_path / "labels.csv")
    out = tmp_path / "fixed"
    assert main(["import", *files, "--labels", labels, "--out", str(out), "--cut", "fixed",
                 "--length", "0.4"]) == 0  # fmt: skip
    ds = _open(out)
    assert ds["acceleration"].shape == (6, 1, 3200)  # 1.5 s -> three 0.4 s windows a file
    np.testing.assert_allclose(ds["t_source"].values, [0.0, 0.4, 0.8] * 2)
    whole = open_recording(files[1]).read(0, 12000)[0] * G
    np.testing.assert_allclose(ds["acceleration"].values[4, 0], whole[3200:6400], rtol=1e-6)
    out = tmp_path / "impacts"
    assert main(["import", *files, "--labels", labels, "--out", str(out), "--cut", "impacts",
                 "--length", "0.05", "--pre", "0.002"]) == 0  # fmt: skip
    ds = _open(out)
    assert ds["acceleration"].shape == (6, 1, 400)
    impacts = pd.read_parquet(out / "impacts.parquet")
    assert list(impacts["t_start"]) == pytest.approx([0.002] * 6)
    np.testing.assert_allclose(ds["t_source"].values[1:3] + 0.002, [0.7, 1.2], atol=0.001)


# -- bad input -----------------------------------------------------------------------------------


def _bad_cases(folder):
    """{name: (argv tail, words the one line must hold)}; files written into ``folder``."""
    from scipy.io import wavfile

    x = _signals()
    write_wav_float(folder / "ok.wav", x)
    raw = (folder / "ok.wav").read_bytes()
    (folder / "cut.wav").write_bytes(raw[: len(raw) - 999])
    write_csv(folder / "ok.csv", x)
    text = (folder / "ok.csv").read_text()
    (folder / "cut.csv").write_text(text[: text.rindex(",")])  # the last row cut short
    import pandas as pd

    pd.DataFrame({"ax": x[0], "ay": x[1]}).to_csv(folder / "norate.csv", index=False)
    wavfile.write(folder / "mono.wav", int(FS), x[0].astype(np.float32))
    (folder / "r.xyz").write_text("1,2\n")
    _labels(folder / "l.csv", [
        {"file": "ok.wav", "unit": "g"}, {"file": "cut.wav", "unit": "g"},
        {"file": "norate.csv", "unit": "g"}, {"file": "mono.wav", "unit": "g"},
        {"file": "r.xyz", "unit": "g"}, {"file": "cut.csv"}])  # fmt: skip
    _labels(folder / "badunit.csv", [{"file": "ok.wav", "unit": "furlongs"}])
    _labels(folder / "missing.csv", [{"file": "ok.wav", "unit": "g"}, {"file": "gone.wav"}])
    _labels(folder / "norow.csv", [{"file": "ok.csv"}])
    _labels(folder / "clash.csv", [{"file": "ok.csv", "sample_rate": 1000}])
    f = {n: str(folder / n) for n in ("ok.wav", "cut.wav", "norate.csv", "mono.wav", "r.xyz",
                                      "ok.csv", "cut.csv")}  # fmt: skip
    lab = {n: str(folder / f"{n}.csv") for n in ("l", "badunit", "missing", "norow", "clash")}
    return {
        "truncated": ([f["cut.wav"], "--labels", lab["l"]], ["cut.wav", "WAV"]),
        "truncated csv": ([f["cut.csv"], "--labels", lab["l"]], ["cut.csv", "cut short"]),
        "no rate": ([f["norate.csv"], "--labels", lab["l"]], ["norate.csv", "sample_rate"]),
        "unknown unit": ([f["ok.wav"], "--labels", lab["badunit"]], ["row 1: unit", "furlongs"]),
        "row of a missing file": (
            [f["ok.wav"], "--labels", lab["missing"]],
            ["row 2: file", "gone.wav"],
        ),  # fmt: skip
        "file without a row": ([f["ok.wav"], "--labels", lab["norow"]], ["ok.wav", "no row"]),
        "rate disagrees": ([f["ok.csv"], "--labels", lab["clash"]], ["row 1: sample_rate"]),
        "channel counts": (
            [f["ok.wav"], f["mono.wav"], "--labels", lab["l"]],
            ["mono.wav", "channels"],
        ),  # fmt: skip
        "unknown extension": ([f["r.xyz"], "--labels", lab["l"]], ["r.xyz", "extension"]),
        "fixed without length": (
            [f["ok.wav"], "--labels", lab["l"], "--cut", "fixed"],
            ["--length"],
        ),  # fmt: skip
    }


def test_bad_input_is_one_line_exit_2_and_nothing_written(tmp_path, capsys):
    for name, (tail, words) in _bad_cases(tmp_path).items():
        out = tmp_path / "out" / name.replace(" ", "_")
        assert main(["import", *tail, "--out", str(out)]) == 2, name
        err = capsys.readouterr().err.strip()
        assert len(err.splitlines()) == 1 and err.startswith("tailbeam import: error:"), err
        assert all(w in err for w in words), (name, err)
        assert not out.exists(), name
    assert not (tmp_path / "out").exists()  # not even a temporary folder


def test_a_failure_while_streaming_leaves_nothing(tmp_path, capsys):
    from scipy.io import wavfile

    noise = np.random.default_rng(2).standard_normal(4000).astype(np.float32)
    wavfile.write(tmp_path / "quiet.wav", 4000, noise)  # no impact to find
    _labels(tmp_path / "l.csv", [{"file": "quiet.wav", "unit": "m/s^2"}])
    out = tmp_path / "out" / "ds"
    argv = ["import", str(tmp_path / "quiet.wav"), "--labels", str(tmp_path / "l.csv"), "--out",
            str(out), "--cut", "impacts", "--length", "0.1", "--threshold", "50"]  # fmt: skip
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "no onset" in err
    assert list((tmp_path / "out").iterdir()) == []  # the temporary folder is gone


def test_uff_channels_without_names_are_named_by_node(tmp_path):
    write_uff(tmp_path / "other.uff", _signals(), names=("", "NONE"))
    rec = open_recording(tmp_path / "other.uff")
    assert rec.channels == ["ch1", "ch2"]
    np.testing.assert_allclose(rec.read(0, N), _signals(), atol=1e-12)


def test_labels_of_an_export_give_the_case_ids_back(tmp_path, capsys):
    """The labels.csv beside exported UFF files holds case, case_hash and, for an imported
    dataset, source_file: one case per file keeps the ids and hashes, the rest is kept as
    labels_<name>."""
    for name, sign in (("case_7.uff", 1.0), ("case_3.uff", -1.0)):
        write_uff(tmp_path / name, sign * _signals())
    rows = [{"file": "case_7.uff", "label": "coal", "case": 7, "case_hash": "h7",
             "source_file": "a.wav"},
            {"file": "case_3.uff", "label": "gangue", "case": 3, "case_hash": "h3",
             "source_file": "b.wav"}]  # fmt: skip
    _labels(tmp_path / "labels.csv", rows)
    files = [str(tmp_path / "case_7.uff"), str(tmp_path / "case_3.uff")]
    out = tmp_path / "ds"
    assert (
        main(["import", *files, "--labels", str(tmp_path / "labels.csv"), "--out", str(out)]) == 0
    )
    ds = _open(out)
    assert list(ds["case"].values) == [7, 3] and list(ds["case_hash"].values) == ["h7", "h3"]
    assert list(ds["labels_source_file"].values) == ["a.wav", "b.wav"]
    np.testing.assert_allclose(ds["acceleration"].values[1], -G * _signals(), atol=1e-9)
    rows[1]["case"] = 7
    _labels(tmp_path / "labels.csv", rows)
    argv = ["import", *files, "--labels", str(tmp_path / "labels.csv"), "--out", str(out) + "2"]
    assert main(argv) == 2
    assert "labels.csv: case: values must differ" in capsys.readouterr().err


def test_mat_and_hdf5_rates_from_a_time_vector_or_a_step(tmp_path):
    import h5py
    from scipy.io import savemat

    x = _signals()
    t = 0.25 + np.arange(N) / FS  # a time vector need not start at 0
    savemat(tmp_path / "t.mat", {"t": t, "ax": x[0], "ay": x[1], "units": "m/s^2"})
    with h5py.File(tmp_path / "dt.h5", "w") as h5:
        for name, values in zip(("ax", "ay"), x, strict=True):
            h5[name] = values
            h5[name].attrs["dt"] = 1.0 / FS
            h5[name].attrs["unit"] = "mm/s^2"
    for name, unit in (("t.mat", "m/s^2"), ("dt.h5", "mm/s^2")):
        rec = open_recording(tmp_path / name)
        assert rec.channels == ["ax", "ay"] and rec.units == [unit, unit]
        assert rec.sample_rate == pytest.approx(FS, rel=1e-9)
        np.testing.assert_allclose(rec.read(0, N), x, atol=1e-12)
    t[500] += 0.5 / FS  # half a step off: not evenly spaced
    savemat(tmp_path / "t.mat", {"t": t, "ax": x[0], "ay": x[1], "units": "m/s^2"})
    with pytest.raises(InputError, match="evenly spaced"):
        open_recording(tmp_path / "t.mat")
