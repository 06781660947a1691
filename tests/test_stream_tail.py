"""The stream solver's dynamic contact tail (``plate.tail = "ritz"``,
tailbeam.plate.contact_tail), each check against an independent truth:

- the Gauss rule keeps the 2k moments of the tail's measure (a closed sum), and is exact
  when the measure has no more points than oscillators;
- one impact with a tail that holds every mode of the wider basis above the band is the
  impact on the wider basis itself (the same modes, as a contact's own oscillators);
- with c = 0 and undamped modes the energy of a stream is conserved, the tails' energy at
  the ends of their contacts included;
- with 4 oscillators the first impacts of lumps of 10-40 mm at a 3 kHz band come within
  0.5 % of all modes to 12 kHz, where the static spring alone is off by more;
- the scene key runs end to end on a stream and says what it chose.
"""

import numpy as np
import pytest

from tailbeam import COAL, SANDSTONE
from tailbeam.physics.bodies import Ball, Plate
from tailbeam.physics.incline import InclinedPlate
from tailbeam.plate.closed_forms import ssss_kirchhoff_basis
from tailbeam.plate.contact_tail import ContactTail, gauss_rule
from tailbeam.solvers.stream.driver.loop import solve_stream
from tailbeam.solvers.stream.plate import StreamPlate
from tailbeam.streams.generator import Particle, generate_particles


def _moments(b, nu, m):
    return np.sum(b**2 / nu ** (2 * m + 2))


def test_gauss_rule_keeps_the_moments():
    rng = np.random.default_rng(4)
    omega = np.sort(rng.uniform(2e4, 2e5, 60))
    phi = rng.normal(size=60)
    for k in (1, 2, 4):
        nu, b = gauss_rule(phi, omega, k)
        assert len(nu) == k and np.all(np.diff(nu) > 0)
        for m in range(2 * k):
            assert _moments(b, nu, m) == pytest.approx(_moments(phi, omega, m), rel=1e-9, abs=0)
        # the next moment is not kept: the rule is not the measure itself
        assert _moments(b, nu, 2 * k) != pytest.approx(_moments(phi, omega, 2 * k), rel=1e-6, abs=0)
    # three points (one at a node: phi = 0, no weight): two oscillators are the measure
    nu, b = gauss_rule([0.5, 0.0, -2.0], [3e4, 5e4, 9e4], 6)
    np.testing.assert_allclose(nu, [3e4, 9e4], rtol=1e-12)
    np.testing.assert_allclose(b, [0.5, 2.0], rtol=1e-12)
    assert gauss_rule(np.zeros(3), [3e4, 5e4, 9e4], 4)[0].size == 0


def _particle(material, radius, speed, xy=(0.07, 0.05)):
    ball = Ball("b", material, radius, (*xy, radius + 1e-4), (0.0, 0.0, -speed))
    return Particle(ball.name, "", "coal", material, radius, ball.mass, 0.0,
                    tuple(ball.position), tuple(ball.velocity))  # fmt: skip


def _first(plate, particle, damping=0.0):
    run = solve_stream([particle], InclinedPlate(), 2e-3, damping=damping, rtol=1e-12,
                       progress=False, plate=plate)  # fmt: skip
    c = next(c for c in run.contacts if c.partner == "plate")
    return np.array([c.peak_force, c.t_end - c.t_start, c.v_out]), run


def _tail_plate(band, wide, k, zeta=0.01):
    tail = ContactTail(band.omega, wide, k, lambda nu: np.full(len(nu), zeta))
    return StreamPlate(band, np.full(band.n_modes, zeta), tail=tail)


def test_a_tail_of_every_wider_mode_is_the_wider_basis():
    band, wide = ssss_kirchhoff_basis(Plate(), 3000.0), ssss_kirchhoff_basis(Plate(), 3600.0)
    assert wide.n_modes - band.n_modes == 9  # 5 distinct frequencies: 5 points of the measure
    particle = _particle(SANDSTONE, 0.012, 3.0)
    truth, _ = _first(StreamPlate(wide, np.full(wide.n_modes, 0.01)), particle, damping=300.0)
    ours, run = _first(_tail_plate(band, wide, 12), particle, damping=300.0)
    static, _ = _first(StreamPlate(band, np.full(band.n_modes, 0.01)), particle, damping=300.0)
    print("tail vs wider basis:", ours / truth - 1, " static spring:", static / truth - 1)
    assert np.all(np.abs(ours / truth - 1.0) < 1e-12)  # measured 1.7e-14
    assert np.abs(static[0] / truth[0] - 1.0) > 1e-5  # (the tail is not the static spring)
    assert run.stats["tail_energy_dropped"] > 0.0


