"""``plate.tail = "ritz"``: the coupled solver with Ritz pseudo-modes at the balls' first
contact points (tailbeam.solvers.modal_setup.ritz_prepass), against the full-FE reference of
tests/test_coupled_fe.py (same meshes, ball, sensor), plus the scene key and its bad input."""

import math

import pytest
from test_cli import tailbeam
from test_coupled_fe import IMPACT, MESHES, SENSOR, R, _basis, runs  # noqa: F401 (fixture)

import tailbeam as tb
from tailbeam.errors import InputError, WorkLimitError
from tailbeam.io.scene_dump import dumps_scene, scene_to_dict
from tailbeam.io.scene_file import loads_scene
from tailbeam.physics.bodies import Ball, Plate
from tailbeam.physics.materials import SANDSTONE
from tailbeam.plate.closed_forms import ssss_kirchhoff_basis
from tailbeam.scene import ContactSettings, ModalPlateSettings, Scene
from tailbeam.solvers.coupled.fe_compare import result_errors
from tailbeam.solvers.modal_setup.ritz_prepass import (
    first_contact_time,
    first_contacts,
    ritz_tail_basis,
)
from tailbeam.solvers.single_ball import simulate_scene_modal

BAND = 20000.0


def _scene(balls, duration=1e-3, **modal):
    """The test-mesh scene of test_coupled_fe: SSSS, 20 kHz, no plate or contact damping."""
    modal = {"damping_ratio": 0.0, "fmax_hz": BAND, **modal}  # tail: the default ("auto")
    modal.setdefault("mesh_divisions", MESHES[modal.get("theory", "kirchhoff")])
    return Scene(tuple(balls), Plate(), ContactSettings(damping=0.0), duration=duration,
                 plate_model="modal", modal=ModalPlateSettings(**modal))  # fmt: skip


def test_first_contact_points_follow_the_free_fall():
    # The lowest point gap + vz t - g t^2 / 2 reaches 0 at t_hit, where the ball is at
    # (x0 + vx t_hit, y0 + vy t_hit); a vertical drop lands under its start.
    g = 9.80665
    drop = Ball("drop", SANDSTONE, R, (0.1, -0.2, R + 0.05), (0.0, 0.0, 0.0))
    thrown = Ball("thrown", SANDSTONE, R, (-0.2, 0.1, R + 0.2), (0.3, -0.2, 1.0))
    off = Ball("off", SANDSTONE, R, (0.28, 0.0, R + 0.2), (2.0, 0.0, 0.0))  # lands past x = 0.3
    late = Ball("late", SANDSTONE, R, (0.0, 0.0, R + 3.0), (0.0, 0.0, 0.0))  # after duration
    scene = _scene([drop, thrown, off, late], duration=0.5)
    hits = {c["ball"]: c for c in first_contacts(scene, "kirchhoff")}
    assert sorted(hits) == ["drop", "thrown"]
    assert hits["drop"]["point"] == (0.1, -0.2)
    t = first_contact_time(0.2, 1.0, g)
    assert abs(0.2 + 1.0 * t - 0.5 * g * t * t) < 1e-15 and t > 0.0
    assert hits["thrown"]["point"] == pytest.approx((-0.2 + 0.3 * t, 0.1 - 0.2 * t), abs=1e-15)
    assert hits["thrown"]["speed"] == pytest.approx(math.sqrt(1.0 + 2 * g * 0.2), rel=1e-14)
    assert first_contact_time(0.1, -2.0, 0.0) == pytest.approx(0.05)
    assert first_contact_time(0.1, 2.0, 0.0) == math.inf


