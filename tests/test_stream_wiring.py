"""Streams in scene files, ``tailbeam.simulate``, impacts.csv's stream columns, particles.csv.

Independent truths: the stream generator run on the file's own tables (particles.csv), the
closed form of the along-slope motion on a frictionless incline (leave times and edges), the
single-ball solver called directly (routing changes no rigid result), the scene file itself
(round trip).
"""

import csv
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import tailbeam
from tailbeam.cli import main
from tailbeam.errors import InputError, WorkLimitError
from tailbeam.io.scene_dump import dumps_scene
from tailbeam.io.scene_file import load_scene, loads_scene, tomllib
from tailbeam.physics.bodies import Plate
from tailbeam.physics.hertz import hertz_max_penetration, hertz_peak_force
from tailbeam.physics.incline import InclinedPlate
from tailbeam.physics.materials import COAL, SANDSTONE
from tailbeam.results.result import (
    IMPACT_COLUMNS,
    IMPACT_TABLE_COLUMNS,
    PARTICLE_COLUMNS,
    Result,
)
from tailbeam.scene import Scene
from tailbeam.solvers.rigid import simulate_rigid
from tailbeam.streams.generator import generate_particles

ROOT = Path(__file__).parents[1]
SMALL = ROOT / "examples" / "small_stream.toml"
G = 9.80665


def read_csv(path):
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    return rows[0], rows[1:]


def same_cell(text, value) -> bool:
    """A CSV cell equals a table value bit for bit (floats written with repr, nan as nan)."""
    if isinstance(value, str):
        return text == value
    if isinstance(value, (bool, np.bool_)):
        return text == ("true" if value else "false")
    x = float(text)
    return (math.isnan(x) and math.isnan(value)) or x == value


@pytest.fixture(scope="module")
def small_cli(tmp_path_factory):
    out = tmp_path_factory.mktemp("small") / "out"
    proc = subprocess.run(
        [sys.executable, "-m", "tailbeam", "simulate", SMALL, "--out", out],
        capture_output=True,
        text=True,
        timeout=3600,  # a hang guard, not a timing: a loaded machine may take many minutes
    )
    assert proc.returncode == 0, proc.stderr
    return out


@pytest.fixture(scope="module")
def small_result():
    return tailbeam.simulate(load_scene(SMALL), progress=False)


def test_small_stream_impacts_csv_equals_the_result(small_cli, small_result):
    assert isinstance(small_result, Result)
    header, rows = read_csv(small_cli / "impacts.csv")
    assert tuple(header) == IMPACT_TABLE_COLUMNS
    assert tuple(header[:12]) == IMPACT_COLUMNS  # today's columns first, in today's order
    table = small_result.impacts_table()
    assert len(rows) == len(table["ball"]) == len(small_result.impacts)
    for r, row in enumerate(rows):
        for c, name in enumerate(header):
            assert same_cell(row[c], table[name][r]), (r, name, row[c], table[name][r])
    # The scene holds what the columns are meant to show: ball-ball rows in pairs.
    ball_rows = [r for r in range(len(rows)) if table["partner"][r] != "plate"]
    assert ball_rows and len(ball_rows) % 2 == 0
    for r in ball_rows:  # one row per ball, both with the pair's restitution and peak
        other = [q for q in ball_rows if table["ball"][q] == table["partner"][r]
                 and table["t_start"][q] == table["t_start"][r]]  # fmt: skip
        assert len(other) == 1
        q = other[0]
        assert table["restitution"][q] == table["restitution"][r]
        assert table["peak_force"][q] == table["peak_force"][r]
        assert math.isnan(table["next_apex_height"][r])
    manifest = json.loads((small_cli / "manifest.json").read_text())
    units = manifest["files"]["impacts.csv"]["units"]
    assert units["x"] == "m" and units["peak_force"] == "N" and units["radius"] == "m"
    data = json.loads((small_cli / "impacts.json").read_text())
    assert len(data["impacts"]) == len(rows) and data["solver"]["status"] == 0
    assert not (small_cli / "timeseries.csv").exists()