def test_energy_with_tails_is_conserved():
    """c = 0, undamped: released = left + at the end (the plate's modes and the tails of the
    contacts in progress included) + the tails' energy when their contacts ended."""
    band, wide = ssss_kirchhoff_basis(Plate(), 3000.0), ssss_kirchhoff_basis(Plate(), 6000.0)
    settings = dict(name="s", rate=100.0, start=0.0, stop=0.2, gangue_fraction=0.3,
                    radius=[0.01, 0.03], area=[[-0.15, 0.15], [-0.15, 0.15]],
                    height=[0.02, 0.2], velocity=[0.0, 0.0, -1.0], velocity_spread=0.5,
                    seed=2)  # fmt: skip
    particles = generate_particles([settings], InclinedPlate())
    plate = _tail_plate(band, wide, 3, zeta=0.0)
    run = solve_stream(particles, InclinedPlate(), 0.3, rtol=1e-12, rest_speed=0.0,
                       progress=False, plate=plate)  # fmt: skip
    st = run.stats
    assert len(run.contacts) > 20 and st["tail_energy_dropped"] > 1e-6 * st["energy_released"]
    imbalance = (st["energy_released"] - st["energy_left"] - st["energy_final"]
                 - st["rest_energy_removed"] - st["energy_plate_final"]
                 - st["tail_energy_dropped"])  # fmt: skip
    print(f"energy imbalance / released with tails: {imbalance / st['energy_released']:.2e}")
    assert abs(imbalance) < 1e-9 * st["energy_released"]


@pytest.mark.parametrize("material", [COAL, SANDSTONE], ids=["coal", "sandstone"])
def test_four_oscillators_reach_the_wider_band(material):
    band, wide = ssss_kirchhoff_basis(Plate(), 3000.0), ssss_kirchhoff_basis(Plate(), 12000.0)
    worst_tail, worst_static = 0.0, 0.0
    for radius in (0.010, 0.015, 0.020, 0.030, 0.040):
        particle = _particle(material, radius, 3.0)
        truth, _ = _first(StreamPlate(wide, np.full(wide.n_modes, 0.01)), particle, 300.0)
        ours, _ = _first(_tail_plate(band, wide, 4), particle, 300.0)
        static, _ = _first(StreamPlate(band, np.full(band.n_modes, 0.01)), particle, 300.0)
        worst_tail = max(worst_tail, abs(ours[0] / truth[0] - 1.0))
        worst_static = max(worst_static, abs(static[0] / truth[0] - 1.0))
    print(f"{material.name}: peak force, 4 oscillators {worst_tail:.2e}, static {worst_static:.2e}")
    assert worst_tail < 5e-3 and worst_tail < 0.5 * worst_static


SCENE = """
duration = 0.15
[contact]
damping = 300.0
[plate]
model = "modal"
boundary = "SSSS"
theory = "kirchhoff"
inclination = 20.0
fmax = 2000.0
tail = "ritz"
{extra}
[[streams]]
name = "cave"
rate = 60.0
start = 0.0
stop = 0.1
gangue_fraction = 0.5
radius = [0.01, 0.02]
area = [[-0.2, 0.0], [-0.15, 0.15]]
height = [0.01, 0.05]
seed = 3
[[sensors]]
name = "S1"
position = [0.1, 0.05]
sample_rate = 8000.0
"""


def test_stream_scene_with_the_ritz_tail_says_what_it_chose(capsys):
    import tailbeam as tb
    from tailbeam.io.scene_dump import scene_to_dict
    from tailbeam.io.scene_file import loads_scene

    scene = loads_scene(SCENE.format(extra="tail_modes = 3"))
    result = tb.simulate(scene)
    err = capsys.readouterr().err
    assert "tail: 3 oscillators at each plate contact for the modes between 2 and 8 kHz" in err
    assert "plate.tail)" in err  # set by the scene, not chosen
    band = result.info["band"]
    assert (band["tail_band_hz"], band["tail_oscillators"]) == (8000.0, 3)
    assert result.stats["tail_energy_dropped"] > 0.0 and len(result.impacts) > 3
    # written back as the run used it: the stream's default is 4 per contact
    assert scene_to_dict(loads_scene(SCENE.format(extra="")))["plate"]["tail_modes"] == 4


def test_cli_stream_tail_auto_is_one_line_exit_2(tmp_path):
    from test_cli import tailbeam

    bad = tmp_path / "bad.toml"
    bad.write_text(SCENE.format(extra='tail_modes = "auto"'))
    proc = tailbeam("simulate", bad, "--out", tmp_path / "out")
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1, proc.stderr
    assert "plate.tail_modes: 'auto' is the coupled solver's" in lines[0]
    assert not (tmp_path / "out").exists()
