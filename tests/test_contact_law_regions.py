"""The region-wise helpers of tailbeam.physics.contact_law are the same IMPACT law as
impact_force."""

import numpy as np
from scipy.integrate import quad

from tailbeam import COAL, SANDSTONE, ball_ball_law
from tailbeam.physics.contact_law import (
    clamp_indicator,
    elastic_energy,
    impact_force,
    impact_force_in_region,
)


def test_region_force_equals_the_law_inside_each_region():
    law = ball_ball_law(COAL, 0.02, SANDSTONE, 0.03, damping=900.0, penetration=1e-4)
    rng = np.random.default_rng(7)
    delta = rng.uniform(1e-9, 3e-4, 2000)
    rate = rng.uniform(-3.0, 3.0, 2000)
    ramp = delta < law.penetration
    raw = impact_force_in_region(delta, rate, law, ramp, False)
    clamped = raw < 0.0
    ours = impact_force_in_region(delta, rate, law, ramp, clamped)
    np.testing.assert_allclose(ours, impact_force(delta, rate, law), rtol=1e-14, atol=1e-12)
    # the clamp indicator has the sign of the unclamped force
    ind = np.array(
        [clamp_indicator(d, u, law, r) for d, u, r in zip(delta, rate, ramp, strict=True)]
    )
    assert np.array_equal(ind < 0.0, clamped)
    # the elastic energy is the integral of the elastic force
    work, _ = quad(lambda x: law.stiffness * x**law.exponent, 0.0, 2e-4, epsabs=0.0, epsrel=1e-12)
    assert abs(elastic_energy(2e-4, law) / work - 1.0) < 1e-8


def test_compiled_twins_equal_the_region_helpers():
    """The numba twins in tailbeam.solvers.stream.active.compiled.pairs (used by the active-set
    kernel) give the same force, clamp indicator and elastic energy as the helpers above, in
    every region and for exponents 1, 1.5 (the x sqrt(x) branch), 2 (its own clamp limit) and
    2.2."""
    from tailbeam.physics.contact_law import ImpactLaw
    from tailbeam.solvers.stream.active.compiled import pairs as ap

    rng = np.random.default_rng(11)
    for e in (1.0, 1.5, 2.0, 2.2):
        law = ImpactLaw(3e9, e, damping=900.0, penetration=1e-4)
        k, c, d = law.stiffness, law.damping, law.penetration
        delta = np.concatenate([rng.uniform(1e-9, 3e-4, 400), [-1e-6, 0.0]])
        rate = rng.uniform(-3.0, 3.0, delta.size)
        for ramp in (True, False):
            for clamped in (True, False):
                ours = [ap.region_force(x, u, k, e, c, d, ramp, clamped)
                        for x, u in zip(delta, rate, strict=True)]  # fmt: skip
                theirs = impact_force_in_region(delta, rate, law, ramp, clamped)
                np.testing.assert_allclose(ours, theirs, rtol=1e-13, atol=1e-9)
            ind = [
                ap.clamp_indicator(x, u, k, e, c, d, ramp) for x, u in zip(delta, rate, strict=True)
            ]
            want = [clamp_indicator(x, u, law, ramp) for x, u in zip(delta, rate, strict=True)]
            np.testing.assert_allclose(ind, want, rtol=1e-13, atol=1e-13)
        energy = [ap.elastic_energy(x, k, e) for x in delta]
        np.testing.assert_allclose(energy, elastic_energy(delta, law), rtol=1e-13, atol=0.0)
