"""One result type (tailbeam.results.result): the impacts.csv and particles.csv columns of [[balls]]
scenes on the rigid and the modal plate.

Independent truths: free fall (a ball dropped from rest at gap h strikes at t = sqrt(2 h / g)
with speed sqrt(2 g h), where its centre is above its release point, or moved by its
uniform lateral velocity), the ball's mass 4/3 pi r^3 rho, the scene's own balls and labels,
the centre's crossing of the plate edge, the coupled solver's own contact points, and the
stream solver (a separate solver with its own records) run on the same balls: the new columns
of the single-ball solvers must mean what the stream solver writes.
"""

import csv
import math

import numpy as np
import pytest

import tailbeam
from tailbeam.cli import main
from tailbeam.errors import InputError
from tailbeam.io.scene_dump import dumps_scene
from tailbeam.physics.bodies import Ball
from tailbeam.physics.materials import COAL, SANDSTONE
from tailbeam.results.result import IMPACT_COLUMNS, IMPACT_TABLE_COLUMNS, PARTICLE_COLUMNS, Result
from tailbeam.scene import ModalPlateSettings, Scene
from tailbeam.solvers.stream.solver import simulate_stream

G = 9.80665
GAPS = {"c": 0.02, "s": 0.03, "m": 0.01}  # drop gaps h (m): lowest point above the plate
LATERAL = {"m": 1.0}  # m/s along x


def balls(radii=None):
    radii = radii or {"c": 0.03, "s": 0.025, "m": 0.02}
    xy = {"c": (-0.1, 0.05), "s": (0.15, -0.1), "m": (0.2, 0.0)}
    mats = {"c": COAL, "s": SANDSTONE, "m": COAL}
    return tuple(
        Ball(n, mats[n], radii[n], (*xy[n], radii[n] + GAPS[n]), (LATERAL.get(n, 0.0), 0.0, 0.0))
        for n in ("c", "s", "m")
    )


@pytest.fixture(scope="module")
def rigid_scene():
    # "s" is sandstone labelled coal in the scene: the label column is the scene's, not a rule
    return Scene(balls(), duration=0.15, labels=("coal", "coal", "coal"))


@pytest.fixture(scope="module")
def rigid(rigid_scene):
    return tailbeam.simulate(rigid_scene, progress=False)


def first_rows(table) -> dict:
    """ball -> its first impacts.csv row (a dict)."""
    out = {}
    for k in range(len(table["ball"])):
        row = {c: table[c][k] for c in table}
        out.setdefault(row["ball"], row)
    return out


def check_free_fall_columns(table, scene, contact_xy=None):
    """x, y, approach_in, partner, ... of every ball's first impact against free fall."""
    assert tuple(table) == IMPACT_TABLE_COLUMNS
    assert tuple(table)[:12] == IMPACT_COLUMNS
    labels = dict(zip([b.name for b in scene.balls], scene.labels, strict=True))
    first = first_rows(table)
    assert set(first) == {b.name for b in scene.balls}
    t_first = min(row["t_start"] for row in first.values())
    for b in scene.balls:
        row = first[b.name]
        t_hit = row["t_start"]
        if t_hit == t_first or scene.plate_model == "rigid":  # the plate is still at rest
            h = GAPS[b.name]
            assert t_hit == pytest.approx(math.sqrt(2.0 * h / G), rel=1e-9)
            assert row["approach_in"] == pytest.approx(math.sqrt(2.0 * G * h), rel=1e-9)
        # free fall from rest until the first touch (of a plate that may vibrate by then)
        assert row["approach_in"] == pytest.approx(G * t_hit, rel=1e-9)
        assert row["x"] == pytest.approx(b.position[0] + b.velocity[0] * t_hit, abs=1e-12)
        assert row["y"] == b.position[1]
        assert (row["partner"], row["stream"], row["end"]) == ("plate", "", "separated")
        assert (row["material"], row["radius"]) == (b.material.name, b.radius)
        assert row["label"] == labels[b.name]
        # on a plate row the pair's speeds are the ball's normal speeds (the stream solver's
        # definition, tailbeam.results.records.Impact)
        assert (row["approach_in"], row["approach_out"]) == (row["v_in"], row["v_out"])
        if contact_xy is not None:  # where the solver applied the contact force
            assert (row["x"], row["y"]) == pytest.approx(contact_xy[b.name], abs=1e-15)


