"""Claims of section 4.1 (effect of velocity: coal A at 1 m/s, coal B at 2 m/s) and conclusion 1.

See tailbeam.paper.claims for the conventions (collision numbers, rebound height and speed)."""

import math

from tailbeam.paper.claims_base import (
    SAME_RESTITUTION_TOL,
    SHORT_CONTACT_RATIO,
    Claim,
    all_greater,
    apex_heights,
    apex_times,
    collision_intervals,
    first_few,
    impacts,
    peak_forces,
    rebound_speeds,
    restitutions,
    strictly_decreasing,
)
from tailbeam.physics.bodies import STANDARD_GRAVITY

# -- 4.1 effect of velocity (balls "A" 1 m/s and "B" 2 m/s) --------------------------------------


def claim_41_apex_decreasing(r) -> Claim:
    """Rebound height falls collision by collision for A and for B, so the highest rebound is the
    one after the first collision. Checked: the sequence of rebound heights is strictly
    decreasing for each ball (needs at least two rebounds)."""
    a, b = apex_heights(r, "A"), apex_heights(r, "B")
    ok = len(a) >= 2 and len(b) >= 2 and strictly_decreasing(a) and strictly_decreasing(b)
    return Claim(
        "4.1-apex-decreasing",
        "4.1",
        "rebound distance decreases with collision number; maximal after the first collision",
        "rebound height after collision n (m)",
        {"A": first_few(a), "B": first_few(b), "n_A": len(a), "n_B": len(b)},
        "strictly decreasing for every n inside the simulated time",
        ok,
    )


def claim_41_max_apex_b(r) -> Claim:
    """B's highest rebound is higher than A's and is reached later (apex time after the first
    collision, measured from t = 0)."""
    ha, hb = apex_heights(r, "A"), apex_heights(r, "B")
    ta, tb = apex_times(r, "A"), apex_times(r, "B")
    ok = bool(ha and hb) and max(hb) > max(ha) and tb[hb.index(max(hb))] > ta[ha.index(max(ha))]
    return Claim(
        "4.1-max-apex-B",
        "4.1",
        "B's peak rebound distance is larger than A's and is reached later",
        "max rebound height (m) and its time (s)",
        {
            "H_A": max(ha, default=math.nan),
            "H_B": max(hb, default=math.nan),
            "t_A": ta[ha.index(max(ha))] if ha else math.nan,
            "t_B": tb[hb.index(max(hb))] if hb else math.nan,
        },
        "H_B > H_A and t_B > t_A",
        ok,
    )


def claim_41_a_collides_more(r) -> Claim:
    """'The collision frequency of A is faster': A makes more collisions than B within the
    simulated time, and A's time between consecutive collisions is shorter than B's at every
    common n (A's velocity also 'varies faster': it reverses more often)."""
    na, nb = len(impacts(r, "A")), len(impacts(r, "B"))
    ia, ib = collision_intervals(r, "A"), collision_intervals(r, "B")
    ok = na > nb and all_greater(ib, ia)
    return Claim(
        "4.1-A-collides-more",
        "4.1",
        "within the simulated time A collides more often (its velocity varies faster)",
        "number of collisions; interval between collisions n and n+1 (s)",
        {"n_A": na, "n_B": nb, "dt_A": first_few(ia), "dt_B": first_few(ib)},
        "n_A > n_B and dt_A(n) < dt_B(n) for every common n",
        ok,
    )


def claim_41_short_contact(r) -> Claim:
    """'The velocity mutates in a very short time': each contact (that is followed by a flight)
    lasts less than SHORT_CONTACT_RATIO times the flight after it, for both balls."""
    ratios = []
    for name in ("A", "B"):
        for i in impacts(r, name):
            if math.isfinite(i.next_apex_height) and i.v_out > 0:
                flight = 2.0 * i.v_out / STANDARD_GRAVITY
                ratios.append((i.t_end - i.t_start) / flight)
    worst = max(ratios, default=math.nan)
    return Claim(
        "4.1-short-contact",
        "4.1",
        "the velocity reverses within a very short time (the contact)",
        "contact duration / following flight time",
        {"max_ratio": worst, "contacts": len(ratios)},
        f"every ratio < {SHORT_CONTACT_RATIO}",
        bool(ratios) and worst < SHORT_CONTACT_RATIO,
    )


