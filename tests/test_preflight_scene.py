"""The preflight sees the whole scene: overlapping bodies and unit slips are refused before
any work, with one line naming the field and the bodies, exit code 2, nothing written.

Independent truths: the overlap of two spheres is |c1 - c2| < r1 + r2, checked here by
brute force over every pair (numpy) against the k-d tree search; a stream particle's
overlap with a ball is recomputed from the ball's free fall x0 + v t + g t^2 / 2 while its
lowest point is above the plate.
"""

import math

import numpy as np
import pytest

from tailbeam.cli.main import main
from tailbeam.errors import InputError
from tailbeam.io.scene_file import loads_scene
from tailbeam.physics.bodies import Ball
from tailbeam.physics.materials import COAL
from tailbeam.preflight.overlaps import check_ball_pairs

G = 9.80665


def ball(name, radius, position, velocity=(0.0, 0.0, 0.0), material="coal"):
    return (
        f'[[balls]]\nname = "{name}"\nmaterial = "{material}"\nradius = {radius!r}\n'
        f"position = {list(position)!r}\nvelocity = {list(velocity)!r}\n"
    )


def scene_text(*balls, head="duration = 0.01\n"):
    return head + "".join(balls)


def refused(tmp_path, capsys, text, field):
    """Run `tailbeam simulate` on ``text``: exit 2, one line naming ``field``, no output."""
    path = tmp_path / "scene.toml"
    path.write_text(text)
    out = tmp_path / "out"
    code = main(["simulate", str(path), "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert err.startswith(f"tailbeam simulate: error: {field}:"), err
    assert not out.exists()
    return err


# -- ball-ball --------------------------------------------------------------------------------


def test_two_balls_10_mm_apart_are_refused_naming_both(tmp_path, capsys):
    text = scene_text(ball("a", 0.03, (0.0, 0.0, 0.1)), ball("b", 0.03, (0.01, 0.0, 0.1)))
    err = refused(tmp_path, capsys, text, "balls[2].position")
    assert "overlaps balls[1] ('a'): centres 0.01 m apart, radii 0.03 + 0.03 m" in err


def test_touching_balls_are_valid_unless_rounding_makes_them_overlap():
    """Centres exactly r1 + r2 apart are valid; written decimals that round the distance
    below it (0.116 and 0.176: 0.06 - 1.4e-17 m) are refused, saying so: the stream solver
    misses a contact that exists at release, however small the overlap."""
    loads_scene(scene_text(ball("a", 0.03, (0.0, 0, 0.03)), ball("b", 0.03, (0.06, 0, 0.03))))
    assert math.dist((0.116, 0.0), (0.176, 0.0)) < 0.06
    text = scene_text(ball("a", 0.03, (0.116, 0, 0.03)), ball("b", 0.03, (0.176, 0, 0.03)))
    with pytest.raises(InputError, match=r"touches balls\[1\].*rounding.*1e-9 m"):
        loads_scene(text)


def test_exactly_touching_approaching_balls_collide():
    """The state the overlap rule keeps is one the stream solver handles: two balls set down
    touching and moving towards each other make a ball-ball contact at once."""
    from tailbeam.simulation import simulate

    a = ball("a", 0.03, (0.0, 0, 0.03), velocity=(0.1, 0, 0))
    b = ball("b", 0.03, (0.06, 0, 0.03), velocity=(-0.1, 0, 0))
    result = simulate(loads_scene(scene_text(a, b)), progress=False)
    pairs = [i for i in result.impacts if {i.ball, i.partner} == {"a", "b"}]
    assert pairs and pairs[0].t_start < 1e-9


def test_an_overlap_of_a_micron_is_refused():
    text = scene_text(ball("a", 0.03, (0.0, 0, 0.03)), ball("b", 0.03, (0.06 - 1e-6, 0, 0.03)))
    with pytest.raises(InputError, match=r"balls\[2\]\.position"):
        loads_scene(text)


def brute_force_first_overlap(centres, radii):
    """(j, i) of the first overlapping pair by j then i, or None: every pair checked."""
    d = np.linalg.norm(centres[:, None, :] - centres[None, :, :], axis=2)
    reach = radii[:, None] + radii[None, :]
    for j in range(len(radii)):
        for i in range(j):
            if d[j, i] < reach[j, i]:
                return j, i
    return None


@pytest.mark.parametrize("seed", range(6))
def test_the_tree_finds_the_pair_brute_force_finds(seed):
    rng = np.random.default_rng(seed)
    n = 150
    centres = rng.uniform([-0.3, -0.3, 0.05], [0.3, 0.3, 0.6], (n, 3))
    radii = rng.uniform(0.001, 0.002 + 0.005 * seed, n)
    balls = [Ball(f"b{k}", COAL, radii[k], tuple(centres[k])) for k in range(n)]
    truth = brute_force_first_overlap(centres, radii)
    if truth is None:
        check_ball_pairs(balls)
        return
    with pytest.raises(InputError) as err:
        check_ball_pairs(balls)
    j, i = truth
    assert err.value.field == f"balls[{j + 1}].position"
    assert err.value.rule.startswith((f"overlaps balls[{i + 1}] ", f"touches balls[{i + 1}] "))


def test_many_touching_balls_on_a_grid_pass():
    """10 000 balls side by side, each exactly touching its neighbours (binary fractions, so
    the distances are exact): no pair overlaps."""
    r = 2.0**-9
    xs = 2 * r * (np.arange(100) - 50)
    balls = [Ball(f"b{i}-{j}", COAL, r, (x, y, r)) for i, x in enumerate(xs) for j, y in
             enumerate(xs)]  # fmt: skip
    check_ball_pairs(balls)


# -- ball-plate -------------------------------------------------------------------------------


def test_a_ball_set_down_on_the_plate_is_valid_one_below_it_is_not(tmp_path, capsys):
    loads_scene(scene_text(ball("a", 0.03, (0.0, 0.0, 0.03))))
    err = refused(tmp_path, capsys, scene_text(ball("a", 0.03, (0.0, 0.0, 0.029))),
                  "balls[1].position")  # fmt: skip
    assert "inside the plate" in err


# -- stream particles against balls -----------------------------------------------------------

STREAM = """
[[streams]]
name = "s"
rate = {rate}
stop = {stop}
gangue_fraction = 0.5
radius = [0.005, 0.01]
area = {area}
height = {height}
seed = 3
"""


def test_a_stream_released_into_a_resting_ball_is_refused(tmp_path, capsys):
    """A ball of 50 mm set down under a release area 40 mm wide whose particles start 10 mm
    above the plate: every particle is inside the ball, the first one is named."""
    stream = STREAM.format(rate=60.0, stop=0.05, area="[[-0.02, 0.02], [-0.02, 0.02]]",
                           height=0.01)  # fmt: skip
    text = scene_text(ball("rock", 0.05, (0.0, 0.0, 0.05)), head="duration = 0.1\n" + stream)
    err = refused(tmp_path, capsys, text, "streams[1].area")
    assert "particle s-1 " in err and "overlaps balls[1] ('rock')" in err


def test_a_stream_against_a_falling_ball_matches_the_free_fall():
    """A ball falls from 0.5 m through a stream's release zone. The first refused particle
    is the first one the free fall puts inside the ball; a stream released after the ball
    has passed is valid."""
    stream = STREAM.format(rate=400.0, stop=0.4, area="[[-0.05, 0.05], [-0.05, 0.05]]",
                           height="[0.05, 0.25]")  # fmt: skip
    falling = ball("rock", 0.04, (0.0, 0.0, 0.5), velocity=(0.0, 0.0, -0.5))
    text = scene_text(falling, head="duration = 0.5\n" + stream)
    with pytest.raises(InputError) as err:
        loads_scene(text)
    # the truth, from the particles generated without the ball
    particles = loads_scene("duration = 0.5\n" + stream).particles
    first = None
    for p in particles:
        t = p.t_release
        z = 0.5 - 0.5 * t - 0.5 * G * t * t
        if z - 0.04 < 0.0:  # the ball has reached the plate: its path is the solver's
            continue
        if math.dist(p.position, (0.0, 0.0, z)) < 0.04 + p.radius:
            first = p
            break
    assert first is not None
    assert err.value.field == "streams[1].area"
    assert err.value.rule.startswith(f"particle {first.name} ")
    # the same ball with the stream starting after it has landed (t > 0.27 s)
    later = stream.replace("stop = 0.4", "start = 0.3\nstop = 0.4")
    assert len(loads_scene(scene_text(falling, head="duration = 0.5\n" + later)).particles) > 1


def test_the_small_stream_example_passes():
    from pathlib import Path

    from tailbeam.io.scene_file import load_scene

    root = Path(__file__).resolve().parents[1]
    scene = load_scene(root / "examples" / "small_stream.toml")
    assert len(scene.particles) > len(scene.balls)


# -- unit slips -------------------------------------------------------------------------------

SLIPS = [
    (
        scene_text(ball("a", 30, (0, 0, 31))),
        "balls[1].radius",
        "30 m is larger than the plate (0.6 x 0.6 m; a radius must be <= 0.3 m); radii are in "
        "metres (30 mm = 0.03)",
    ),
    (scene_text(ball("a", 0.03, (0, 0, 31))), "balls[1].position", "(31 mm = 0.031)"),
    (scene_text(ball("a", 0.03, (50, 0, 0.031))), "balls[1].position", "(50 mm = 0.05"),
    (
        scene_text(ball("a", 0.03, (0, 0, 0.031), velocity=(0, 0, -2000))),
        "balls[1].velocity",
        "2000 mm/s = 2)",
    ),
    (
        scene_text(
            ball("a", 0.03, (0, 0, 0.031)), head="duration = 0.01\n[plate]\nsize = [600, 600, 10]\n"
        ),  # fmt: skip
        "plate.size[0]",
        "(600 mm = 0.6)",
    ),
    (
        scene_text(
            ball("a", 0.03, (0, 0, 0.031)), head="duration = 0.01\n[plate]\nsize = [0.6, 0.6, 10]\n"
        ),  # fmt: skip
        "plate.size[2]",
        "(10 mm = 0.01)",
    ),
    (
        scene_text(
            ball("a", 0.03, (0, 0, 0.031)),
            head="duration = 0.01\n[plate]\nsize = [0.6, 0.6, 1e-7]\n",
        ),  # fmt: skip
        "plate.size[2]",
        "thinner than 1e-06 m",
    ),
    (
        scene_text(
            ball("a", 0.03, (0, 0, 0.031), material="x"),
            head="duration = 0.01\n"
            "[materials.x]\ndensity = 2.5\nyoungs_modulus = 1e10\npoisson_ratio = 0.2\n",
        ),
        "materials.x.density",
        "(2.5 g/cm^3 = 2500)",
    ),
    (
        scene_text(
            ball("a", 0.03, (0, 0, 0.031), material="x"),
            head="duration = 0.01\n"
            "[materials.x]\ndensity = 2500\nyoungs_modulus = 10\npoisson_ratio = 0.2\n",
        ),
        "materials.x.youngs_modulus",
        "(10 GPa = 1e+10",
    ),
    (
        scene_text(ball("a", 0.03, (0, 0, 0.031)), head="duration = 0.01\ngravity = 9806.65\n"),
        "gravity",
        "(9806.65 mm/s^2 = 9.80665)",
    ),
    (
        "duration = 0.1\n"
        + STREAM.format(rate=10.0, stop=0.05, area="[[0, 0.1], [0, 0.1]]", height=0.05).replace(
            "[0.005, 0.01]", "[5, 10]"
        ),
        "streams[1].radius",
        "(10 mm = 0.01)",
    ),
]


@pytest.mark.parametrize(("text", "field", "says"), SLIPS, ids=[s[1] for s in SLIPS])
def test_a_unit_slip_is_refused_with_the_unit_meant(tmp_path, capsys, text, field, says):
    err = refused(tmp_path, capsys, text, field)
    assert says in err


def test_values_at_the_edge_of_the_plausible_ranges_run_the_checks_clean():
    """A 0.3 m ball on the default plate, 100 m/s, a centre 6 m up, osmium-dense material:
    each at its bound, each accepted."""
    loads_scene(scene_text(ball("big", 0.3, (0, 0, 0.3))))
    loads_scene(scene_text(ball("fast", 0.01, (0, 0, 0.011), velocity=(0, 99, -5))))
    loads_scene(scene_text(ball("high", 0.01, (0, 0, 6.0))))
    loads_scene(
        scene_text(
            ball("a", 0.01, (0, 0, 0.011), material="os"),
            head="duration = 0.01\n"
            "[materials.os]\ndensity = 22590\nyoungs_modulus = 5.6e11\n"
            "poisson_ratio = 0.25\n",
        )  # fmt: skip
    )
