"""What the command line says and where it writes by default.

- `tailbeam simulate SCENE` without --out writes out/<SCENE's stem>; a rerun of the same
  scene file replaces it; a folder another scene file or command wrote is refused (exit 2,
  one line, untouched) unless --overwrite; an explicit --out replaces any earlier output.
- `--help` is plain text, and every option that takes a value shows its default and, for
  a fixed set of values, its choices.
- The study commands' missing-dependency error gives the install command for a checkout and
  for a package index; modes.png says how many of the computed modes it shows.
"""

import argparse
import json
import re
from pathlib import Path

import pytest

from tailbeam.cli.main import COMMANDS, build_parser, main
from tailbeam.cli.simulate import default_out
from tailbeam.errors import InputError

SCENE = """duration = 0.01
sample_rate = 1000.0
[[balls]]
name = "a"
material = "coal"
radius = 0.03
position = [0.0, 0.0, 0.031]
velocity = [0.0, 0.0, -1.0]
"""
REFERENCE = ("--solver", "stream-reference")


def one_line(capsys, field):
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert f"error: {field}:" in err, err
    return err


def fake_output(folder: Path, command: str, scene_file=None) -> Path:
    """A folder as a tailbeam run leaves it: a manifest (with the scene file when given)."""
    folder.mkdir(parents=True)
    files = {"impacts.json": {"scene_file": scene_file}} if scene_file else {}
    (folder / "manifest.json").write_text(json.dumps({"command": command, "files": files}))
    (folder / "impacts.json").write_text("{}")
    return folder


# -- the default output folder ---------------------------------------------------------------


def test_the_default_folder_follows_the_scene_and_a_rerun_replaces_it(tmp_path, monkeypatch):
    """(The reference stream solver runs the scene: no kernels to compile.)"""
    monkeypatch.chdir(tmp_path)
    Path("drop.toml").write_text(SCENE)
    assert main(["simulate", "drop.toml", "-q", *REFERENCE]) == 0
    manifest = json.loads(Path("out/drop/manifest.json").read_text())
    assert manifest["files"]["impacts.json"]["scene_file"] == str(Path("drop.toml").resolve())
    first = Path("out/drop/impacts.csv").stat().st_mtime_ns
    assert main(["simulate", "drop.toml", "-q", *REFERENCE]) == 0
    assert Path("out/drop/impacts.csv").stat().st_mtime_ns >= first
    assert sorted(p.name for p in Path("out").iterdir()) == ["drop"]  # no out/simulate
    # an explicit --out replaces an earlier output whatever wrote it (as it always has)
    Path("other").mkdir()
    Path("other/drop.toml").write_text(SCENE)
    assert main(["simulate", "other/drop.toml", "--out", "out/drop", "-q", *REFERENCE]) == 0
    manifest = json.loads(Path("out/drop/manifest.json").read_text())
    assert manifest["files"]["impacts.json"]["scene_file"] == str(Path("other/drop.toml").resolve())


def test_a_default_folder_of_another_scene_file_is_refused(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    Path("drop.toml").write_text(SCENE)
    theirs = fake_output(tmp_path / "out" / "drop", "tailbeam simulate x", "/elsewhere/drop.toml")
    assert main(["simulate", "drop.toml"]) == 2
    err = one_line(capsys, "--out")
    assert "/elsewhere/drop.toml" in err and "--overwrite" in err
    assert json.loads((theirs / "manifest.json").read_text())["files"]  # untouched
    assert default_out("drop.toml", overwrite=True) == Path("out/drop")


def test_a_default_folder_of_another_command_is_refused(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    Path("modes.toml").write_text(SCENE)
    fake_output(tmp_path / "out" / "modes", "tailbeam modes")
    assert main(["simulate", "modes.toml"]) == 2
    assert "'tailbeam modes'" in one_line(capsys, "--out")


def test_a_folder_the_same_scene_wrote_before_the_path_was_recorded_is_replaced(
    tmp_path, monkeypatch
):
    """Manifests without ``scene_file``: the command's scene path, resolved here."""
    monkeypatch.chdir(tmp_path)
    fake_output(tmp_path / "out" / "drop", "tailbeam simulate drop.toml")
    assert default_out("drop.toml") == Path("out/drop")
    with pytest.raises(InputError, match="--out"):
        default_out("sub/drop.toml")


# -- help -------------------------------------------------------------------------------------


def _subparsers(parser):
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return action.choices


def test_the_top_level_help_is_plain_text_and_lists_every_command():
    text = build_parser().format_help()
    assert "``" not in text and "`" not in text
    for name in COMMANDS:
        assert re.search(rf"^\s+{name}\b", text, re.MULTILINE), name


@pytest.mark.parametrize("command", list(COMMANDS))
def test_every_option_shows_its_default_and_choices(command):
    sub = _subparsers(build_parser())[command]
    text = " ".join(sub.format_help().split())
    for action in sub._actions:
        if not action.option_strings or action.nargs == 0:  # positionals, flags, --help
            continue
        name = action.option_strings[-1]
        helptext = " ".join(sub._get_formatter()._get_help_string(action).split())
        assert "(default" in helptext or "(required)" in helptext, f"{command} {name}: {helptext}"
        if action.default is not None:
            shown = action.default
            if isinstance(shown, (list, tuple)):
                shown = " ".join(str(v) for v in shown)
            assert f"(default: {shown})" in text, f"{command} {name}"
        if action.choices:
            assert "{" + ",".join(action.choices) + "}" in text, f"{command} {name}"


# -- install advice and modes.png -------------------------------------------------------------


def test_a_missing_study_dependency_names_the_install_for_a_checkout_and_an_index(monkeypatch):
    import importlib.util

    from tailbeam.study import require_study_dependencies

    real = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util, "find_spec", lambda name, *a: None if name == "xarray" else real(name)
    )
    with pytest.raises(InputError) as err:
        require_study_dependencies()
    assert "xarray" in err.value.rule
    assert "pip install -e '.[study]'" in err.value.rule
    assert "pip install 'tailbeam[study]'" in err.value.rule


def test_modes_png_says_which_modes_it_shows():
    from tailbeam.physics.bodies import Plate
    from tailbeam.plate import compute_modes
    from tailbeam.plate.export import PNG_MODES, build_modes_figure

    basis = compute_modes(Plate(), "SSSS", fmax_hz=3000.0, divisions=8, use_cache=False)
    assert basis.n_modes > PNG_MODES
    title = build_modes_figure(basis)._suptitle.get_text()
    assert title.startswith(f"first {PNG_MODES} of {basis.n_modes} modes: SSSS plate")
    few = build_modes_figure(basis, n_modes=basis.n_modes)._suptitle.get_text()
    assert few.startswith(f"all {basis.n_modes} modes: ")