def test_small_stream_plate_rows_against_their_own_definitions(small_result):
    """restitution = v_out / v_in on the plate (the plate does not move); the apex of the
    next normal flight is v_out^2 / (2 g cos theta)."""
    t = small_result.impacts_table()
    plate = (t["partner"] == "plate") & (t["end"] == "separated")
    assert plate.sum() > 10
    np.testing.assert_allclose(t["restitution"][plate], (t["v_out"] / t["v_in"])[plate], 1e-12)
    apex = ~np.isnan(t["next_apex_height"]) & plate
    g_n = G * math.cos(math.radians(20.0))
    np.testing.assert_allclose(t["next_apex_height"][apex], t["v_out"][apex] ** 2 / (2 * g_n))
    assert apex.sum() > 10


def test_small_stream_particles_csv_equals_the_generator(small_cli):
    """particles.csv: the [[balls]] as written, then exactly what the generator makes of the
    file's [[streams]] tables (run here on the raw tables, not through the scene)."""
    header, rows = read_csv(small_cli / "particles.csv")
    assert tuple(header) == PARTICLE_COLUMNS
    data = tomllib.loads(SMALL.read_text())
    incline = InclinedPlate(Plate(), data["plate"]["inclination"])
    made = generate_particles(data["streams"], incline)
    balls = data["balls"]
    assert len(rows) == len(balls) + len(made)
    for row, b in zip(rows, balls, strict=False):
        assert row[:4] == [b["name"], "", b["material"], b.get("label", "coal")]
        assert [float(v) for v in row[7:13]] == b["position"] + b["velocity"]
        assert float(row[6]) == 0.0
    for row, p in zip(rows[len(balls) :], made, strict=True):
        expect = [p.name, p.stream, p.material.name, p.label, p.radius, p.mass, p.t_release,
                  *p.position, *p.velocity]  # fmt: skip
        assert all(same_cell(c, v) for c, v in zip(row[:13], expect, strict=True)), row
    left = [r for r in rows if r[14]]
    assert left and all(r[14] in ("x-", "x+", "y-", "y+") and float(r[13]) > 0 for r in left)
    assert all(r[13] == "nan" for r in rows if not r[14])


LEAVING = """
duration = 0.5
[plate]
inclination = 30.0
[[balls]]                 # downhill: leaves over x+
name = "down"
material = "coal"
radius = 0.02
position = [0.1, 0.0, 0.1]
velocity = [0.5, 0.0, 0.0]
[[balls]]                 # thrown uphill: leaves over x-
name = "up"
material = "sandstone"
radius = 0.02
position = [-0.1, 0.2, 0.1]
velocity = [-2.0, 0.0, 0.0]
[[balls]]                 # sideways: leaves over y-
name = "side"
material = "coal"
radius = 0.015
position = [-0.25, -0.2, 0.05]
velocity = [0.0, -1.0, -0.2]
"""


def _first_root(a, b, c):
    """First t > 0 with a t^2 + b t + c = 0 (a > 0, c < 0 or the first crossing)."""
    disc = math.sqrt(b * b - 4 * a * c)
    roots = sorted(r for r in ((-b - disc) / (2 * a), (-b + disc) / (2 * a)) if r > 0)
    return roots[0]


def test_leave_times_and_edges_match_the_closed_form(tmp_path):
    """Frictionless incline: plate forces are normal, so x(t) = x0 + vx t + g sin(th) t^2 / 2
    and y(t) = y0 + vy t whatever the bounces; a ball leaves where its centre passes an edge
    (+-a/2, +-b/2 = 0.3 m). Through the CLI, read from particles.csv."""
    scene = tmp_path / "leaving.toml"
    scene.write_text(LEAVING)
    assert main(["simulate", str(scene), "--out", str(tmp_path / "out")]) == 0
    header, rows = read_csv(tmp_path / "out" / "particles.csv")
    got = {r[0]: (float(r[13]), r[14]) for r in rows}
    gs = 0.5 * G * math.sin(math.radians(30.0))
    expect = {
        "down": (_first_root(gs, 0.5, 0.1 - 0.3), "x+"),
        "up": (_first_root(gs, -2.0, -0.1 + 0.3), "x-"),
        "side": ((0.3 - 0.2) / 1.0, "y-"),
    }
    for name, (t, edge) in expect.items():
        assert got[name][1] == edge
        assert abs(got[name][0] - t) < 1e-12, (name, got[name][0], t)


