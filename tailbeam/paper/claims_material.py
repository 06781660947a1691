"""Claims of sections 4.2 (coal vs sandstone at 1 m/s) and 4.3 (equal kinetic energy), and
conclusion 3. See tailbeam.paper.claims for the conventions."""

import math

from tailbeam.paper.claims_base import (
    MUCH_LARGER_FACTOR,
    Claim,
    all_greater,
    apex_heights,
    apex_times,
    collision_intervals,
    common,
    first_few,
    impacts,
    peak_forces,
    rebound_speeds,
    restitutions,
)

# -- 4.2 effect of material (balls "coal" and "sandstone", both 1 m/s) ---------------------------


def claim_42_coal_lower(r) -> Claim:
    """After the same collision coal rebounds lower than sandstone: at every common n."""
    hc, hs = apex_heights(r, "coal"), apex_heights(r, "sandstone")
    return Claim(
        "4.2-coal-lower",
        "4.2",
        "after the same collision coal's rebound distance is less than sandstone's",
        "rebound height after collision n (m)",
        {"coal": first_few(hc), "sandstone": first_few(hs)},
        "coal < sandstone at every common n",
        all_greater(hs, hc),
    )


def claim_42_coal_peak_sooner(r) -> Claim:
    """Coal reaches the peak of its rebound height (its highest apex) sooner than sandstone."""
    hc, hs = apex_heights(r, "coal"), apex_heights(r, "sandstone")
    tc, ts = apex_times(r, "coal"), apex_times(r, "sandstone")
    t_c = tc[hc.index(max(hc))] if hc else math.nan
    t_s = ts[hs.index(max(hs))] if hs else math.nan
    return Claim(
        "4.2-coal-peak-sooner",
        "4.2",
        "coal reaches the peak of its rebound height in a shorter time",
        "time of the highest apex (s)",
        {"t_coal": t_c, "t_sandstone": t_s},
        "t_coal < t_sandstone",
        t_c < t_s,
    )


def claim_42_coal_collides_more(r) -> Claim:
    """Within the simulated time coal collides more often and its collision frequency is higher
    (conclusion 2: 'the collision time interval is smaller'): more collisions, and a shorter
    interval between collisions n and n+1 at every common n."""
    nc, ns = len(impacts(r, "coal")), len(impacts(r, "sandstone"))
    ic, is_ = collision_intervals(r, "coal"), collision_intervals(r, "sandstone")
    return Claim(
        "4.2-coal-collides-more",
        "4.2",
        "within a certain time coal collides more often; its collision interval is smaller",
        "number of collisions; interval between collisions n and n+1 (s)",
        {
            "n_coal": nc,
            "n_sandstone": ns,
            "dt_coal": first_few(ic),
            "dt_sand": first_few(is_),
        },
        "n_coal > n_sandstone and dt_coal(n) < dt_sandstone(n) for every common n",
        nc > ns and all_greater(is_, ic),
    )


def claim_42_sand_faster(r) -> Claim:
    """At the same initial speed sandstone rebounds faster: its restitution at the first
    collision is larger, and its rebound speed is larger at every common n."""
    ec, es = restitutions(r, "coal"), restitutions(r, "sandstone")
    vc, vs = rebound_speeds(r, "coal"), rebound_speeds(r, "sandstone")
    ok = bool(ec and es) and es[0] > ec[0] and all_greater(vs, vc)
    return Claim(
        "4.2-sand-rebounds-faster",
        "4.2",
        "sandstone's rebound speed and restitution are larger than coal's",
        "restitution at collision 1; rebound speed after collision n (m/s)",
        {
            "e_coal": ec[0] if ec else math.nan,
            "e_sand": es[0] if es else math.nan,
            "v_coal": first_few(vc),
            "v_sand": first_few(vs),
        },
        "e_sand(1) > e_coal(1) and v_sand(n) > v_coal(n) at every common n",
        ok,
    )


def claim_42_sand_decays_gently(r) -> Claim:
    """'The velocity of sandstone decreases more slowly' (conclusion 2: 'the change trend of
    rebound velocity is relatively gentle'). Read as the fractional loss of speed per
    collision: sandstone's restitution v_out(n) / v_in(n) is larger than coal's at every common
    collision n (its rebound speed falls by a smaller fraction collision by collision)."""
    ec, es = restitutions(r, "coal"), restitutions(r, "sandstone")
    return Claim(
        "4.2-sand-decays-gently",
        "4.2",
        "sandstone's rebound speed decreases more slowly, collision by collision",
        "restitution v_out/v_in at collision n",
        {"coal": first_few(ec), "sandstone": first_few(es)},
        "e_sand(n) > e_coal(n) at every common n",
        all_greater(es, ec),
    )


