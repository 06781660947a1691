"""Sweep files: expansion into cases (grid x random design, follow, repeats, seeds), stability
when a sweep grows, and one-line errors naming the field before any work."""

import pytest

from tailbeam.cli import main
from tailbeam.errors import InputError
from tailbeam.study.design import expand, parse_sweep

BASE = {
    "duration": 0.01,
    "plate": {"model": "modal", "fmax": 3000.0},
    "balls": [
        {
            "name": "rock",
            "material": "coal",
            "radius": 0.02,
            "position": [0.0, 0.0, 0.06],
            "velocity": [0.0, 0.0, -1.0],
        }
    ],
    "sensors": [{"name": "S1", "position": [0.1, 0.1], "sample_rate": 8000.0, "noise": 0.01}],
}


def sweep(axes, **top):
    return parse_sweep({"scene": BASE, "axes": axes, **top})


def test_grid_times_random_design_with_repeats_and_follow():
    spec = sweep(
        {
            "balls.rock.material": ["coal", "sandstone"],
            "balls.rock.radius": {
                "distribution": "uniform",
                "low": 0.01,
                "high": 0.05,
                "samples": 3,
            },
            "balls.rock.position[2]": {"follow": "balls.rock.radius", "offset": 0.001},
            "balls[1].velocity[2]": {
                "distribution": "loguniform",
                "low": 1.0,
                "high": 5.0,
                "samples": 3,
            },
        },
        repeats=2,
    )
    cases = expand(spec)
    assert len(cases) == 2 * 3 * 2
    for c in cases:
        p = c.params
        assert 0.01 <= p["balls.rock.radius"] <= 0.05
        assert p["balls.rock.position[2]"] == pytest.approx(p["balls.rock.radius"] + 0.001)
        assert 1.0 <= p["balls[1].velocity[2]"] <= 5.0
        assert f"radius = {p['balls.rock.radius']!r}" in c.toml
        assert f"seed = {c.seed}" in c.toml  # the noise seed is the case seed
        assert c.labels["label"] == ("coal" if p["balls.rock.material"] == "coal" else "gangue")
    assert len({c.hash for c in cases}) == len(cases)
    assert len({c.seed for c in cases}) == len(cases)  # repeats differ in seed


def test_a_grown_sweep_keeps_its_cases():
    def axes(n, values):
        return {
            "balls.rock.material": values,
            "balls.rock.radius": {
                "distribution": "uniform",
                "low": 0.01,
                "high": 0.05,
                "samples": n,
            },
        }

    small = {c.hash for c in expand(sweep(axes(2, ["coal"])))}
    grown = {c.hash for c in expand(sweep(axes(4, ["coal", "sandstone"]), repeats=1))}
    assert small < grown and len(grown) == 8


def test_choice_and_vector_values():
    spec = sweep(
        {
            "sensors.S1.position": [[0.0, 0.0], [0.2, -0.1]],
            "balls.rock.material": {"distribution": "choice", "values": ["coal"], "samples": 2},
        }
    )
    cases = expand(spec)
    assert [c.params["sensors.S1.position"] for c in cases[::2]] == [[0.0, 0.0], [0.2, -0.1]]


@pytest.mark.parametrize(
    "axes, field",
    [
        ({"balls.stone.radius": [0.01]}, 'axes."balls.stone.radius"'),
        ({"balls.rock.radius": []}, 'axes."balls.rock.radius"'),
        (
            {"balls.rock.radius": {"distribution": "normal"}},
            'axes."balls.rock.radius".distribution',
        ),
        (
            {
                "balls.rock.radius": {
                    "distribution": "uniform",
                    "low": 0.1,
                    "high": 0.01,
                    "samples": 2,
                }
            },
            'axes."balls.rock.radius".high',
        ),
        (
            {"balls.rock.radius": [0.02, -0.01]},
            "case 2 (balls.rock.radius = -0.01): balls[1].radius",
        ),
        ({"sensors.S1.sample_rate": [8000.0, 9000.0]}, "case 2"),
        (
            {"balls.rock.position[2]": {"follow": "balls.rock.radius"}},
            'axes."balls.rock.position[2]"',
        ),
    ],
)
def test_bad_sweeps_name_the_field(axes, field):
    with pytest.raises(InputError) as info:
        expand(sweep(axes))
    assert info.value.field == field