def claim_41_same_restitution(r) -> Claim:
    """'The recovery coefficients of the two balls after the first collision are basically the
    same': |e_A(1) - e_B(1)| <= SAME_RESTITUTION_TOL (scatter of measured restitution)."""
    ea, eb = restitutions(r, "A"), restitutions(r, "B")
    diff = abs(ea[0] - eb[0]) if ea and eb else math.nan
    return Claim(
        "4.1-same-restitution",
        "4.1",
        "restitution of A and B at the first collision basically the same",
        "restitution e = v_out / v_in at collision 1",
        {"e_A": ea[0] if ea else math.nan, "e_B": eb[0] if eb else math.nan, "diff": diff},
        f"|e_A - e_B| <= {SAME_RESTITUTION_TOL}",
        diff <= SAME_RESTITUTION_TOL,
    )


def claim_41_force_decreasing(r) -> Claim:
    """The collision force is largest at the first collision and decreases in turn: the peak
    forces of each ball are strictly decreasing with n."""
    fa, fb = peak_forces(r, "A"), peak_forces(r, "B")
    ok = len(fa) >= 2 and len(fb) >= 2 and strictly_decreasing(fa) and strictly_decreasing(fb)
    return Claim(
        "4.1-force-decreasing",
        "4.1",
        "collision force is maximal at the first collision and then decreases in turn",
        "peak force of collision n (N)",
        {"A": first_few(fa), "B": first_few(fb)},
        "strictly decreasing for every n inside the simulated time",
        ok,
    )


def claim_41_b_higher_faster_stronger(r) -> Claim:
    """After the same number of collisions B rebounds higher and faster, and each collision of B
    has the larger peak force: at every common n."""
    h = all_greater(apex_heights(r, "B"), apex_heights(r, "A"))
    v = all_greater(rebound_speeds(r, "B"), rebound_speeds(r, "A"))
    f = all_greater(peak_forces(r, "B"), peak_forces(r, "A"))
    return Claim(
        "4.1-B-higher-faster-stronger",
        "4.1",
        "after the same number of collisions B rebounds higher and faster, with larger force",
        "rebound height, rebound speed, peak force at collision n",
        {
            "v_out_A": first_few(rebound_speeds(r, "A")),
            "v_out_B": first_few(rebound_speeds(r, "B")),
            "F_A": first_few(peak_forces(r, "A")),
            "F_B": first_few(peak_forces(r, "B")),
        },
        "B > A at every common n for height, speed and force",
        h and v and f,
    )


def claim_c1_maxima_increase(r) -> Claim:
    """Conclusion (1): the maximum rebound height and the maximum collision force increase with
    the initial velocity (B, 2 m/s, versus A, 1 m/s)."""
    ha, hb = apex_heights(r, "A"), apex_heights(r, "B")
    fa, fb = peak_forces(r, "A"), peak_forces(r, "B")
    vals = {
        "H_A": max(ha, default=math.nan),
        "H_B": max(hb, default=math.nan),
        "F_A": max(fa, default=math.nan),
        "F_B": max(fb, default=math.nan),
    }
    return Claim(
        "C1-maxima-increase",
        "conclusion 1",
        "maximum rebound distance and maximum collision force increase with initial velocity",
        "max rebound height (m), max peak force (N)",
        vals,
        "H_B > H_A and F_B > F_A",
        vals["H_B"] > vals["H_A"] and vals["F_B"] > vals["F_A"],
    )