def check_particles(table, scene, leave=None):
    """particles.csv: one row per ball, its release state, mass 4/3 pi r^3 rho, leave."""
    leave = leave or {}
    assert tuple(table) == PARTICLE_COLUMNS
    assert list(table["name"]) == [b.name for b in scene.balls]
    for k, b in enumerate(scene.balls):
        mass = 4.0 / 3.0 * math.pi * b.radius**3 * b.material.density
        assert table["mass"][k] == pytest.approx(mass, rel=1e-12)
        assert (table["stream"][k], table["t_release"][k]) == ("", 0.0)
        assert (table["material"][k], table["label"][k]) == (b.material.name, scene.labels[k])
        state = [table[c][k] for c in ("x0", "y0", "z0", "vx0", "vy0", "vz0")]
        assert state == [*b.position, *b.velocity]
        if b.name in leave:
            assert table["t_leave"][k] == pytest.approx(leave[b.name][0], rel=1e-12)
            assert table["leave_edge"][k] == leave[b.name][1]
        else:
            assert math.isnan(table["t_leave"][k]) and table["leave_edge"][k] == ""


def test_rigid_plate_columns_against_free_fall(rigid, rigid_scene):
    assert isinstance(rigid, Result) and rigid.plate_model == "rigid"
    check_free_fall_columns(rigid.impacts_table(), rigid_scene)
    # "m" (x0 = 0.2 m, 1 m/s) passes the x+ edge (x = 0.3 m) at 0.1 s
    check_particles(rigid.particles_table(), rigid_scene, leave={"m": (0.1, "x+")})
    assert [e.ball for e in rigid.leaves] == ["m"]


def test_rigid_columns_mean_what_the_stream_solver_writes(rigid, rigid_scene):
    """The same balls through the stream solver (its own records): every column of
    impacts.csv and particles.csv agrees (rtol 1e-10 both; measured <= 1.3e-9 relative)."""
    scene = rigid_scene
    stream = simulate_stream(
        scene.particles, scene.incline, scene.duration, laws=scene.contact, rtol=1e-10,
        max_steps=10**6,
    )  # fmt: skip
    ours, theirs = rigid.impacts_table(), stream.impacts_table()
    assert len(ours["ball"]) == len(theirs["ball"]) == 3
    for c in IMPACT_TABLE_COLUMNS:
        if ours[c].dtype == object or c in ("index", "ends_at_rest"):
            assert list(ours[c]) == list(theirs[c]), c
        else:
            assert ours[c] == pytest.approx(
                theirs[c], rel=1e-8, abs=1e-12, nan_ok=c == "normal_impulse"
            ), c
    ours, theirs = rigid.particles_table(), stream.particles_table()
    for c in PARTICLE_COLUMNS:
        if ours[c].dtype == object:
            assert list(ours[c]) == list(theirs[c]), c
        else:
            assert ours[c] == pytest.approx(theirs[c], rel=1e-9, nan_ok=True), c
    for name in ("c", "s", "m"):  # the contact events of both, in the one format
        mine = [t for t, _k in rigid.events_of(name, "contact_start")]
        assert mine == pytest.approx([t for t, _k in stream.events_of(name, "contact_start")])


