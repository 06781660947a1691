"""Random invalid scene values (hypothesis): each is refused with one line naming the field,
exit code 2, no traceback and nothing written, before any work.

Lists are numbered from 1 in messages, as in the manual (``balls[1]`` is the first ball).
A valid base scene (the paper's two balls, a small stream, a modal plate with a sensor) gets
one documented key replaced by a value that breaks the key's documented rule: a wrong type,
NaN or infinity, a value outside its range, a list of the wrong length, an unknown name.
The budget is bounded for CI (``TAILBEAM_PROPERTY_EXAMPLES``, default 40 scenes);
``benchmarks/fuzz_scenes.py`` runs a longer tally.
"""

import math
import os
from pathlib import Path

import hypothesis
import hypothesis.strategies as st
import tomli_w
import tomllib

from tailbeam.cli import main

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = int(os.environ.get("TAILBEAM_PROPERTY_EXAMPLES", "40"))

BASES = {
    "rigid": tomllib.loads((ROOT / "examples" / "two_balls_rigid.toml").read_text()),
    "stream": tomllib.loads((ROOT / "examples" / "small_stream.toml").read_text()),
    "modal": tomllib.loads((ROOT / "examples" / "modal_plate.toml").read_text()),
}

NOT_A_NUMBER = st.sampled_from(["abc", True, [1.0, 2.0], {"x": 1.0}])
NON_FINITE = st.sampled_from([math.nan, math.inf, -math.inf])
NEGATIVE = st.floats(min_value=-1e6, max_value=-1e-9)
NOT_A_RANGE = st.sampled_from(["abc", True, [1.0], [1.0, 2.0, 3.0], [1.0, "x"], [0.2, 0.1]])
NOT_A_VECTOR = st.sampled_from(["abc", 1.0, [1.0], [1.0, 2.0, 3.0, 4.0], [1.0, "x", 2.0]])


def positive():
    """Invalid values of a key that must be a positive number."""
    return st.one_of(NOT_A_NUMBER, NON_FINITE, NEGATIVE, st.just(0.0))


def vector3():
    return st.one_of(NOT_A_VECTOR, st.lists(NON_FINITE, min_size=3, max_size=3))


def fraction():
    """Invalid values of a key in [0, 1]."""
    return st.one_of(NOT_A_NUMBER, NON_FINITE, NEGATIVE, st.floats(1.0001, 1e6))


