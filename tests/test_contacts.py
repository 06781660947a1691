"""The contact table (tailbeam.physics.contacts) against the laws it replaces and eq. 5 by hand;
the solvers give identical results whether they get the table or today's ``laws``."""

import math

import pytest

import tailbeam
from tailbeam import COAL, SANDSTONE, Ball, InputError, Plate
from tailbeam.physics.contact_law import ImpactLaw, ball_plate_law
from tailbeam.physics.contacts import PLATE, ContactTable, LawOptions, contact_table
from tailbeam.physics.materials import CARBON_STEEL
from tailbeam.plate.closed_forms import ssss_kirchhoff_basis
from tailbeam.scene import ContactSettings, Scene
from tailbeam.solvers.coupled import simulate_coupled
from tailbeam.solvers.rigid import simulate_rigid
from tailbeam.solvers.stream.solver import simulate_reference, simulate_stream

SETTINGS = ContactSettings(exponent=1.5, damping=2000.0, penetration=2e-5, clamp=True)
FIELDS = ("stiffness", "exponent", "damping", "penetration", "clamp")


def _balls():
    return (
        Ball("c", COAL, 0.02, (-0.1, 0.0, 0.05), (0.0, 0.0, -1.0)),
        Ball("s", SANDSTONE, 0.035, (0.1, 0.0, 0.06), (0.0, 0.0, -2.0)),
        Ball("k", COAL, 0.03, (0.0, 0.15, 0.04), (0.0, 0.0, -0.5)),
    )


def test_plate_rows_are_the_scene_laws_field_by_field():
    scene = Scene(_balls(), contact=SETTINGS)
    table = scene.contacts()
    for i, ball in enumerate(scene.balls):
        today = SETTINGS.law_for(ball, scene.plate.material)  # the path Scene.laws() took
        for row in (table.law(i, PLATE), table.law(ball.name, PLATE), scene.laws()[i]):
            assert [getattr(row, f) for f in FIELDS] == [getattr(today, f) for f in FIELDS]
    # and the closed form of eqs. 4-6 for the coal ball of R = 0.02 m on carbon steel
    inv = (1 - 0.32**2) / 5.3e9 + (1 - 0.28**2) / 2.06e11
    assert table.law("c", PLATE).stiffness == pytest.approx(4 / 3 / inv * math.sqrt(0.02), 1e-14)


def test_ball_ball_row_is_eq_5_by_hand():
    table = ContactTable.from_settings(_balls(), CARBON_STEEL, SETTINGS)
    r_star = 0.02 * 0.035 / (0.02 + 0.035)  # eq. 5
    e_star = 1.0 / ((1 - 0.32**2) / 5.3e9 + (1 - 0.123**2) / 1.35e10)  # coal, sandstone
    law = table.law("c", "s")
    assert law.stiffness == pytest.approx(4.0 / 3.0 * e_star * math.sqrt(r_star), rel=1e-14)
    assert (law.exponent, law.damping, law.penetration, law.clamp) == (1.5, 2000.0, 2e-5, True)
    # two coal balls of R = 0.02 and 0.03 m: R* = 0.012 m, E* = E / (2 (1 - nu^2))
    k_cc = 4.0 / 3.0 * 5.3e9 / (2 * (1 - 0.32**2)) * math.sqrt(0.012)
    assert table.law(0, 2).stiffness == pytest.approx(k_cc, rel=1e-14)


def test_laws_are_symmetric_and_one_object_per_pair():
    table = ContactTable.from_settings(_balls(), CARBON_STEEL, SETTINGS)
    assert table.law("c", "s") is table.law("s", "c") is table.law(1, 0) is table.law(0, "s")
    assert table.law(PLATE, "k") is table.law("k", PLATE) is table.law(2, PLATE)
    assert table.law("c", "s") is not table.law("c", "k")


def test_rows_are_never_materialised_for_all_pairs():
    balls = [Ball(f"b{i}", COAL, 0.02, (0.0, 0.0, 0.05)) for i in range(2000)]
    table = ContactTable.from_settings(balls, CARBON_STEEL, SETTINGS)
    assert len(table) == 2000 and len(list(table.rows())) == 2000
    table.law(5, 17)
    table.law("b17", "b5")  # the same pair again
    table.law(1999, 0)
    rows = list(table.rows())
    assert len(table) == len(rows) == 2002
    assert [r[:2] for r in rows[2000:]] == [("b5", "b17"), ("b0", "b1999")]
    assert rows[3] == ("b3", PLATE, table.law(3, PLATE))