@pytest.mark.parametrize("tail_modes", [None, "auto"])
@pytest.mark.parametrize("theory", ["kirchhoff", "mindlin"])
def test_ritz_tail_scene_reaches_the_fe_reference_at_20_khz(runs, theory, tail_modes):  # noqa: F811
    # The target: 2e-5 on restitution, peak force, duration and max penetration at 20 kHz with
    # the default settings (tail "auto" = Ritz here, k = 32) and 200 steps/contact.
    # Measured: Kirchhoff 8x8 1.64e-5, Mindlin 6x6 1.66e-5 (the a posteriori "auto" k is
    # 32 on both; the rest is the time step's +1.6e-5 on the restitution), where the
    # quasi-static tail gives 3.0e-5 on both (test_coupled_fe). In-band sensor (0-10 kHz):
    # measured 1.09e-4 / 1.26e-4 (quasi-static 2.7e-4 / 2.0e-4); the bound 1.5e-3.
    case, ref = runs(theory)
    chosen = {} if tail_modes is None else {"tail_modes": tail_modes}
    scene = _scene([case.ball], duration=float(ref.t[-1]), theory=theory, **chosen)
    assert scene.laws() == (case.law,)
    basis = _basis(theory, fmax_hz=BAND)
    res = simulate_scene_modal(scene, basis=basis)
    err = result_errors(case, res, ref)
    assert err["contact"] < 2e-5, err
    assert err["sensor"] < 2e-4, err
    tail = res.info["tail"]
    assert tail["model"] == "ritz" and tail["k"] == 32 and tail["added_modes"] == 32
    assert tail.get("k_per_point", [32]) == [32] and ("k_per_point" in tail) == bool(chosen)
    assert res.plate.basis.n_modes == basis.n_modes + 32
    assert tail["load_radii_m"] == [case.load_radius]


@pytest.mark.parametrize("theory", ["kirchhoff", "mindlin"])
def test_no_double_counting_at_the_sensor(theory):
    # The sensors' quasi-static correction is the residual of the AUGMENTED basis (static
    # minus every mode held, the Ritz modes included): the Ritz modes span the contact's
    # static residual K^-1 f - sum phi phi^T f / omega^2 (their first Krylov vector), so what
    # is left at the contact and at the sensor is the round-off of "static minus the modal
    # sum" (measured 1.5e-7 of the quasi-static residual), not that residual a second time.
    ball = Ball("b", SANDSTONE, R, (*IMPACT, R + 1e-5), (0.0, 0.0, -1.0))
    basis = _basis(theory, fmax_hz=BAND)
    augmented, _ = ritz_tail_basis(_scene([ball], theory=theory), basis, 8)
    radius = first_contacts(_scene([ball], theory=theory), theory)[0]["radius"]
    assert (radius > 0.0) == (theory == "mindlin")  # a point load, or the Mindlin disc
    before = basis.residual_cross_compliance(IMPACT, [SENSOR, IMPACT], radius)
    after = augmented.residual_cross_compliance(IMPACT, [SENSOR, IMPACT], radius)
    assert abs(after).max() < 1e-6 * abs(before).max(), (before, after)
    assert augmented.residual_compliance([IMPACT], radius)[0] < 1e-6 * before[1]
    # a later contact elsewhere keeps the quasi-static residual of the augmented basis: still
    # there (the Ritz modes are local to the first point: measured 0.97 of it), never more
    other = [(-0.2, 0.15)]
    kept, aug = (
        basis.residual_compliance(other, radius),
        augmented.residual_compliance(other, radius),
    )
    assert 0.8 * kept[0] < aug[0] <= kept[0], (kept, aug)


SCENE = """
duration = 0.0008
[contact]
damping = 0.0
[plate]
model = "modal"
theory = "kirchhoff"
mesh_divisions = 8
fmax = 20000
tail = "ritz"
[[balls]]
name = "a"
material = "sandstone"
radius = 0.03
position = [0.05, 0.03, 0.03001]
velocity = [0.0, 0.0, -1.0]
"""


def test_scene_key_end_to_end(capsys):
    scene = loads_scene(SCENE)
    # the solver's default, set by the scene: 32 on the coupled solver (4 for a stream's
    # contacts, tests/test_stream_tail.py)
    assert scene.modal.tail == "ritz" and scene.modal.tail_modes == 32
    assert ModalPlateSettings(tail="ritz").tail_modes is None
    assert loads_scene(SCENE.replace('tail = "ritz"', 'tail = "ritz"\ntail_modes = 16')).modal == (
        ModalPlateSettings(
            theory="kirchhoff", mesh_divisions=8, fmax_hz=BAND, tail="ritz", tail_modes=16
        )  # fmt: skip
    )
    assert scene_to_dict(scene)["plate"]["tail"] == "ritz"
    # always written back (a sweep's case scene must keep it whatever the default is)
    plain = scene_to_dict(loads_scene(SCENE.replace('tail = "ritz"', 'tail = "quasi-static"')))
    assert plain["plate"]["tail"] == "quasi-static" and plain["plate"]["tail_modes"] == 32
    assert (
        loads_scene(
            dumps_scene(loads_scene(SCENE.replace('tail = "ritz"', 'tail = "quasi-static"')))
        ).modal.tail
        == "quasi-static"
    )
    assert scene_to_dict(loads_scene(SCENE.replace('tail = "ritz"', "")))["plate"]["tail"] == "auto"
    res = tb.simulate(scene)
    assert res.info["tail"]["k"] == 32 and res.info["tail"]["points"] == 1
    assert len(res.impacts) == 1
    err = capsys.readouterr().err
    assert "Ritz tail: k = 32 (plate.tail_modes, the default)" in err
    assert "Ritz tail k = 32, +32 modes" in err


