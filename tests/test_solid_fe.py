"""The coupled solver on a structure against the full finite-element integration of the
same mesh (tailbeam.solvers.coupled.fe_structure: every DOF, Newmark average acceleration,
the IMPACT law implicit each step; the plate's reference run on the structure's K, M, load
vector and surface readings).

Configuration: a box beam 0.4 x 0.15 x 0.1 m, 10 mm steel walls (tests/solid_meshes.py,
4 x 2 x 1 cells between the walls: 841 DOFs, a legitimate truth because both sides use the
same mesh and elements), pinned at its root about y, a 2e7 N/m spring under its tip. A 30 mm
sandstone ball at 1 m/s lands on the top at (0.05, 0) m; the sensor is on the back (the
bottom's underside at x = -0.1 m) along z, compared in 0-2.5 kHz over the first 1.5 ms. No
damping (the FE model has none to match); gravity as the library's default.
"""

import numpy as np
import pytest
from solid_meshes import box_beam_mesh

from tailbeam.io.scene_file import loads_scene
from tailbeam.physics.bodies import Ball
from tailbeam.physics.contact_law import ball_plate_law
from tailbeam.physics.materials import CARBON_STEEL, SANDSTONE
from tailbeam.plate.solid import Support, assemble_structure, structure_modes
from tailbeam.signals.sensor import SensorSpec
from tailbeam.solvers.coupled.fe_compare import modal_errors, observed_order
from tailbeam.solvers.coupled.fe_reference import QUANTITIES, fe_time_step_study
from tailbeam.solvers.coupled.fe_structure import StructureCase, structure_fe_reference
from tailbeam.solvers.modal_setup.band import choose_band

R = 0.03
REF_DT = 5e-7  # 670 steps per contact (0.335 ms)
SUPPORTS = (Support("pinned", group="root", axis=(0.0, 1.0, 0.0)),
            Support("spring", group="tip", stiffness=2.0e7, direction=(0.0, 0.0, 1.0)))  # fmt: skip


@pytest.fixture(scope="module")
def beam(tmp_path_factory):
    path = tmp_path_factory.mktemp("solid_fe") / "box.msh"
    box_beam_mesh(path, 0.4, 0.15, 0.1, 0.01, 4, cells_y=2, cells_z=1)
    model = assemble_structure(path, "top", SUPPORTS)
    ball = Ball("b", SANDSTONE, R, (0.05, 0.0, R + 1e-5), (0.0, 0.0, -1.0))
    sensor = SensorSpec("back", (-0.1, 0.0, -0.1), direction=(0.0, 0.0, 1.0))
    case = StructureCase(model, ball, ball_plate_law(SANDSTONE, R, CARBON_STEEL), sensor,
                         sensor_band_hz=2500.0, sensor_window_s=1.5e-3)  # fmt: skip
    return path, case, case.reference(REF_DT, duration=2e-3)


def test_reference_on_a_structure_is_second_order(beam):
    # Measured orders 1.85-1.97 (4e-6 -> 1e-6 s), within 2e-6 of Richardson at 5e-7 s
    _, case, _ = beam
    study = fe_time_step_study(case.model, case.ball, case.law, 5e-4, [2e-6, 1e-6, 5e-7],
                               reference=structure_fe_reference,
                               load_radius=case.load_radius)  # fmt: skip
    for name in QUANTITIES:
        assert 1.7 < study["orders"][name][0] < 2.3, (name, study["orders"])
        assert study["error_estimate"][name] < 5e-6, (name, study["error_estimate"])


