"""The IMPACT law's core (``tailbeam.physics.impact``) as numba ufuncs: they broadcast like
numpy, so the law's parameters may be arrays (one per pair) and ``ramp`` / ``clamped`` arrays
of flags. Compiled on first call and cached on disk; ``tailbeam.physics.contact_law`` imports
this module when it first evaluates a force, so building a law needs no numba.

The region forms serve integrators that stop at every kink: ``ramp`` (delta < d: damping
c STEP(delta, 0, 0, d, c), the cubic extended past d) or full damping (c), and ``clamped``
(Adams' max(0, .) active: force 0).
"""

from numba import vectorize

from tailbeam.physics import impact


@vectorize(cache=True)
def step(x, x0, h0, x1, h1):
    """Adams STEP (``impact.step``)."""
    return impact.step(x, x0, h0, x1, h1)


@vectorize(cache=True)
def impact_force_array(delta, rate, k, e, c, d, clamp):
    """``impact.force`` as a ufunc: every argument may be an array (one per pair)."""
    return impact.force(delta, rate, k, e, c, d, clamp)


@vectorize(cache=True)
def region_damping(delta, c, d, ramp):
    """``impact.region_damping``: damping in N s/m of one region."""
    return impact.region_damping(delta, c, d, ramp)


@vectorize(cache=True)
def region_force(delta, rate, k, e, c, d, ramp, clamped):
    """``impact.region_force``: force in N of one region's formula."""
    return impact.region_force(delta, rate, k, e, c, d, ramp, clamped)


@vectorize(cache=True)
def elastic_energy(delta, k, e):
    """``impact.elastic_energy``: energy in J of the elastic term."""
    return impact.elastic_energy(delta, k, e)