@pytest.mark.parametrize(
    "new, field, rule_part",
    [
        ('tail = "cubic"', "plate.tail", "one of"),
        ('tail = "ritz"\ntail_modes = 0', "plate.tail_modes", ">= 1"),
        ('tail = "ritz"\ntail_modes = 2.5', "plate.tail_modes", "whole number"),
        ('tail = "ritz"\ntail_modes = "many"', "plate.tail_modes", "'auto'"),
        ('tail = "ritz"\nresidual_flexibility = false', "plate.tail", "residual_flexibility"),
        ('tail = "ritz"\ncoupling = "one-way"', "plate.tail", "two-way"),
    ],
)
def test_bad_tail_settings_name_the_field(new, field, rule_part):
    with pytest.raises(InputError) as info:
        loads_scene(SCENE.replace('tail = "ritz"', new))
    assert info.value.field == field and rule_part in info.value.rule
    assert "\n" not in str(info.value)


def test_ritz_needs_an_fe_basis_and_a_number_on_the_stream_solver():
    ball = Ball("b", SANDSTONE, R, (*IMPACT, R + 1e-5), (0.0, 0.0, -1.0))
    with pytest.raises(InputError, match=r"^plate\.tail: .*closed form"):
        ritz_tail_basis(_scene([ball]), ssss_kirchhoff_basis(Plate(), BAND))
    # the stream solver has its own "ritz" (oscillators at every contact): a number, not "auto"
    inclined = Scene((ball,), Plate(), plate_model="modal", inclination=10.0,
                     modal=ModalPlateSettings(tail="ritz", tail_modes="auto"))  # fmt: skip
    with pytest.raises(InputError, match=r"^plate\.tail_modes: 'auto' is the coupled solver's"):
        tb.simulate(inclined, progress=False)


@pytest.mark.parametrize(
    "new, field, error",
    [
        ('tail = "cubic"', "plate.tail", "plate.tail:"),
        ('tail = "ritz"\ntail_modes = -3', "plate.tail_modes", "plate.tail_modes:"),
        ('tail = "ritz"\ntail_modes = 2000', "plate.tail_modes", "2000 Ritz modes x 1"),
    ],
)
def test_cli_bad_tail_exit_2_one_line_no_output(tmp_path, new, field, error):
    bad = tmp_path / "bad.toml"
    bad.write_text(SCENE.replace('tail = "ritz"', new))
    out = tmp_path / "out"
    proc = tailbeam("simulate", bad, "--out", out)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1, proc.stderr
    assert field in lines[0] and error in lines[0] and "Traceback" not in proc.stderr
    assert not out.exists()


def test_work_limit_before_the_basis_is_built():
    balls = [Ball(f"b{i}", SANDSTONE, 0.01, (-0.25 + 0.025 * i, 0.0, 0.02), (0.0, 0.0, 0.0))
             for i in range(20)]  # fmt: skip
    scene = _scene(balls, duration=0.1, tail="ritz", tail_modes=64, mesh_divisions=200)
    with pytest.raises(WorkLimitError, match=r"^plate\.tail_modes: 64 Ritz modes x 20"):
        simulate_scene_modal(scene)


def test_augmented_basis_keeps_the_kept_shapes_and_repeats_itself():
    # one mesh search serves the kept and the Ritz modes (memoised): the kept modes' shapes
    # are the parent basis' own (measured 2e-16 relative), a repeated call gives the same
    basis = _basis("mindlin", fmax_hz=BAND)
    ball = Ball("b", SANDSTONE, R, (*IMPACT, R + 1e-5), (0.0, 0.0, -1.0))
    augmented, _ = ritz_tail_basis(_scene([ball], theory="mindlin"), basis, 4)
    pts = [SENSOR, (-0.2, 0.13), (0.3, 0.0)]
    first = augmented.deflection(pts)
    kept = basis.deflection(pts)
    assert abs(first[:, : basis.n_modes] - kept).max() < 1e-12 * abs(kept).max()
    first[:] = 0.0  # the caller's copy: the memo is not changed through it
    assert abs(augmented.deflection(pts)[:, : basis.n_modes] - kept).max() < 1e-12 * abs(kept).max()