def test_coupled_solver_converges_to_the_full_fe_with_the_band(beam):
    # Measured (max contact error; sensor), 800 steps/contact, 5 / 10 / 20 / 40 kHz
    # (13 / 34 / 71 / 153 modes): 6.8e-3 7.4e-5 3.8e-5 1.4e-6 (order 3.9);
    # 8.4e-2 1.2e-2 1.2e-3 2.1e-4 (order 2.9). Kept modes only: contact 2.6e-2 3.9e-3
    # 2.6e-3 3.0e-4.
    _, case, ref = beam
    bands = [5000.0, 10000.0, 20000.0, 40000.0]
    errs, bare = [], []
    for band in bands:
        basis = structure_modes(case.model, fmax_hz=band)
        errs.append(modal_errors(case, basis, ref, steps_per_contact=800))
        bare.append(modal_errors(case, basis, ref, steps_per_contact=800,
                                 residual_flexibility=False))  # fmt: skip
    contact, sensor = [e["contact"] for e in errs], [e["sensor"] for e in errs]
    assert all(b < a for a, b in zip(contact, contact[1:], strict=False)), contact
    assert all(b < a for a, b in zip(sensor, sensor[1:], strict=False)), sensor
    assert observed_order(bands, contact) > 3.0, contact
    assert observed_order(bands, sensor) > 2.3, sensor
    assert contact[-1] < 5e-6 and sensor[-1] < 5e-4, (contact, sensor)
    for with_rf, without in zip(contact[1:], bare[1:], strict=True):
        assert with_rf < without["contact"] / 10, (contact, bare)


def test_default_band_and_settings_against_the_full_fe(beam):
    # The band a scene of this impact gets without plate.fmax, the solver's default settings
    # (residual flexibility, 200 steps per contact): 10 kHz, 34 modes. Measured: contact
    # 6.6e-5 (peak force), sensor 1.1e-2 (8.1e-3 without the truncated modes' quasi-static
    # part: the modes just above 10 kHz do not answer the 3 kHz pulse quasi-statically).
    path, case, ref = beam
    band = choose_band(loads_scene(_scene(path, case.ball)))["fmax_hz"]
    assert band == 10000.0
    err = modal_errors(case, structure_modes(case.model, fmax_hz=band), ref)
    assert err["contact"] < 1e-4, err
    assert err["sensor"] < 2e-2, err


def _scene(path, ball) -> str:
    x, y, z = ball.position
    return (f'duration = 0.002\n[plate]\nmodel = "modal"\nmaterial = "carbon_steel"\n'
            f'mesh = "{path.as_posix()}"\nimpact_face = "top"\n'
            '[[plate.supports]]\ngroup = "root"\nkind = "pinned"\naxis = [0.0, 1.0, 0.0]\n'
            '[[plate.supports]]\ngroup = "tip"\nkind = "spring"\nstiffness = 2.0e7\n'
            'direction = [0.0, 0.0, 1.0]\n'
            f'[[balls]]\nname = "b"\nmaterial = "sandstone"\nradius = {R}\n'
            f'position = [{x}, {y}, {z}]\nvelocity = [0.0, 0.0, {ball.velocity[2]}]\n')  # fmt: skip


def test_structure_reference_reads_every_axis_and_refuses_bad_sensors(beam):
    # A three-axis sensor gives one row per axis: their sum along (1, 1, 1) / sqrt 3 equals
    # that direction's single reading (the surface operator is linear in the direction).
    _, case, _ = beam
    point = (-0.1, 0.0, -0.1)
    three = SensorSpec("s", point, axes="xyz")
    diag = SensorSpec("d", point, direction=(1.0, 1.0, 1.0))
    run = structure_fe_reference(case.model, case.ball, case.law, 4e-4, dt=2e-6,
                                 load_radius=case.load_radius, sensors=[three, diag])  # fmt: skip
    assert run.sensor_a.shape[0] == 4
    summed = run.sensor_a[:3].sum(axis=0) / np.sqrt(3.0)
    assert np.allclose(summed, run.sensor_a[3], rtol=0, atol=1e-12 * np.abs(summed).max())
    from tailbeam.errors import InputError

    with pytest.raises(InputError, match=r"sensors\[off\]\.position"):
        structure_fe_reference(case.model, case.ball, case.law, 1e-4, dt=2e-6,
                               sensors=[SensorSpec("off", (0.0, 0.0, -0.05))])  # fmt: skip
    with pytest.raises(InputError, match="sensors"):
        structure_fe_reference(case.model, case.ball, case.law, 1e-4, dt=2e-6,
                               sensors=[(0.0, 0.0)])  # fmt: skip