def test_cli_rejects_a_bad_sweep_before_any_work(tmp_path, capsys):
    (tmp_path / "s.toml").write_text('scene = "base.toml"\n[axes]\n"contact.damping" = [1.0]\n')
    out = tmp_path / "out"
    assert main(["sweep", str(tmp_path / "s.toml"), "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("tailbeam sweep: error: scene: cannot read") and "\n" not in err
    assert not out.exists()


def test_core_imports_and_cli_work_without_the_study_extra():
    import subprocess
    import sys

    code = (
        "import sys\n"
        "for m in ('dask', 'xarray', 'zarr', 'pyarrow', 'sklearn', 'pywt', 'pandas'):\n"
        "    sys.modules[m] = None  # import of any of them now fails\n"
        "import tailbeam, tailbeam.io.scene_file, tailbeam.signals.sensor, tailbeam.signals.noise\n"
        "from tailbeam.cli import main\n"
        "sys.exit(main(['sweep', 'missing.toml']))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 2, done.stderr
    assert "pip install 'tailbeam[study]'" in done.stderr


def test_example_sweep_file_expands_to_its_stated_cases():
    """examples/sweeps/single_impacts.toml (the README's example) says 2 x 20 = 40 cases; every
    radius lies in its log-uniform range and the drop gap follows the radius."""
    from pathlib import Path

    from tailbeam.study.design import load_sweep

    path = Path(__file__).resolve().parents[1] / "examples" / "sweeps" / "single_impacts.toml"
    cases = expand(load_sweep(path))
    assert len(cases) == 40
    materials = sorted(c.params["balls.rock.material"] for c in cases)
    assert materials == ["coal"] * 20 + ["sandstone"] * 20
    for c in cases:
        r = c.params["balls.rock.radius"]
        assert 0.01 <= r <= 0.1
        assert c.params["balls.rock.position[2]"] == pytest.approx(r + 0.0002, rel=1e-12)


def test_labels_coal_labels_the_balls_in_the_scene():
    """``labels.coal`` decides each ball's label in the case's scene (so impacts.csv's
    ``label`` and the dataset's ``class`` agree with it); the default rule writes nothing,
    so the case hashes of a default sweep do not change; an explicit ``label`` wins."""
    from tailbeam.io.scene_file import loads_scene
    from tailbeam.study.case import run_case

    grid = {"balls.rock.material": ["coal", "sandstone"]}
    default = expand(sweep(grid))
    assert all("label" not in c.toml for c in default)
    near = {**BASE, "balls": [{**BASE["balls"][0], "position": [0.0, 0.0, 0.021]}]}
    spec = parse_sweep({"scene": near, "axes": grid, "labels": {"coal": ["sandstone"]}})
    cases = expand(spec)  # sandstone counted as coal, each ball 1 mm above the plate
    labels = [loads_scene(c.toml).labels for c in cases]
    assert labels == [("gangue",), ("coal",)]
    assert [c.labels["label"] for c in cases] == ["gangue", "coal"]
    out = run_case(cases[1].toml)
    assert out["status"] == "ok" and out["impacts"]
    assert {(r["material"], r["label"], r["class"]) for r in out["impacts"]} == {
        ("sandstone", "coal", "coal")
    }
    assert out["n_coal_impacts"] == len(out["impacts"]) and out["n_gangue_impacts"] == 0
    base = {**BASE, "balls": [{**BASE["balls"][0], "label": "gangue"}]}
    spec = parse_sweep({"scene": base, "axes": grid})
    assert [loads_scene(c.toml).labels for c in expand(spec)] == [("gangue",), ("gangue",)]