def test_bad_lookups_and_tables_name_the_field():
    table = ContactTable.from_laws(_balls()[:2], [ball_plate_law(COAL, 0.02, CARBON_STEEL)] * 2)
    with pytest.raises(InputError) as err:
        table.law(0, 1)  # a list of ball-plate laws has no ball-ball law
    assert err.value.field == "laws"
    with pytest.raises(InputError) as err:
        table.law("nobody", PLATE)
    assert err.value.field == "contacts"
    with pytest.raises(InputError) as err:
        contact_table(_balls(), table)  # built for two of the three balls
    assert err.value.field == "laws"
    with pytest.raises(InputError) as err:
        ContactTable.from_laws(_balls()[:1], ["steel"])
    assert err.value.field == "laws[0]"


def _same(a, b):
    """Every record of two results, bit for bit (repr round-trips floats exactly)."""
    assert repr(a.impacts) == repr(b.impacts)
    assert repr(a.events) == repr(b.events)


def test_rigid_and_coupled_same_with_the_laws_list_or_the_table():
    scene = Scene(_balls(), contact=SETTINGS, duration=0.05)
    laws, table = scene.laws(), scene.contacts()
    assert isinstance(laws, tuple) and all(isinstance(w, ImpactLaw) for w in laws)
    _same(
        simulate_rigid(scene.balls, scene.plate, list(laws), 0.05),
        simulate_rigid(scene.balls, scene.plate, table, 0.05),
    )
    basis = ssss_kirchhoff_basis(Plate(), 2000.0)
    for coupling in ("two-way", "one-way"):
        old = simulate_coupled(scene.balls, basis, list(laws), 0.02, coupling=coupling)
        new = simulate_coupled(scene.balls, basis, table, 0.02, coupling=coupling)
        _same(old, new)


def _stream_scene():
    """Two balls meeting head-on in flight over a 15 deg plate (one ball-ball contact), and a
    third falling alone."""
    balls = (
        Ball("p1", COAL, 0.025, (0.15, -0.15, 0.1), (0.0, 0.5, 0.0)),
        Ball("p2", SANDSTONE, 0.015, (0.15, -0.05, 0.1), (0.0, -0.5, 0.0)),
        Ball("f1", SANDSTONE, 0.035, (-0.2, -0.2, 0.1), (0.2, 0.1, -1.0)),
    )
    return Scene(balls, contact=SETTINGS, duration=0.08, inclination=15.0)


def test_stream_solvers_same_with_the_settings_or_the_table():
    scene = _stream_scene()
    table = ContactTable.from_settings(scene.particles, scene.plate.material, SETTINGS)
    kw = dict(rtol=1e-10, max_steps=10**6, progress=False)
    old = simulate_stream(scene.particles, scene.incline, scene.duration, laws=SETTINGS, **kw)
    new = simulate_stream(scene.particles, scene.incline, scene.duration, laws=table, **kw)
    assert repr(old.impacts) == repr(new.impacts) and repr(old.events) == repr(new.events)
    met = {frozenset((c.ball, c.partner)) for c in new.impacts if c.partner != PLATE}
    assert met == {frozenset(("p1", "p2"))}
    # the solver asked the table for the pair it watched, not for all three (f1 stays far)
    pairs = {frozenset(r[:2]) for r in table.rows() if r.other != PLATE}
    assert pairs == met and len(table) == 3 + 1

    kw = dict(rtol=1e-10, max_steps=10**5)
    two = scene.particles[:2]
    old = simulate_reference(two, scene.incline, 0.07, laws=SETTINGS, **kw)
    new = simulate_reference(
        two, scene.incline, 0.07, laws=contact_table(two, table.options, CARBON_STEEL), **kw
    )
    assert repr(old.impacts) == repr(new.impacts) and len(new.impacts) == 2


def test_simulate_passes_the_scene_table(monkeypatch):
    """tailbeam.simulate hands the rigid solver the scene's table (not a list of laws)."""
    import tailbeam.solvers.single_ball as rigid

    seen = []
    original = rigid.simulate_rigid
    monkeypatch.setattr(
        rigid, "simulate_rigid", lambda *a, **k: seen.append(a[2]) or original(*a, **k)
    )
    scene = Scene(_balls(), contact=SETTINGS, duration=0.01)
    tailbeam.simulate(scene, progress=False)
    assert seen == [scene.contacts()]
    assert LawOptions.of(SETTINGS) == scene.contacts().options


def test_a_ball_may_not_be_named_plate():
    # "plate" is the plate's name as a partner (impacts.csv) and as a body of the table
    balls = (Ball("a", COAL, 0.02, (0.0, 0.0, 0.05)), Ball(PLATE, COAL, 0.02, (0.1, 0.0, 0.05)))
    with pytest.raises(InputError, match=r"^balls\[2\]\.name: 'plate' names the plate"):
        Scene(balls)
