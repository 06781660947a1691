"""The run cost estimate (tailbeam.solvers.cost, run_cost, modal_setup.plan): its structure,
never its timings (those are benchmarks/bench_cost_model.py's): the parts sum to the total,
the estimate grows with the band, the particles and the duration, a cached basis costs
nothing to solve, and a sensor whose replay is beyond the limits is refused naming
``sensors[i].sample_rate`` before any work."""

import math

import pytest

from tailbeam.errors import InputError
from tailbeam.io.scene_file import loads_scene
from tailbeam.simulation import choose_solver
from tailbeam.solvers import cost as C
from tailbeam.solvers.coupled.solver import DEFAULT_REST_SPEED
from tailbeam.solvers.run_cost import ball_restitution, estimate_run, expected_impacts

BALL = """
[[balls]]
name = "b"
material = "sandstone"
radius = 0.02
position = [0.05, 0.05, 0.03]
velocity = [0.0, 0.0, -2.0]
"""
SENSOR = """
[[sensors]]
name = "s"
position = [0.0, 0.1]
sample_rate = {rate}
bandwidth = 2000.0
"""
STREAM = """
[[streams]]
name = "s"
rate = {rate}
stop = 0.1
gangue_fraction = 0.3
radius = [0.01, 0.02]
area = [[-0.2, 0.0], [-0.1, 0.1]]
height = [0.02, 0.05]
seed = 1
"""


def modal(fmax=3000.0, duration=0.05, rate=10240.0, extra=""):
    text = (
        f'duration = {duration}\n{extra}\n[plate]\nmodel = "modal"\nfmax = {fmax}\n'
        + BALL
        + SENSOR.format(rate=rate)
    )
    return loads_scene(text)


def stream(rate=100.0, duration=0.2, model="rigid"):
    text = f'duration = {duration}\n[plate]\nmodel = "{model}"\ninclination = 20.0\n'
    text += ("fmax = 3000.0\n" if model == "modal" else "") + STREAM.format(rate=rate)
    return loads_scene(text)


@pytest.fixture(autouse=True)
def empty_cache(tmp_path, monkeypatch):
    """No basis cached: every eigen-solve is estimated, not looked up."""
    monkeypatch.setenv("TAILBEAM_CACHE_DIR", str(tmp_path))


def run_cost(scene, solver="auto"):
    return estimate_run(scene, choose_solver(scene, solver))


def test_parts_sum_to_the_total_and_name_the_work():
    cost = run_cost(modal())
    names = [p.name for p in cost.parts]
    assert names == ["eigen-solve", "set-up", "simulation", "sensor replay", "writing"]
    assert cost.time_s == pytest.approx(sum(p.time_s for p in cost.parts), rel=1e-15)
    assert cost.memory_bytes == max(p.memory_bytes for p in cost.parts)
    assert "eigen-solve (band 3 kHz from plate.fmax)" in cost.describe()
    assert cost.as_dict()["parts"]["sensor replay"]["time_s"] == cost.part("sensor replay").time_s


def test_estimate_grows_with_the_band():
    times = [run_cost(modal(fmax=f)).part("eigen-solve").time_s for f in (2000.0, 4000.0, 8000.0)]
    assert times[0] < times[1] < times[2]
    totals = [run_cost(modal(fmax=f)).time_s for f in (2000.0, 4000.0, 8000.0)]
    assert totals[0] < totals[1] < totals[2]


def test_estimate_grows_with_the_duration_and_the_sample_rate():
    durations = [run_cost(modal(duration=d)).time_s for d in (0.05, 0.2, 0.8)]
    assert durations[0] < durations[1] < durations[2]
    rates = [run_cost(modal(rate=r)).part("sensor replay").time_s for r in (1e4, 1e5, 1e6)]
    assert rates[0] < rates[1] < rates[2]


@pytest.mark.parametrize("model", ["rigid", "modal"])
def test_estimate_grows_with_the_particles(model):
    totals = [run_cost(stream(rate=r, model=model)).part("simulation").time_s for r in (50, 200)]
    assert totals[0] < totals[1]
    reference = [run_cost(stream(rate=r), "stream-reference").time_s for r in (30, 120)]
    assert reference[0] < reference[1]


