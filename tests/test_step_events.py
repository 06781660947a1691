"""Events inside a step (tailbeam.solvers.numerics.step_events) against closed-form roots."""

import math

import numpy as np

from tailbeam.solvers.numerics.step_events import (
    STEP_POINTS,
    certified_positive,
    chebyshev_coefficients,
    first_downward_crossing,
    interpolant_max,
)


def _rows(funcs):
    return np.array([f(STEP_POINTS) for f in funcs])


def test_a_dip_between_the_step_ends_is_found():
    """Two balls passing through each other within one step: the squared distance minus
    the contact distance, (s - 0.5)^2 - 1e-4, is positive at both ends; its first root is
    0.5 - 0.01. A far pair (s + 1)^2 is certified positive; a degree-14 polynomial too."""
    dip = lambda s: (s - 0.5) ** 2 - 1e-4  # noqa: E731
    far = lambda s: (s + 1.0) ** 2  # noqa: E731
    wiggle = lambda s: 2.0 + np.cos(14 * np.arccos(2 * s - 1))  # T_14, in [1, 3]  # noqa: E731
    values = _rows([dip, far, wiggle])
    coef = chebyshev_coefficients(values)
    assert certified_positive(coef).tolist() == [False, True, True]
    s = first_downward_crossing(coef[0], values[0], is_fresh=False)
    assert math.isclose(s, 0.49, rel_tol=0.0, abs_tol=1e-14)


def test_fresh_rows_skip_their_own_root_and_up_crossings_do_not_count():
    up = lambda s: s - 0.3  # noqa: E731  # crosses upwards: not an event of a "g < 0" row
    at_start = lambda s: -s * (s - 0.7)  # noqa: E731  # sits on 0 at s = 0, falls at 0.7
    values = _rows([up, at_start])
    coef = chebyshev_coefficients(values)
    assert first_downward_crossing(coef[0], values[0], is_fresh=False) == 0.0  # wrong at start
    s = first_downward_crossing(coef[1], values[1], is_fresh=True)
    assert math.isclose(s, 0.7, abs_tol=1e-14)


def test_interpolant_max_of_a_smooth_peak():
    peak = lambda s: 1.0 - (s - 0.4321) ** 2  # noqa: E731
    s, value = interpolant_max(peak(STEP_POINTS))
    assert math.isclose(s, 0.4321, abs_tol=1e-12) and math.isclose(value, 1.0, rel_tol=1e-14)
