"""Bad inputs raise InputError naming the field; work limits raise a readable WorkLimitError."""

import math

import numpy as np
import pytest

from tailbeam import CARBON_STEEL, COAL, Ball, InputError, Plate, WorkLimitError, ball_plate_law
from tailbeam.results.records import Impact
from tailbeam.results.result import Result
from tailbeam.solvers.rigid import simulate_rigid
from tailbeam.solvers.rigid.reference import simulate_rigid_reference

LAW = ball_plate_law(COAL, 0.03, CARBON_STEEL, damping=800.0, penetration=1e-4)
BALL = Ball("A", COAL, 0.03, (0.0, 0.0, 0.13), (0.0, 0.0, -1.0))


@pytest.mark.parametrize("solver", [simulate_rigid, simulate_rigid_reference])
@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"duration": 0.0}, "duration"),
        ({"duration": -1.0}, "duration"),
        ({"duration": math.nan}, "duration"),
        ({"rtol": 0.5}, "rtol"),
        ({"rtol": math.nan}, "rtol"),
        ({"gravity": -9.8}, "gravity"),
        ({"rest_speed": -1.0}, "rest_speed"),
        ({"max_contacts": 0}, "max_contacts"),
        ({"max_steps": 1.5}, "max_steps"),
        ({"balls": []}, "balls"),
        ({"balls": [BALL, BALL]}, "balls[1].name"),
        ({"laws": []}, "laws"),
        ({"laws": ["steel"]}, "laws[0]"),
        ({"plate": "steel"}, "plate"),
    ],
)
def test_bad_input_names_the_field(solver, kwargs, field):
    args = {"balls": [BALL], "plate": Plate(), "laws": [LAW], "duration": 0.1}
    args.update(kwargs)
    if "balls" in kwargs and "laws" not in kwargs:
        args["laws"] = [LAW] * len(args["balls"])
    positional = [args.pop(k) for k in ("balls", "plate", "laws", "duration")]
    with pytest.raises(InputError) as err:
        solver(*positional, **args)
    assert err.value.field == field


def test_ball_starting_inside_the_plate():
    inside = Ball("A", COAL, 0.03, (0.0, 0.0, 0.029), (0.0, 0.0, 0.0))
    with pytest.raises(InputError) as err:
        simulate_rigid([inside], Plate(), [LAW], 0.1)
    assert err.value.field == "balls[A].position"


def test_nan_in_ball_state_is_rejected_when_built():
    with pytest.raises(InputError, match=r"velocity\[2\]"):
        Ball("A", COAL, 0.03, (0.0, 0.0, 0.1), (0.0, 0.0, math.nan))


def test_sample_times_outside_the_run():
    res = simulate_rigid([BALL], Plate(), [LAW], 0.1)
    with pytest.raises(InputError) as err:
        res.sample([0.2])
    assert err.value.field == "times"
    with pytest.raises(InputError):
        res.time_grid(0.0)
    with pytest.raises(InputError):
        res.impacts_of("nobody")


def test_max_contacts_limit_message():
    with pytest.raises(WorkLimitError, match="max_contacts=3.*raise max_contacts"):
        simulate_rigid([BALL], Plate(), [LAW], 2.0, max_contacts=3)


def test_max_steps_limit_message():
    with pytest.raises(WorkLimitError, match="max_steps.*raise max_steps"):
        simulate_rigid([BALL], Plate(), [LAW], 1.0, max_steps=20)
    with pytest.raises(WorkLimitError, match="max_steps"):
        simulate_rigid_reference([BALL], Plate(), [LAW], 1.0, max_steps=20)


def test_result_types_and_table():
    res = simulate_rigid([BALL], Plate(), [LAW], 0.5)
    assert isinstance(res, Result) and res.status == 0 and res.message
    assert res.stats["nfev"] > res.stats["n_steps"] > 0
    assert all(isinstance(i, Impact) for i in res.impacts)
    row = res.impacts[0].as_dict()
    assert row["ball"] == "A" and row["index"] == 1 and isinstance(row["peak_force"], float)
    kinds = {e.kind for e in res.events}
    assert kinds <= {"contact_start", "full_damping", "clamp_on", "clamp_off", "contact_end"}
    grid = res.time_grid(1000.0)
    assert grid[0] == 0.0 and grid[-1] == 0.5 and np.all(np.diff(grid) > 0)
