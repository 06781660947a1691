"""Putting a member of the active set at rest on the plate (a slider inside the set).

A ball whose plate contact has settled, or that rebounds too slowly, is held at its static
state: its static penetration under its weight (plus the residual spring's C m g_n in
series on the modal plate), moving with the plate under it, touching, in the law's region
of that penetration. The normal motion above this state is removed; the energy it held is
returned for the driver's ledger.
"""

from tailbeam.solvers.stream.active.compiled.pairs import settle_excess


def static_height(balls, i: int, compliance: float) -> float:
    """Height (m) of ball i resting on the undeflected plate.

    Parameters
    ----------
    balls : Balls
        The stream's balls (radius m, static_pen m, mass kg, g m/s^2).
    i : int
        Ball number.
    compliance : float
        Residual compliance (m/N) in series with the contact (0 on the rigid plate).
    """
    b = balls
    return b.radius[i] - b.static_pen[i] - compliance * b.mass[i] * -b.g[2]


def excess_energy(s, q: int, p: int) -> float:
    """Energy (J) removed by putting ball q of ``s`` (an ``ActiveSet``) at rest: its normal
    excess energy over the static state while its plate pair p touches, else (a slow
    rebound) the energy of its normal motion."""
    if not s.contacts.touching[p]:
        return 0.5 * s.model.mass[q] * s.v[q, 2] ** 2
    return float(settle_excess(s.y, s.model.arrays(), p, q))


def place_at_rest(s, q: int, p: int, height: float, speed: float, static_pen: float) -> None:
    """Hold ball q of ``s`` (an ``ActiveSet``) at ``height`` (m) with normal speed ``speed``
    (m/s, the plate's under it), its plate pair p touching in the region of its static
    penetration ``static_pen`` (m), never settling again until woken; p's rows are no longer
    fresh."""
    s.x[q, 2] = height
    s.v[q, 2] = speed
    s.contacts.hold(p, static_pen, s.model.law[p])
    s.model.settle_energy[q] = 0.0
    s.io.forget_fresh(p)