def test_simulate_writes_the_tables_bit_for_bit(rigid_scene, tmp_path, capsys):
    path = tmp_path / "scene.toml"
    path.write_text(dumps_scene(rigid_scene))
    assert main(["simulate", str(path), "--out", str(tmp_path / "o"), "-q"]) == 0
    result = tailbeam.simulate(rigid_scene, progress=False)
    for name, table in (
        ("impacts.csv", result.impacts_table()),
        ("particles.csv", result.particles_table()),
    ):
        with open(tmp_path / "o" / name, newline="") as fh:
            header, *rows = list(csv.reader(fh))
        assert header == list(table)
        for k, row in enumerate(rows):
            for c, cell in zip(header, row, strict=True):
                value = table[c][k]
                if isinstance(value, str):
                    assert cell == value
                elif isinstance(value, bool | np.bool_):
                    assert cell == ("true" if value else "false")
                else:
                    assert repr(float(cell)) == repr(float(value))


def test_events_and_sample_of_the_one_interface(rigid):
    starts = [t for t, _k in rigid.events_of("c", "contact_start")]
    assert starts == [imp.t_start for imp in rigid.impacts_of("c")]
    assert set(rigid.stats) == {"nfev", "n_steps"} and rigid.stats["nfev"] > rigid.stats["n_steps"]
    assert rigid.sensor_signals == {} and rigid.keeps_states
    with pytest.raises(InputError, match="name"):
        rigid.impacts_of("nobody")


def test_modal_plate_columns_against_free_fall():
    """Two balls on the modal plate (the coupled solver), one moving sideways: first impacts
    against free fall (the plate is at rest until then) and the solver's contact points."""
    scene = Scene(
        balls({"c": 0.03, "s": 0.02, "m": 0.02})[::2],  # "c" and "m" (sideways)
        duration=0.07,
        plate_model="modal",
        modal=ModalPlateSettings(fmax_hz=2000.0),
    )
    result = tailbeam.simulate(scene, progress=False)
    assert result.plate_model == "modal" and result.keeps_states
    names = [b.name for b in scene.balls]
    points = {names[b]: (x, y) for t, b, x, y, _r in reversed(result.plate.contact_points)}
    check_free_fall_columns(result.impacts_table(), scene, contact_xy=points)
    check_particles(result.particles_table(), scene)


def test_a_stream_result_keeps_no_states():
    stream = simulate_stream(
        Scene(balls()[:1], duration=0.01).particles, Scene(balls()[:1]).incline, 0.01,
        laws=Scene(balls()[:1]).contact, rtol=1e-10, max_steps=10**5,
    )  # fmt: skip
    assert not stream.keeps_states and stream.plate_model == "rigid"
    with pytest.raises(InputError, match="times"):
        stream.sample([0.0])


TWO_GAPS = {"c": 0.02, "m": 0.01}  # drop gaps (m) of the two balls of ``every_solver``


@pytest.fixture(scope="module")
def every_solver():
    """Rigid, rigid reference, two-way coupled, one-way, stream and stream reference on two
    balls: "c" dropped from rest, "m" moving sideways at 1 m/s from x = 0.25 m (it passes
    the x+ edge at 0.05 s). name -> result."""
    from tailbeam.physics.bodies import Plate
    from tailbeam.physics.contact_law import ball_plate_law
    from tailbeam.physics.materials import CARBON_STEEL
    from tailbeam.plate.closed_forms import ssss_kirchhoff_basis
    from tailbeam.solvers.coupled import simulate_coupled
    from tailbeam.solvers.coupled.oneway import simulate_one_way
    from tailbeam.solvers.rigid import simulate_rigid
    from tailbeam.solvers.rigid.reference import simulate_rigid_reference
    from tailbeam.solvers.stream.solver import simulate_reference

    two = (Ball("c", COAL, 0.03, (-0.1, 0.05, 0.05), (0.0, 0.0, 0.0)),
           Ball("m", COAL, 0.02, (0.25, 0.0, 0.03), (1.0, 0.0, 0.0)))  # fmt: skip
    scene, duration = Scene(two, duration=0.07), 0.07
    laws = [ball_plate_law(COAL, b.radius, CARBON_STEEL) for b in two]
    basis = ssss_kirchhoff_basis(Plate(), 2000.0)
    stream_args = (scene.particles, scene.incline, duration)
    stream_kw = dict(laws=scene.contact, rtol=1e-10, max_steps=10**6)
    return two, {
        "rigid": simulate_rigid(two, Plate(), laws, duration),
        "rigid reference": simulate_rigid_reference(two, Plate(), laws, duration),
        "coupled two-way": simulate_coupled(two, basis, laws, duration),
        "one-way": simulate_one_way(two, basis, laws, duration),
        "stream": simulate_stream(*stream_args, **stream_kw),
        "stream reference": simulate_reference(*stream_args, **stream_kw),
    }