def test_simulate_keeps_the_single_ball_solver_for_rigid_scenes():
    """Routing changes nothing for a rigid scene whose balls cannot touch: the result is the
    one simulate_rigid gives when called directly."""
    scene = load_scene(ROOT / "examples" / "two_balls_rigid.toml")
    assert not scene.needs_stream_solver
    got = tailbeam.simulate(scene, progress=False)
    direct = simulate_rigid(scene.balls, scene.plate, scene.laws(), scene.duration)
    assert [i.as_dict() for i in got.impacts] == [i.as_dict() for i in direct.impacts]


def test_simulate_refuses_what_it_cannot_run():
    with pytest.raises(InputError, match="must be a tailbeam.scene.Scene"):
        tailbeam.simulate("scene.toml")
    scene = load_scene(SMALL)
    # streams on the modal plate: the stream solver's contacts drive the plate (one-way)
    modal = Scene(scene.balls, streams=scene.streams, plate_model="modal", duration=0.8)
    assert modal.needs_stream_solver
    # a scene over the fast solver's particle limit is refused before any work
    ball = scene.balls[1]
    crowd = Scene((ball,), streams=scene.streams, duration=0.8)
    with pytest.MonkeyPatch.context() as mp:
        from tailbeam.simulation import SOLVERS

        mp.setattr(SOLVERS["stream"], "max_particles", 5)
        with pytest.raises(WorkLimitError, match=r"^streams\[1\].rate: .*at most 5"):
            tailbeam.simulate(crowd, progress=False)


STREAM = """
duration = 0.5
[plate]
inclination = 15.0
[[balls]]
name = "a"
material = "coal"
radius = 0.03
position = [0.0, 0.0, 0.05]
[[streams]]
name = "s"
rate = 20.0
stop = 0.2
gangue_fraction = 0.5
radius = [0.01, 0.02]
area = [[-0.2, 0.2], [-0.2, -0.1]]
height = 0.05
"""


def _bad(old, new):
    """STREAM with ``old`` replaced by ``new`` (old None: ``new`` is the whole text)."""
    text = new if old is None else STREAM.replace(old, new, 1)
    assert text != STREAM
    return text


