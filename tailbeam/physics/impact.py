"""The IMPACT contact law (paper eqs. 1, 5), written once: the scalar core every solver calls.

In terms of the penetration delta (m, > 0 in contact) and its rate (m/s, > 0 approaching),
with stiffness k (N/m^e), exponent e, damping c (N s/m) reached at penetration d (m):

    F = max(0, k delta^e + STEP(delta, 0, 0, d, c) rate)   for delta > 0,   0 otherwise

(the max(0, .) clamp is Adams' behaviour and optional). STEP's cubic c s^2 (3 - 2 s),
s = delta / d, ramps the damping in over [0, d]; its second derivative jumps at delta = 0
and d, and the clamp is a kink too. The kink-respecting integrators therefore use the law
region by region: ``ramp`` (delta < d: the cubic, extended past d) or full damping (c), and
``clamped`` (force held at 0) or not; each region's formula is smooth and is used past the
region's border, up to the event that switches region.

Every function here is compiled with numba (``njit(cache=True, inline="always")``): callable
from the compiled integrators (rigid, coupled, active-set kernels) and from Python (the
references, and the array wrappers of ``tailbeam.physics.contact_law``). Inlined into the
kernels at numba's IR level, so a kernel that asks for several pieces at one point (the rigid
kernel's watched functions) computes delta^e once. The solvers differ in how they integrate and
find events, never in the formula. ``tests/test_impact_core.py`` checks the core against eq. 5
written out, Adams' STEP end conditions, finite-difference derivatives and the work of the
elastic force."""

import math

from tailbeam.jit import njit


@njit(cache=True, inline="always")
def power(x, e):
    """x^e for x >= 0; the Hertz exponent 3/2 as x sqrt(x) (several times cheaper)."""
    if e == 1.5:
        return x * math.sqrt(x)
    return x**e


@njit(cache=True, inline="always")
def step(x, x0, h0, x1, h1):
    """Adams STEP: h0 for x <= x0, h1 for x >= x1, h0 + (h1 - h0) s^2 (3 - 2 s) between,
    s = (x - x0) / (x1 - x0). C1: the cubic has zero slope at both ends."""
    if x <= x0:
        return h0
    if x >= x1:
        return h1
    s = (x - x0) / (x1 - x0)
    return h0 + (h1 - h0) * s * s * (3.0 - 2.0 * s)


@njit(cache=True, inline="always")
def region_damping(delta, c, d, ramp):
    """Damping in N s/m of a region: STEP's cubic c s^2 (3 - 2 s), s = delta / d, extended past
    [0, d] (``ramp``), or c (full damping)."""
    if not ramp:
        return c
    s = delta / d
    return c * s * s * (3.0 - 2.0 * s)


@njit(cache=True, inline="always")
def region_damping_slope(delta, c, d, ramp):
    """d(damping)/d(delta) in N s/m^2 of a region: 6 c s (1 - s) / d in the ramp, else 0."""
    if not ramp:
        return 0.0
    s = delta / d
    return c * 6.0 * s * (1.0 - s) / d


@njit(cache=True, inline="always")
def region_force(delta, rate, k, e, c, d, ramp, clamped):
    """Force in N of one region's smooth formula, k delta^e + damping(delta) rate, with
    delta <= 0 read as 0 (so the elastic term vanishes there); 0 where ``clamped``."""
    if clamped:
        return 0.0
    pos = delta if delta > 0.0 else 0.0
    return k * power(pos, e) + region_damping(pos, c, d, ramp) * rate


@njit(cache=True, inline="always")
def force(delta, rate, k, e, c, d, clamp):
    """The IMPACT force in N at penetration ``delta`` (m) and rate ``rate`` (m/s); ``clamp``:
    Adams' max(0, .)."""
    if delta <= 0.0:
        return 0.0
    raw = region_force(delta, rate, k, e, c, d, delta < d, False)
    if clamp and raw < 0.0:
        return 0.0
    return raw


@njit(cache=True, inline="always")
def elastic_stiffness(delta, k, e):
    """d(k delta^e)/d(delta) = k e delta^(e-1) in N/m for delta > 0, else 0."""
    if delta <= 0.0:
        return 0.0
    return k * e * power(delta, e) / delta


@njit(cache=True, inline="always")
def region_force_slope(delta, rate, k, e, c, d, ramp):
    """dF/d(delta) in N/m of one region's formula at delta > 0 (unclamped)."""
    return elastic_stiffness(delta, k, e) + region_damping_slope(delta, c, d, ramp) * rate


@njit(cache=True, inline="always")
def force_partials(delta, rate, k, e, c, d, clamp):
    """(F N, dF/d(delta) N/m, dF/d(rate) N s/m, unclamped F N) of the IMPACT law; all 0 at
    delta <= 0, the partials 0 where the clamp holds F at 0."""
    if delta <= 0.0:
        return 0.0, 0.0, 0.0, 0.0
    ramp = delta < d
    raw = region_force(delta, rate, k, e, c, d, ramp, False)
    if clamp and raw < 0.0:
        return 0.0, 0.0, 0.0, raw
    slope = region_force_slope(delta, rate, k, e, c, d, ramp)
    return raw, slope, region_damping(delta, c, d, ramp), raw


@njit(cache=True, inline="always")
def region_force_rate(delta, rate, accel, k, e, c, d, ramp):
    """dF/dt in N/s of one region's (unclamped) formula along a motion with penetration rate
    ``rate`` (m/s) and its derivative ``accel`` (m/s^2); 0 at delta <= 0. Its zeros are the
    force peaks."""
    if delta <= 0.0:
        return 0.0
    slope = region_force_slope(delta, rate, k, e, c, d, ramp)
    return slope * rate + region_damping(delta, c, d, ramp) * accel


@njit(cache=True, inline="always")
def clamp_indicator(delta, rate, k, e, c, d, ramp):
    """Unclamped force / (k delta^e): the sign of the unclamped force, but not 0 at delta = 0.

    Its zero is the clamp kink (clamp on / off); unlike the force it does not vanish at
    separation, so the clamp events never coincide with contact end. At delta <= 0: its limit
    at delta -> 0+ (1 in the ramp for e < 2; 1 + 3 c rate / (k d^2) for e = 2; else the sign
    of the rate)."""
    if delta > 0.0:
        return 1.0 + region_damping(delta, c, d, ramp) * rate / (k * power(delta, e))
    if ramp and e < 2.0:
        return 1.0
    if ramp and e == 2.0:
        return 1.0 + 3.0 * c * rate / (k * d * d)
    return -1.0 if rate < 0.0 else 1.0


@njit(cache=True, inline="always")
def elastic_energy(delta, k, e):
    """Energy in J stored by the elastic term: k delta^(e+1) / (e+1) for delta > 0, else 0."""
    if delta <= 0.0:
        return 0.0
    return k * power(delta, e) * delta / (e + 1.0)