# (base scene, path to the key, the field as the error must name it, invalid values)
CASES = [
    ("rigid", ("duration",), "duration", positive()),
    ("rigid", ("sample_rate",), "sample_rate", positive()),
    ("rigid", ("gravity",), "gravity", st.one_of(NOT_A_NUMBER, NON_FINITE, NEGATIVE)),
    ("rigid", ("contact", "exponent"), "contact.exponent", positive()),
    ("rigid", ("contact", "damping"), "contact.damping", st.one_of(NOT_A_NUMBER, NEGATIVE)),
    ("rigid", ("contact", "penetration"), "contact.penetration", positive()),
    ("rigid", ("plate", "model"), "plate.model", st.sampled_from(["elastic", "", 3])),
    ("rigid", ("plate", "material"), "plate.material", st.sampled_from(["unobtainium", 3])),
    ("rigid", ("plate", "size"), "plate.size", vector3()),
    ("rigid", ("balls", 0, "radius"), "balls[1].radius", positive()),
    ("rigid", ("balls", 1, "position"), "balls[2].position", vector3()),
    ("rigid", ("balls", 0, "velocity"), "balls[1].velocity", vector3()),
    ("rigid", ("balls", 1, "material"), "balls[2].material", st.sampled_from(["rock?", 7])),
    ("rigid", ("balls", 0, "label"), "balls[1].label", st.sampled_from(["stone", 1])),
    ("modal", ("plate", "boundary"), "plate.boundary", st.sampled_from(["SSS", "XXXX", 4])),
    ("modal", ("plate", "damping_ratio"), "plate.damping_ratio", fraction()),
    ("modal", ("plate", "fmax"), "plate.fmax", positive()),
    ("modal", ("sensors", 0, "sample_rate"), "sensors[1].sample_rate", positive()),
    ("stream", ("plate", "inclination"), "plate.inclination", st.floats(90.0, 1e4)),
    ("stream", ("streams", 0, "rate"), "streams[1].rate", positive()),
    ("stream", ("streams", 0, "gangue_fraction"), "streams[1].gangue_fraction", fraction()),
    ("stream", ("streams", 0, "radius"), "streams[1].radius", NOT_A_VECTOR),
    ("stream", ("streams", 0, "velocity_spread"), "streams[1].velocity_spread", NEGATIVE),
    ("modal", ("plate", "theory"), "plate.theory", st.sampled_from(["euler", 1, True])),
    ("modal", ("plate", "coupling"), "plate.coupling", st.sampled_from(["both", 2])),
    ("modal", ("plate", "tail"), "plate.tail", st.sampled_from(["dynamic", 0])),
    ("modal", ("plate", "tail_modes"), "plate.tail_modes", st.sampled_from([0, -3, 2.5, "x"])),
    ("modal", ("plate", "mesh_divisions"), "plate.mesh_divisions", st.sampled_from([0, -4, 2.5])),
    ("modal", ("plate", "residual_flexibility"), "plate.residual_flexibility", NOT_A_VECTOR),
    ("modal", ("plate", "rayleigh"), "plate.rayleigh", st.one_of(NOT_A_VECTOR, NON_FINITE)),
    ("modal", ("sensors", 0, "position"), "sensors[1].position", NOT_A_VECTOR),
    ("modal", ("sensors", 0, "bandwidth"), "sensors[1].bandwidth", st.floats(3e4, 1e7)),
    ("modal", ("sensors", 0, "noise"), "sensors[1].noise", st.one_of(NEGATIVE, NON_FINITE)),
    # a start after stop is named by the pair's second key
    ("stream", ("streams", 0, "start"), "streams[1].", st.floats(0.8, 1e3)),
    ("stream", ("streams", 0, "stop"), "streams[1].stop", st.one_of(NEGATIVE, st.just(0.0))),
    ("stream", ("streams", 0, "height"), "streams[1].height", st.one_of(NEGATIVE, NOT_A_RANGE)),
    ("stream", ("streams", 0, "seed"), "streams[1].seed", st.sampled_from([-1, 1.5, "x"])),
    ("stream", ("streams", 0, "max_tries"), "streams[1].max_tries", st.sampled_from([0, -2])),
    (
        "stream",
        ("streams", 0, "size_distribution"),
        "streams[1].size_distribution",
        st.sampled_from(["gamma", 3]),
    ),
    (
        "stream",
        ("streams", 0, "area"),
        "streams[1].area",
        st.sampled_from([[[0.0, 1.0], [0.0, 0.1]], [[0.1, 0.0], [0.0, 0.1]], [0.0, 0.1], "x"]),
    ),
]


def _replace(data: dict, path: tuple, value) -> dict:
    out = _deep_copy(data)
    node = out
    for step in path[:-1]:
        node = node[step]
    node[path[-1]] = value
    return out


def _deep_copy(value):
    if isinstance(value, dict):
        return {k: _deep_copy(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_deep_copy(v) for v in value]
    return value


@hypothesis.settings(
    max_examples=EXAMPLES,
    deadline=None,
    suppress_health_check=[hypothesis.HealthCheck.function_scoped_fixture],
)
@hypothesis.given(data=st.data())
def test_an_invalid_value_is_one_line_and_exit_2(data, tmp_path, capsys):
    base, path, field, values = data.draw(st.sampled_from(CASES), label="key")
    value = data.draw(values, label="value")
    scene = _replace(BASES[base], path, value)
    case = tmp_path / f"case{len(list(tmp_path.iterdir()))}"
    case.mkdir()
    scene_file = case / "scene.toml"
    scene_file.write_text(tomli_w.dumps(scene))
    out = case / "out"
    code = main(["simulate", str(scene_file), "--out", str(out), "--quiet"])
    err = capsys.readouterr().err
    assert code == 2, (field, value, err)
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert field in err, (field, value, err)
    assert not out.exists(), (field, value)