BAD = [
    ("inclination = 15.0", "inclination = 90.0", "plate.inclination", "[0, 90)"),
    ("inclination = 15.0", "inclination = -1.0", "plate.inclination", "[0, 90)"),
    ("inclination = 15.0", 'inclination = "steep"', "plate.inclination", "number"),
    ("[plate]", "gravity = -1.0\n[plate]", "gravity", ">= 0"),
    ('radius = 0.03', 'radius = 0.03\nlabel = "rock"', "balls[1].label", "coal"),
    ('radius = 0.03', "radius = 0.03\nlabel = 3", "balls[1].label", "string"),
    ('radius = 0.03', "radius = 0.03\nlabl = 'coal'", "balls[1].labl", "label"),
    ("rate = 20.0", "rate = -20.0", "streams[1].rate", "> 0"),
    ("rate = 20.0", "rate = 2000000.0", "streams[1].rate", "at most 200000"),
    ("stop = 0.2", "stop = 0.2\nstart = 0.6", "streams[1].stop", "> start"),
    ("stop = 0.2", "stop = 0.9\nstart = 0.6", "streams[1].start", "< duration"),
    ("gangue_fraction = 0.5", "gangue_fraction = 1.5", "streams[1].gangue_fraction", "[0, 1]"),
    ("radius = [0.01, 0.02]", "radius = [0.02, 0.01]", "streams[1].radius", "min <= max"),
    ("[[-0.2, 0.2], [-0.2, -0.1]]", "[[-0.2, 0.4], [-0.2, -0.1]]", "streams[1].area", "over"),
    ("height = 0.05", "height = 0.0", "streams[1].height", "> 0"),
    ("height = 0.05", "height = 0.05\ncolour = 'red'", "streams[1].colour", "unknown key"),
    ("height = 0.05", "height = 0.05\nseed = -1", "streams[1].seed", ">= 0"),
    ("height = 0.05", "height = 0.05\ncoal_material = 'cheese'", "streams[1].coal_material",
     "cheese"),
    ('name = "s"', 'name = ""', "streams[1].name", "non-empty"),
    ("height = 0.05", "height = 0.05\nsize_distribution = 'gauss'",
     "streams[1].size_distribution", "one of"),
    ("height = 0.05", "height = 0.05\nsize_distribution = 'lognormal'\nsigma = 0.3",
     "streams[1].median", "required"),
    ("height = 0.05", "height = 0.05\nvelocity_spread = -0.1", "streams[1].velocity_spread",
     ">= 0"),
    ("height = 0.05", "height = 0.05\nmax_tries = 0", "streams[1].max_tries", ">= 1"),
    ("radius = [0.01, 0.02]", "radius = [0.01, 0.02, 0.03]", "streams[1].radius", "2 numbers"),
    ("[[-0.2, 0.2], [-0.2, -0.1]]", "[-0.2, 0.2]", "streams[1].area", "[[x0, x1], [y0, y1]]"),
    ('name = "a"', 'name = "s-1"', "streams[1].name", "'s-1'"),
    ("height = 0.05", "height = 0.05\n" + STREAM[STREAM.index("[[streams]]") :],
     "streams[2].name", "earlier stream"),
    (None, STREAM[: STREAM.index("[[streams]]")].replace("[plate]", "streams = 3\n[plate]"),
     "streams", "array of tables"),
    ("height = 0.05", "height = 0.05\nvelocity = [0.0, 0.0, -80.0]", "streams[1].velocity",
     "penetrate"),
    # a 600 m fall (106 m/s) needs a plate of 60 m or more to be a plausible height
    (None, STREAM.replace("height = 0.05", "height = 600.0").replace(
        "inclination = 15.0", "inclination = 15.0\nsize = [100.0, 100.0, 0.05]"),
     "streams[1].height", "penetrate"),
    ("height = 0.05", "height = 1000.0", "streams[1].height", "more than 10 x its size"),
]  # fmt: skip


