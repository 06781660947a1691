"""Two-way coupled impacts of balls on a modal (flexible) plate: the driver.

The compiled kernel (``tailbeam.coupled.kernel``) steps the balls and the modes and stops at
every event; this driver records the events and impacts, refreshes each ball's contact point
(its (x, y) at contact: mode shapes and residual compliance there), declares balls at rest and
grows the node buffers. Everything physical happens in the kernel.
"""

import contextlib
import math

import numpy as np

from tailbeam.bodies import STANDARD_GRAVITY, Ball, check_ball_above_plate
from tailbeam.contact_law import ImpactLaw
from tailbeam.contact_patch import load_radius
from tailbeam.coupled import kernel as K
from tailbeam.coupled import step as S
from tailbeam.coupled.records import Compliance, close_contact
from tailbeam.coupled.result import CoupledResult
from tailbeam.errors import InputError, WorkLimitError, require_positive
from tailbeam.hertz import hertz_contact_duration
from tailbeam.modal import ModalBasis
from tailbeam.progress import task
from tailbeam.solvers.records import EventKind

DEFAULT_DAMPING_RATIO = 0.01  # of every mode; README "Defaults" (welded steel, light joints)
DEFAULT_REST_SPEED = 0.01  # m/s, the rigid solver's value, so both models stop alike
DEFAULT_STEPS_PER_CONTACT = 200  # steps per Hertz contact duration: ~1e-5 relative error
_EVENT_NAMES = {
    K.EV_START: EventKind.CONTACT_START,
    K.EV_END: EventKind.CONTACT_END,
    K.EV_DEEP: EventKind.FULL_DAMPING,
    K.EV_SHALLOW: EventKind.FULL_DAMPING,
    K.EV_CLAMP_ON: EventKind.CLAMP_ON,
    K.EV_CLAMP_OFF: EventKind.CLAMP_OFF,
}


def modal_damping(omega, damping_ratio=DEFAULT_DAMPING_RATIO, rayleigh=None) -> np.ndarray:
    """Damping ratio of each mode: constant, or Rayleigh zeta = alpha/(2 omega) + beta omega/2."""
    omega = np.asarray(omega, dtype=float)
    if rayleigh is not None:
        alpha, beta = rayleigh
        if alpha < 0 or beta < 0:
            raise InputError("plate.rayleigh", "alpha and beta must be >= 0")
        zeta = alpha / (2.0 * omega) + 0.5 * beta * omega
        if np.any(zeta >= 1.0):
            raise InputError("plate.rayleigh", "gives a damping ratio >= 1 for some mode")
        return zeta
    if not 0 <= damping_ratio < 1:
        raise InputError("plate.damping_ratio", f"must be in [0, 1), got {damping_ratio!r}")
    return np.full(omega.shape, float(damping_ratio))