def test_every_solver_records_the_one_event_record(every_solver):
    """Rigid, rigid reference, two-way coupled, one-way, stream and stream reference: their
    ``events`` are ``Event`` records (the same fields, kinds from ``EventKind``) in time
    order, with the partners the record documents. Independent truth: each ball's first
    contact starts at the free-fall time sqrt(2 h / g) of its gap h (on the flexible plate
    only the first ball's: the plate is at rest until then); "m" moves sideways at 1 m/s
    from x = 0.25 m and passes the x+ edge at 0.05 s.
    """
    from tailbeam.results.records import PLATE, Event, EventKind

    gaps = TWO_GAPS
    _, results = every_solver
    for solver, result in results.items():
        events = result.events
        assert events and all(type(e) is Event for e in events), solver
        assert all(e._fields == ("t", "ball", "kind", "partner") for e in events), solver
        assert all(type(e.kind) is EventKind and isinstance(e.t, float) for e in events), solver
        assert [e.t for e in events] == sorted(e.t for e in events), solver
        for e in events:
            edge = e.partner in ("x+", "x-", "y+", "y-")
            want = {EventKind.LEAVE: edge, EventKind.RELEASE: e.partner == ""}
            assert want.get(e.kind, e.partner == PLATE), (solver, e)
        for name, h in gaps.items():
            if solver == "coupled two-way" and name == "c":
                continue  # "m" struck the flexible plate first: it vibrates when "c" lands
            t_hit = math.sqrt(2.0 * h / G)
            first = [e.t for e in events if e.ball == name and e.kind == "contact_start"][0]
            assert first == pytest.approx(t_hit, rel=1e-9), (solver, name)
            assert result.events_of(name, "contact_start")[0] == (first, "contact_start")
    leaves = [e for e in results["stream"].events if e.kind == EventKind.LEAVE]
    assert [(e.ball, e.partner) for e in leaves] == [("m", "x+")]
    assert leaves[0].t == pytest.approx(0.05, rel=1e-9)


SINGLE_BALL = ("rigid", "rigid reference", "coupled two-way", "one-way")


def test_every_solver_records_the_one_impact_record(every_solver):
    """Every solver's ``impacts`` are ``tailbeam.results.records.Impact`` records (one class),
    numbered 1, 2, ... per ball in time order. Independent
    truth: the lateral motion is uniform until a ball touches anything, so a single-ball
    solver's x, y (the ball centre's at t_start) are x0 + vx t_start, y0 + vy t_start for
    every contact, and so is every solver's first contact point of each ball (the contact
    point is under the centre on the horizontal plate)."""
    from tailbeam.results.records import PLATE, Impact

    two, results = every_solver
    for solver, result in results.items():
        assert type(result) is Result, solver
        assert result.impacts and all(type(i) is Impact for i in result.impacts), solver
        for b in two:
            mine = sorted(result.impacts_of(b.name), key=lambda i: i.t_start)
            assert [i.index for i in mine] == list(range(1, len(mine) + 1)), (solver, b.name)
            for imp in mine if solver in SINGLE_BALL else mine[:1]:
                assert imp.partner == PLATE, (solver, imp)
                t = imp.t_start
                assert imp.x == pytest.approx(b.position[0] + b.velocity[0] * t, abs=1e-12)
                assert imp.y == pytest.approx(b.position[1] + b.velocity[1] * t, abs=1e-12)