@pytest.mark.parametrize("old, new, field, rule", BAD, ids=[f"{b[2]}:{b[3]}" for b in BAD])
def test_bad_new_key_one_line_exit_2_nothing_written(tmp_path, capsys, old, new, field, rule):
    scene = tmp_path / "bad.toml"
    scene.write_text(_bad(old, new))
    out = tmp_path / "out"
    assert main(["simulate", str(scene), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    assert lines[0].startswith(f"tailbeam simulate: error: {field}: "), lines[0]
    assert rule in lines[0], lines[0]
    assert not out.exists()


def test_good_stream_scene_loads():
    """The base of the bad-key cases is valid (so each case tests its one key)."""
    scene = loads_scene(STREAM)
    assert scene.inclination == 15.0 and scene.streams[0].name == "s"
    assert scene.labels == ("coal",) and scene.needs_stream_solver


ROUND_TRIP = """
duration = 2.0
gravity = 9.81
[plate]
inclination = 27.5
[materials.shale]
density = 2500.0
youngs_modulus = 2e10
poisson_ratio = 0.25
[[balls]]
name = "a"
material = "coal"
radius = 0.03
position = [0.0, 0.0, 0.05]
label = "gangue"
[[balls]]
name = "b"
material = "shale"
radius = 0.02
position = [0.2, 0.2, 0.05]
label = "gangue"
[[streams]]
name = "logn"
rate = 7.5
start = 0.1
stop = 1.5
gangue_fraction = 0.25
gangue_material = "shale"
radius = [0.01, 0.04]
size_distribution = "lognormal"
median = 0.02
sigma = 0.4
area = [[-0.25, 0.0], [-0.2, 0.2]]
height = [0.1, 0.3]
velocity = [0.5, 0.0, -1.0]
velocity_spread = 0.05
seed = 11
max_tries = 50
[[streams]]
name = "rr"
rate = 3.0
stop = 1.0
gangue_fraction = 1.0
radius = [0.015, 0.03]
size_distribution = "rosin_rammler"
characteristic_radius = 0.02
uniformity = 2.5
area = [[0.0, 0.2], [-0.1, 0.1]]
height = 0.2
seed = 12
"""


def test_new_keys_round_trip_through_scene_dump():
    scene = loads_scene(ROUND_TRIP)
    text = dumps_scene(scene)
    again = loads_scene(text)
    assert again == scene
    assert again.particles == scene.particles and len(scene.particles) > 2
    assert again.labels == ("gangue", "gangue")
    assert "inclination = 27.5" in text and 'label = "gangue"' in text
    assert text.count('label = "gangue"') == 1  # b's label is the default: not written
    assert {s.name for s in again.streams} == {"logn", "rr"}
    # and a scene without the new keys writes none of them (echoes stay as they were)
    plain = dumps_scene(load_scene(ROOT / "examples" / "two_balls_rigid.toml"))
    assert "inclination" not in plain and "label" not in plain and "streams" not in plain


def test_ball_ball_rows_against_conservation_and_hertz():
    """Two balls head-on in flight, g = 0, c = 0: each ball's row holds its own velocity along
    its normal, from the elastic-collision closed form (momentum and energy conserved:
    restitution 1); touch at t = gap / closing speed at x = the touching point; peak force
    and approach from Hertz with m* and R*."""
    text = """
duration = 0.2
gravity = 0.0
[contact]
damping = 0.0
[[balls]]
name = "c"
material = "coal"
radius = 0.02
position = [-0.1, 0.0, 0.1]
velocity = [1.0, 0.0, 0.0]
[[balls]]
name = "g"
material = "sandstone"
radius = 0.03
position = [0.1, 0.0, 0.1]
velocity = [-1.0, 0.0, 0.0]
"""
    scene = loads_scene(text)
    assert scene.needs_stream_solver and scene.labels == ("coal", "gangue")
    t = tailbeam.simulate(scene, progress=False).impacts_table()
    assert list(t["ball"]) == ["c", "g"] and list(t["partner"]) == ["g", "c"]
    m1, m2 = (b.mass for b in scene.balls)
    u1, u2 = 1.0, -1.0
    v1 = ((m1 - m2) * u1 + 2 * m2 * u2) / (m1 + m2)
    v2 = ((m2 - m1) * u2 + 2 * m1 * u1) / (m1 + m2)
    # normals from the partner to the ball: -x for c, +x for g
    np.testing.assert_allclose(t["v_in"], [u1, -u2], rtol=1e-12)
    np.testing.assert_allclose(t["v_out"], [-v1, v2], rtol=1e-9)
    np.testing.assert_allclose(t["restitution"], 1.0, rtol=1e-9)
    np.testing.assert_allclose(t["t_start"], 0.15 / 2.0, rtol=1e-12)
    np.testing.assert_allclose(t["x"], -0.1 + 0.075 + 0.02, atol=1e-12)
    law = tailbeam.ball_ball_law(COAL, 0.02, SANDSTONE, 0.03, damping=0.0)
    m_star = m1 * m2 / (m1 + m2)
    np.testing.assert_allclose(t["peak_force"], hertz_peak_force(m_star, 2.0, law.stiffness), 1e-8)
    np.testing.assert_allclose(
        t["max_penetration"], hertz_max_penetration(m_star, 2.0, law.stiffness), 1e-8
    )
    assert list(t["material"]) == ["coal", "sandstone"] and list(t["radius"]) == [0.02, 0.03]
    assert np.isnan(t["next_apex_height"]).all() and not t["ends_at_rest"].any()


def test_simulate_bounds_the_stream_work():
    scene = load_scene(SMALL)
    with pytest.raises(WorkLimitError, match=r"^max_steps: more than 5 steps"):
        tailbeam.simulate(scene, max_steps=5, progress=False)
    modal = load_scene(ROOT / "examples" / "modal_plate.toml")
    with pytest.raises(InputError, match="rtol: is not a setting of the modal"):
        tailbeam.simulate(modal, rtol=1e-8, progress=False)