@pytest.mark.parametrize(
    "modal, reason",
    [
        ({}, "closed form"),  # the Navier basis passed below
        ({"residual_flexibility": False}, "residual_flexibility is off"),
        ({"coupling": "one-way"}, "one-way coupling"),
        ({"tail_modes": 600}, "2 first-contact points x 600 pseudo-modes > 128"),
        ({"tail_modes": 65}, "2 first-contact points x 65 pseudo-modes > 128"),  # the budget
    ],
)
def test_auto_tail_keeps_the_quasi_static_tail_where_ritz_does_not_apply(capsys, modal, reason):
    # plate.tail = "auto" (the default) runs where "ritz" would refuse, with the quasi-static
    # tail, and says why on stderr and in result.info["tail"]
    balls = [Ball(n, SANDSTONE, R, (x, 0.03, R + 1e-5), (0.0, 0.0, -1.0))
             for n, x in (("a", 0.05), ("b", -0.1))]  # fmt: skip
    scene = _scene(balls, duration=2e-4, mesh_divisions=4, **modal)
    assert scene.modal.tail == "auto"
    basis = ssss_kirchhoff_basis(Plate(), BAND) if not modal else _basis("kirchhoff", fmax_hz=BAND)
    res = simulate_scene_modal(scene, basis=basis)
    assert res.info["tail"]["model"] == "quasi-static" and reason in res.info["tail"]["reason"]
    assert res.plate.basis.n_modes == basis.n_modes
    assert f"tail: quasi-static ({res.info['tail']['reason']})" in capsys.readouterr().err


def test_auto_tail_on_the_stream_solver_runs(capsys):
    # "auto" on the stream solver: its contact tails (tests/test_stream_tail.py) where they
    # apply, else the static spring, said
    ball = Ball("b", SANDSTONE, R, (*IMPACT, R + 1e-3), (0.0, 0.0, -1.0))
    inclined = Scene((ball,), Plate(), plate_model="modal", inclination=10.0, duration=2e-3,
                     modal=ModalPlateSettings(fmax_hz=2000.0))  # fmt: skip
    assert inclined.modal.tail == "auto"
    result = tb.simulate(inclined)
    assert len(result.impacts) == 1 and result.info["band"]["tail_band_hz"] == 8000.0
    assert "tail: 4 oscillators at each plate contact for the modes between 2 and 8 kHz" in (
        capsys.readouterr().err
    )
    off = ModalPlateSettings(fmax_hz=2000.0, residual_flexibility=False)
    without = Scene((ball,), Plate(), plate_model="modal", inclination=10.0, duration=2e-3,
                    modal=off)  # fmt: skip
    assert tb.simulate(without).info["band"]["tail_band_hz"] is None
    assert "tail: quasi-static (plate.tail auto: residual flexibility off)" in (
        capsys.readouterr().err
    )


@pytest.mark.parametrize("tail", ["quasi-static", "ritz", "auto"])
def test_a_sweep_case_keeps_the_tail_of_its_base_scene(tail):
    # the case scenes of a sweep are the base scene written back (scene_dump): a tail set in
    # the base must survive it, the default's included
    import tomllib

    from tailbeam.study.design import expand, parse_sweep

    base = tomllib.loads(SCENE.replace('tail = "ritz"', f'tail = "{tail}"\ntail_modes = 8'))
    base["sensors"] = [{"name": "S1", "position": [0.1, 0.15], "sample_rate": 51200.0}]
    cases = expand(parse_sweep({"scene": base, "axes": {"balls.a.radius": [0.02, 0.03]}}))
    for case in cases:
        modal = loads_scene(case.toml).modal
        assert (modal.tail, modal.tail_modes) == (tail, 8)


def test_auto_tail_builds_up_to_its_budget():
    # 2 first contacts x 64 pseudo-modes = AUTO_RITZ_BUDGET: still built (65: kept out, above)
    balls = [Ball(n, SANDSTONE, R, (x, 0.03, R + 1e-5), (0.0, 0.0, -1.0))
             for n, x in (("a", 0.05), ("b", -0.1))]  # fmt: skip
    scene = _scene(balls, duration=2e-4, tail_modes=64)
    basis = _basis("kirchhoff", fmax_hz=BAND)
    res = simulate_scene_modal(scene, basis=basis)
    assert res.info["tail"]["model"] == "ritz" and res.info["tail"]["added_modes"] == 128
    assert res.plate.basis.n_modes == basis.n_modes + 128