def claim_42_sand_force_much_larger(r) -> Claim:
    """Sandstone's collision force is much larger than coal's at every collision: 'much' read as
    at least MUCH_LARGER_FACTOR times the peak force of coal's collision of the same number."""
    fc, fs = common(peak_forces(r, "coal"), peak_forces(r, "sandstone"))
    ratios = [s / c for c, s in zip(fc, fs, strict=True)]
    return Claim(
        "4.2-sand-force-much-larger",
        "4.2",
        "sandstone's collision force is much larger than coal's at each collision",
        "peak force ratio sandstone / coal at collision n",
        {"ratio": first_few(ratios), "min_ratio": min(ratios, default=math.nan)},
        f"ratio >= {MUCH_LARGER_FACTOR} at every common n",
        bool(ratios) and min(ratios) >= MUCH_LARGER_FACTOR,
    )


# -- 4.3 equal initial kinetic energy (coal 1.3425 m/s, sandstone 1 m/s) -------------------------


def claim_43_crossover(r) -> Claim:
    """After collisions 1 and 2 coal rebounds higher and faster than sandstone; from collision 3
    on (every common n >= 3 inside the simulated time) lower and slower."""
    hc, hs = common(apex_heights(r, "coal"), apex_heights(r, "sandstone"))
    vc, vs = common(rebound_speeds(r, "coal"), rebound_speeds(r, "sandstone"))
    ok = len(hc) >= 3
    for n in range(len(hc)):
        coal_above = n < 2
        ok = ok and (hc[n] > hs[n]) == coal_above and (vc[n] > vs[n]) == coal_above
    return Claim(
        "4.3-crossover",
        "4.3",
        "coal rebounds higher/faster after collisions 1-2, lower/slower from the 3rd on",
        "rebound height (m) and speed (m/s) after collision n",
        {
            "H_coal": first_few(hc),
            "H_sand": first_few(hs),
            "v_coal": first_few(vc),
            "v_sand": first_few(vs),
        },
        "coal > sandstone for n = 1, 2 and coal < sandstone for every common n >= 3",
        ok,
    )


def claim_43_coal_varies_more(r) -> Claim:
    """'The variation range of rebound distance and rebound velocity of coal is larger': the
    range (max - min) of the rebound heights and of the rebound speeds over the common
    collisions n = 1..N (N = collisions both balls make in the simulated time) is larger for
    coal, for both quantities."""
    hc, hs = common(apex_heights(r, "coal"), apex_heights(r, "sandstone"))
    vc, vs = common(rebound_speeds(r, "coal"), rebound_speeds(r, "sandstone"))

    def spread(x):
        return max(x) - min(x) if x else math.nan

    vals = {
        "dH_coal": spread(hc),
        "dH_sand": spread(hs),
        "dv_coal": spread(vc),
        "dv_sand": spread(vs),
        "N": len(hc),
    }
    return Claim(
        "4.3-coal-varies-more",
        "4.3",
        "coal's rebound distance and rebound speed vary over a larger range",
        "max - min of rebound height (m) and speed (m/s) over common collisions",
        vals,
        "range_coal > range_sandstone for height and for speed (N >= 2)",
        len(hc) >= 2 and vals["dH_coal"] > vals["dH_sand"] and vals["dv_coal"] > vals["dv_sand"],
    )


def claim_43_coal_rests_first(r) -> Claim:
    """After repeated collisions coal reaches static equilibrium first: coal is declared at rest
    (the solver's definition, ``Result.states.rest_time``) inside the simulated time, and before
    sandstone (which may still be bouncing at the end)."""
    tc = r.states.rest_time.get("coal", math.nan)
    ts = r.states.rest_time.get("sandstone", math.nan)
    ok = math.isfinite(tc) and (not math.isfinite(ts) or tc < ts)
    return Claim(
        "4.3-coal-rests-first",
        "4.3",
        "coal achieves static equilibrium first",
        "time declared at rest (s; nan = still moving at the end)",
        {"coal": tc, "sandstone": ts},
        "coal at rest inside the simulated time and before sandstone",
        ok,
    )


def claim_43_coal_force_smaller(r) -> Claim:
    """Coal's contact force is smaller than sandstone's at each collision (every common n), even
    at collisions 1-2 where coal rebounds higher."""
    fc, fs = peak_forces(r, "coal"), peak_forces(r, "sandstone")
    return Claim(
        "4.3-coal-force-smaller",
        "4.3",
        "coal's impact contact force is smaller at each collision",
        "peak force of collision n (N)",
        {"coal": first_few(fc), "sandstone": first_few(fs)},
        "coal < sandstone at every common n",
        all_greater(fs, fc),
    )


def claim_c3_coal_loses_more(r) -> Claim:
    """Conclusion (3) / 4.3: 'materials with poor mechanical properties consume more energy during
    collisions': the fraction of kinetic energy lost at collision n, 1 - e(n)^2, is larger for
    coal than for sandstone at every common n (equal initial energies, scenario 4.3)."""
    lc = [1.0 - e * e for e in restitutions(r, "coal")]
    ls = [1.0 - e * e for e in restitutions(r, "sandstone")]
    return Claim(
        "C3-coal-loses-more-energy",
        "conclusion 3",
        "the material with poor mechanical properties consumes more energy per collision",
        "fraction of kinetic energy lost at collision n, 1 - e^2",
        {"coal": first_few(lc), "sandstone": first_few(ls)},
        "coal > sandstone at every common n",
        all_greater(lc, ls),
    )