def test_a_cached_basis_is_not_solved_again():
    part = C.eigen_part("eigen-solve", 30000, 250, 4e7, "")
    fresh = C.eigen_part("eigen-solve", 30000, 250, None, "")
    assert part.cached and not fresh.cached and part.time_s < fresh.time_s
    assert "cached" in part.describe()


def test_expected_impacts_of_a_bouncing_ball():
    # an undamped Hertz impact returns the speed (restitution ~1): the ball bounces to the
    # same height for the whole run, a flight of 2 v / g between impacts (the truth)
    speed = (2.0**2 + 2 * 9.80665 * 0.01) ** 0.5  # 2 m/s, 10 mm above the plate
    flight = 2 * speed / 9.80665
    undamped = modal(duration=4.5 * flight, extra="[contact]\ndamping = 0.0")
    assert expected_impacts(undamped) == 5  # at 0.005 s, then 4 flights later
    # damped (the default): the rebounds fall geometrically, v e^k, and the ball rests once
    # one is slower than the rest speed; their flights sum to less than 2 v / (g (1 - e))
    damped = modal(duration=10.0)
    law = damped.laws()[0]
    e = ball_restitution(damped.balls[0].mass, speed, law)
    assert 0.0 < e < 1.0 and 2 * speed / (9.80665 * (1 - e)) < 10.0
    rebounds = math.floor(math.log(DEFAULT_REST_SPEED / speed) / math.log(e))
    assert expected_impacts(damped) == 1 + rebounds


def test_sensor_replay_beyond_the_limit_is_refused_naming_the_sensor():
    with pytest.raises(InputError) as err:
        run_cost(modal(rate=5e8, duration=0.02))
    assert err.value.field == "sensors[1].sample_rate"


def test_a_1e9_hz_sensor_is_refused_by_simulate_before_any_work():
    # 1e9 Hz over 10 ms is 1e7 samples (within the preflight's 2e7), but 2e7 fine samples of
    # replay, 1e7 CSV rows and a figure of them: refused before the basis is computed
    import tailbeam

    with pytest.raises(InputError) as err:
        tailbeam.simulate(modal(rate=1e9, duration=0.01), progress=False)
    assert err.value.field == "sensors[1].sample_rate"
    assert "lower it or the duration" in err.value.rule


def test_a_total_names_the_parts_it_leaves_out():
    # a part that is not estimated counts as 0 s: the headline total must say it is partial
    parts = (C.Part("eigen-solve", 0.0, 0.0, estimated=False), C.Part("simulation", 2.0, 1e8))
    line = C.RunCost(parts).describe()
    assert line.startswith("estimated cost without the eigen-solve (not estimated) ")
    whole = C.RunCost(parts[1:]).describe()
    assert whole.startswith("estimated cost ") and "without" not in whole


def test_the_line_names_what_the_band_costs_and_what_half_of_it_would():
    # no plate.fmax, a sensor of 20 kHz bandwidth: the band comes from the sensors, the
    # line gives its bases' cost and half the band's, and the key that sets the band
    text = 'duration = 0.05\n[plate]\nmodel = "modal"\n' + BALL + SENSOR.format(rate=51200.0)
    scene = loads_scene(text.replace("bandwidth = 2000.0", "bandwidth = 20000.0"))
    cost = run_cost(scene)
    eigen = cost.part("eigen-solve")
    assert eigen.driver.startswith("band 20 kHz from the sensors' bandwidth")
    bases = f"the bases of 20 kHz ~{eigen.time_s:.0f} s; 10 kHz would take ~"
    assert cost.alternative.startswith(bases) and cost.alternative.endswith(
        " s for the bases: set sensors[i].bandwidth"
    )
    half = float(cost.alternative[len(bases) :].split(" ")[0])
    assert half < eigen.time_s
    assert cost.describe().endswith(cost.alternative)


def test_the_load_stretch_is_the_load_over_the_cores(monkeypatch):
    monkeypatch.setattr(C.os, "cpu_count", lambda: 2)
    monkeypatch.setattr(C.os, "getloadavg", lambda: (6.0, 5.0, 4.0))
    assert C.load_stretch() == (3.0, 6.0, 2)
    monkeypatch.setattr(C.os, "getloadavg", lambda: (0.5, 0.5, 0.5))
    assert C.load_stretch()[0] == 1.0  # an idle machine: the estimate itself