def test_the_fe_reference_records_the_one_impact_record():
    """The full-FE reference (tailbeam.solvers.coupled.fe_reference) writes ``Impact`` too.
    Independent truth: until the touch the plate is at rest and the ball falls freely, so
    the touch is at the root of r + gap - (v t + g t^2 / 2) = r (Newmark is exact for
    constant acceleration; the located start within 1e-9 relative), at the ball's x, y."""
    from tailbeam.physics.bodies import Plate
    from tailbeam.physics.contact_law import ball_plate_law
    from tailbeam.physics.materials import CARBON_STEEL
    from tailbeam.plate import assemble_plate
    from tailbeam.results.records import PLATE, Impact
    from tailbeam.solvers.coupled.fe_reference import fe_reference

    gap, speed = 1e-4, 2.0
    ball = Ball("s", SANDSTONE, 0.03, (0.07, -0.05, 0.03 + gap), (0.0, 0.0, -speed))
    law = ball_plate_law(SANDSTONE, 0.03, CARBON_STEEL, damping=800.0)
    model = assemble_plate(Plate(), "SSSS", theory="kirchhoff", divisions=4)
    ref = fe_reference(model, ball, law, 4e-4, dt=1e-6)
    (imp,) = ref.impacts
    assert type(imp) is Impact
    assert (imp.ball, imp.partner, imp.index, imp.end) == ("s", PLATE, 1, "separated")
    t_touch = (-speed + math.sqrt(speed**2 + 2.0 * G * gap)) / G
    assert imp.t_start == pytest.approx(t_touch, rel=1e-9)
    # v_in is interpolated over the step in which the force starts: measured 3.6e-9 off
    assert imp.v_in == pytest.approx(speed + G * t_touch, rel=1e-7)
    assert (imp.x, imp.y) == (0.07, -0.05)
    assert imp.t_start < imp.t_peak < imp.t_end
    assert imp.restitution == imp.v_out / imp.v_in and imp.duration == imp.t_end - imp.t_start


def test_ball_ball_events_name_the_partner():
    """Two balls flying head-on (1 m/s each, surfaces 0.02 m apart, 0.2 m above the plate):
    both stream solvers record the contact's start, kinks and end as ``Event`` records of
    one ball with the other as partner; the start at the closed-form time 0.02 m / 2 m/s = 0.01 s
    (gravity moves both alike)."""
    from tailbeam.results.records import Event, EventKind
    from tailbeam.solvers.stream.solver import simulate_reference

    pair = (Ball("a", COAL, 0.02, (-0.03, 0.0, 0.2), (1.0, 0.0, 0.0)),
            Ball("b", COAL, 0.02, (0.03, 0.0, 0.2), (-1.0, 0.0, 0.0)))  # fmt: skip
    scene = Scene(pair, duration=0.02)
    args = (scene.particles, scene.incline, scene.duration)
    kw = dict(laws=scene.contact, rtol=1e-10, max_steps=10**6)
    for solver in (simulate_stream, simulate_reference):
        events = [e for e in solver(*args, **kw).events if e.kind != EventKind.RELEASE]
        assert all(type(e) is Event for e in events)
        kinds = [e.kind for e in events]  # the law's kinks (full damping, clamp) in between
        assert kinds[0] == "contact_start" and kinds[-1] == "contact_end", kinds
        assert "contact_start" not in kinds[1:] and "contact_end" not in kinds[:-1], kinds
        assert all({e.ball, e.partner} == {"a", "b"} for e in events)
        assert events[0].t == pytest.approx(0.01, rel=1e-9)