def simulate_coupled(
    balls,
    basis: ModalBasis,
    laws,
    duration: float,
    *,
    sensors=(),
    damping_ratio: float = DEFAULT_DAMPING_RATIO,
    rayleigh=None,
    residual_flexibility: bool = True,
    coupling: str = "two-way",
    steps_per_contact: int = DEFAULT_STEPS_PER_CONTACT,
    rest_speed: float = DEFAULT_REST_SPEED,
    rest_contact_factor: float = 50.0,
    gravity: float = STANDARD_GRAVITY,
    max_steps: int = 5_000_000,
    max_events: int = 200_000,
) -> CoupledResult:
    """Balls striking the modal plate ``basis`` over [0, duration] s; see the package docstring.

    laws: one ball-plate ImpactLaw per ball. sensors: SensorSpec accelerometers. Damping: a
    ratio per mode (or Rayleigh (alpha 1/s, beta s)). residual_flexibility adds the static
    compliance of the truncated modes in series with each contact. steps_per_contact: steps per
    Hertz contact duration (accuracy, 2nd order). A ball whose rebound is slower than
    ``rest_speed`` (m/s), or that stays in contact longer than rest_contact_factor Hertz
    durations, is declared at rest and then loads the plate with its weight.
    """
    balls = tuple(balls)
    laws = tuple(laws)
    if not balls:
        raise InputError("balls", "need at least one ball")
    if len(laws) != len(balls):
        raise InputError("laws", f"need one law per ball: {len(balls)} balls, {len(laws)} laws")
    for ball, law in zip(balls, laws, strict=True):
        if not isinstance(ball, Ball):
            raise InputError("balls", "must be Ball objects")
        if not isinstance(law, ImpactLaw):
            raise InputError("laws", "must be ImpactLaw objects")
        check_ball_above_plate(ball)
    duration = require_positive("duration", duration)
    if coupling not in ("two-way", "one-way"):
        raise InputError("plate.coupling", f"must be 'two-way' or 'one-way', got {coupling!r}")
    if int(steps_per_contact) < 4:
        raise InputError("steps_per_contact", "must be >= 4")
    for spec in sensors:
        if not basis.plate.contains(*spec.position):
            raise InputError(f"sensors[{spec.name}].position", "must lie on the plate")
    if residual_flexibility and basis.static_compliance_at is None and coupling == "two-way":
        raise InputError(
            "plate.residual_flexibility",
            f"the {basis.theory} {basis.boundary} basis has no static compliance (a plate with "
            "rigid-body modes); set residual_flexibility = false",
        )
    if coupling == "one-way":
        from tailbeam.coupled.oneway import simulate_one_way

        return simulate_one_way(
            balls,
            basis,
            laws,
            duration,
            sensors=sensors,
            damping_ratio=damping_ratio,
            rayleigh=rayleigh,
            rest_speed=rest_speed,
            gravity=gravity,
        )
    omega = np.ascontiguousarray(basis.omega, dtype=float)
    zeta = modal_damping(omega, damping_ratio, rayleigh)
    nb, n = len(balls), basis.n_modes
    plate = basis.plate
    mass = np.array([b.mass for b in balls])
    radius = np.array([b.radius for b in balls])
    kk = np.array([lw.stiffness for lw in laws])
    ee = np.array([lw.exponent for lw in laws])
    cc = np.array([lw.damping for lw in laws])
    dd = np.array([lw.penetration for lw in laws])
    clampf = np.array([lw.clamp for lw in laws], dtype=np.bool_)
    x0 = np.array([b.position[0] for b in balls])
    y0 = np.array([b.position[1] for b in balls])
    vx = np.array([b.velocity[0] for b in balls])
    vy = np.array([b.velocity[1] for b in balls])
    compliance = Compliance(basis, residual_flexibility)
    # the load model (tailbeam.contact_patch): a point (Kirchhoff) or the Hertz disc (Mindlin)
    rload = [load_radius(basis.theory, b, lw, gravity) for b, lw in zip(balls, laws, strict=True)]

    def shape(b, px, py):
        return basis.load_deflection([[px, py]], rload[b])[0]

    def xy(b, t):
        return x0[b] + vx[b] * t, y0[b] + vy[b] * t

    # state
    q = np.zeros(n)
    qd = np.zeros(n)
    z = np.array([b.position[2] for b in balls])
    vz = np.array([b.velocity[2] for b in balls])
    F = np.zeros(nb)
    mode = np.full(nb, S.FLIGHT, dtype=np.int64)
    deep = np.zeros(nb, dtype=np.bool_)
    cur = np.zeros((4, nb))
    hist = np.zeros((2, nb))  # last step's force slope (N/s) and length (s), per ball
    cur[0] = radius - z
    cur[1] = -vz
    cur[3] = vz
    phi = np.ascontiguousarray([shape(b, x0[b], y0[b]) for b in range(nb)], dtype=float)
    cres = np.zeros(nb)
    h = np.zeros(nb)

    def nominal_step(b, speed):
        speed = max(abs(speed), 1e-3)
        return hertz_contact_duration(mass[b], speed, kk[b], ee[b]) / steps_per_contact

    for b in range(nb):
        if not plate.contains(x0[b], y0[b]):
            mode[b] = S.OFF
        h[b] = nominal_step(b, math.sqrt(vz[b] ** 2 + 2 * gravity * max(z[b] - radius[b], 0)))

    cap = 65536
    bt, bz, bvz, bF, bd = (np.empty(cap), *(np.empty((cap, nb)) for _ in range(4)))
    bt[0], bz[0], bvz[0], bF[0], bd[0] = 0.0, z, vz, F, cur[0]
    nbuf = 1
    seg_phase = [0]
    phis = [phi.copy()]
    events, impacts, open_contacts, contact_points = [], [], {}, []
    counts = [0] * nb
    rest_time = {b.name: math.nan for b in balls}
    evout = np.zeros(2, dtype=np.int64)
    t, total_steps, status, message = 0.0, 0, 0, "reached the end of the simulated time"
    moving = np.hypot(vx, vy) > 0
    progress = contextlib.ExitStack()  # closed after the loop (no re-indented loop body)
    bar = progress.enter_context(
        task(f"simulating {duration:g} s", total=1e3 * duration, unit="ms simulated")
    )
    t_shown = 0.0
    while t < duration:
        if len(events) > max_events:
            raise WorkLimitError(f"more than max_events={max_events} events; raise max_events")
        # refresh contact points of flying balls (lateral motion) and leave-the-plate checks
        t_stop = duration
        for b in range(nb):
            if mode[b] == S.FLIGHT and moving[b]:
                px, py = xy(b, t)
                if not plate.contains(px, py):
                    mode[b] = S.OFF
                    continue
                phi[b] = shape(b, px, py)
                # refresh again after 1 mm of lateral travel (mode shapes vary on ~ cm scales)
                t_stop = min(t_stop, t + 1e-3 / math.hypot(vx[b], vy[b]))
            if mode[b] in (S.CONTACT, S.CLAMPED):
                t_stop = min(t_stop, open_contacts[b]["t_start"] + open_contacts[b]["t_limit"])
        phis.append(phi.copy())
        seg_phase[-1] = len(phis) - 1
        ctx = (omega, zeta, phi, cres, mass, radius, kk, ee, cc, dd, clampf)
        st = (q, qd, z, vz, F, mode, deep, cur, hist)
        res = K.run(
            ctx,
            st,
            t,
            t_stop,
            h,
            max_steps - total_steps,
            gravity,
            (bt, bz, bvz, bF, bd),
            nbuf,
            evout,
        )
        code, t, nbuf_new, steps = res
        bar.update(1e3 * (t - t_shown))
        t_shown = t
        total_steps += steps
        seg_phase.extend([len(phis) - 1] * (nbuf_new - nbuf))
        nbuf = nbuf_new
        if code == K.ST_FULL:
            bt, bz, bvz, bF, bd = (
                np.concatenate([a, np.empty_like(a)]) for a in (bt, bz, bvz, bF, bd)
            )
            continue
        if code == K.ST_STEPS:
            raise WorkLimitError(f"more than max_steps={max_steps} steps; raise max_steps")
        if code == K.ST_FAIL:
            raise WorkLimitError(
                f"the contact Newton iteration failed to converge at t = {t:.9g} s; "
                "raise steps_per_contact"
            )
        if code == K.ST_STOP:
            # persistent contacts that reached their time limit come to rest
            for b in range(nb):
                if mode[b] in (S.CONTACT, S.CLAMPED) and t >= open_contacts[b]["t_start"] + (
                    open_contacts[b]["t_limit"] * (1 - 1e-12)
                ):
                    _rest(b, t, balls, laws, mode, z, vz, F, cur, gravity, radius, phi, q)
                    impacts.append(
                        close_contact(
                            open_contacts.pop(b),
                            b,
                            balls[b],
                            t,
                            0.0,
                            (bt, bz, bvz, bF, bd),
                            nbuf,
                            radius[b],
                            gravity,
                            at_rest=True,
                        )
                    )
                    rest_time[balls[b].name] = t
                    events.append((t, balls[b].name, EventKind.REST))
                    nbuf = _append_node(t, z, vz, F, cur, (bt, bz, bvz, bF, bd), nbuf, seg_phase)
            continue
        kind, b = int(evout[0]), int(evout[1])
        name = balls[b].name
        events.append((t, name, _EVENT_NAMES[kind]))
        if kind == K.EV_START:
            px, py = xy(b, t)
            phi[b] = shape(b, px, py)
            contact_points.append((t, b, px, py, rload[b]))
            w_rel = float(phi[b] @ qd)
            speed = max(w_rel - vz[b], 1e-6)
            h[b] = nominal_step(b, speed)
            cres[b] = compliance(px, py, rload[b])
            counts[b] += 1
            open_contacts[b] = {
                "index": counts[b],
                "t_start": t,
                "v_in": -vz[b],
                "node": nbuf - 1,
                "t_limit": rest_contact_factor * h[b] * steps_per_contact,
            }
        elif kind == K.EV_END:
            info = open_contacts.pop(b)
            v_out = vz[b]
            at_rest = v_out < rest_speed
            impacts.append(
                close_contact(
                    info,
                    b,
                    balls[b],
                    t,
                    v_out,
                    (bt, bz, bvz, bF, bd),
                    nbuf,
                    radius[b],
                    gravity,
                    at_rest=at_rest,
                    z=z[b],
                )
            )
            cres[b] = 0.0
            if at_rest:
                _rest(b, t, balls, laws, mode, z, vz, F, cur, gravity, radius, phi, q)
                rest_time[name] = t
                events.append((t, name, EventKind.REST))
                nbuf = _append_node(t, z, vz, F, cur, (bt, bz, bvz, bF, bd), nbuf, seg_phase)
            else:
                h[b] = nominal_step(b, v_out)
    progress.close()
    for b, info in open_contacts.items():  # contacts still open at the end
        impacts.append(
            close_contact(
                info,
                b,
                balls[b],
                t,
                math.nan,
                (bt, bz, bvz, bF, bd),
                nbuf,
                radius[b],
                gravity,
                at_rest=False,
            )
        )
    impacts.sort(key=lambda imp: (imp.t_start, imp.ball))
    return CoupledResult(
        balls=balls,
        laws=laws,
        basis=basis,
        duration=duration,
        gravity=gravity,
        zeta=zeta,
        impacts=impacts,
        events=events,
        rest_time=rest_time,
        nodes=(
            bt[:nbuf].copy(),
            bz[:nbuf].copy(),
            bvz[:nbuf].copy(),
            bF[:nbuf].copy(),
            bd[:nbuf].copy(),
        ),
        seg_phase=np.asarray(seg_phase[:nbuf], dtype=np.int64),
        phis=np.ascontiguousarray(np.array(phis)),
        sensors=tuple(sensors),
        contact_points=tuple(contact_points),
        n_steps=total_steps,
        status=status,
        message=message,
        info={
            "coupling": "two-way",
            "residual_flexibility": residual_flexibility,
            "steps_per_contact": steps_per_contact,
            "n_modes": n,
        },
    )


def _append_node(t, z, vz, F, cur, bufs, nbuf, seg_phase):
    bt, bz, bvz, bF, bd = bufs
    if nbuf >= len(bt):
        raise WorkLimitError("node buffer full at a rest declaration; raise max_steps")
    bt[nbuf], bz[nbuf], bvz[nbuf], bF[nbuf], bd[nbuf] = t, z, vz, F, cur[0]
    seg_phase.append(seg_phase[-1])
    return nbuf + 1


def _rest(b, t, balls, laws, mode, z, vz, F, cur, gravity, radius, phi, q):
    """Ball b sits on the plate from now on: a dead weight m g at its contact point."""
    mg = balls[b].mass * gravity
    w = float(phi[b] @ q)
    mode[b] = S.REST
    z[b] = radius[b] - laws[b].static_penetration(mg) + w
    vz[b] = 0.0
    F[b] = mg
    cur[:, b] = 0.0
