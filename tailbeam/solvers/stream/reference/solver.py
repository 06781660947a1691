"""Slow, independent reference for streams: all balls and the inclined plate together, the
plate rigid or modal (two-way, ``plate=ReferencePlate(...)``, see below).

One ODE for every ball (3-D translation; with ``friction`` also its rotation, the tangential
forces and rolling resistance of ``tailbeam.solvers.stream.reference.friction``), integrated
by scipy's DOP853 (the method of ``solve_ivp(method="DOP853")``, driven step by
step through its ``OdeSolver`` class so that every step can be checked for contacts; rtol
1e-12 by default). Every pair is watched (O(N^2): this is the slow reference):

* ball-ball and ball-plate contacts use the IMPACT law of ``tailbeam.physics.contact_law``
  (from the contact table, ``tailbeam.physics.contacts``: ball-ball R = R1 R2 / (R1 + R2),
  E* of both materials; ball-plate), the pair geometry of ``tailbeam.physics.pair`` and the
  plate frame of ``tailbeam.physics.incline`` (gravity g (sin theta, 0, -cos theta));
* events at every kink: contact start and end of every pair, penetration = d (STEP kink,
  when c > 0), clamp on/off (when c > 0 and the clamp is on), and a ball's centre passing an
  edge of the plate (the ball leaves and is dropped). Inside a region each pair's force is
  that region's smooth formula; a step in which an event is found is discarded and redone
  to end exactly at the event, where the integration restarts with the new region, so no
  accepted step straddles a kink.

The parts, each given the others it uses when it is made (``_simulate`` wires them):

* ``state.StateLayout``: which balls the state vector holds, in which order, and the modes;
* ``pairs.PairSet``: the watched pairs, their laws and region flags;
* ``kinematics.Kinematics``: the pairs' penetration, rate and normal at given states;
* ``dynamics.Dynamics``: the right-hand side of the current contacts;
* ``events.EventSearch``: the watched functions (rows) and the first event on a step;
* ``changes.SceneChanges``: an event or a release applied to the pairs and the state;
* ``contacts.ContactLog``: the records written out (contacts, leaves, the event log);
* ``steps.StepSeries``: what an accepted step records (peaks, energy, states);
* ``loop.StepLoop``: drives DOP853 (``loop.Integrator``) from event to event.

Friction (``friction=FrictionModel``; on the modal plate with exact or frozen shapes, a
frozen contact keeping its shapes' gradients too: ``plate``). The state gains every ball's angular
velocity (moment of inertia 2/5 m r^2). The regularised Adams law is smooth (C^1 in the slip
velocity), so it needs no event of its own: DOP853 resolves its stiffness by short steps.
That is the honest cost of the slow truth: with a contact held at slip speeds below v_s the
step is bounded by stability to ~3 / lambda, lambda ~ mu_s |F_n| / (m_eff v_s) (about 1e-4 s
for a ball resting on the plate with v_s = 1e-3 m/s, and shorter during impacts, where F_n is
thousands of times the weight); the run's step budget ``max_steps`` bounds it. Impulses and
friction's dissipated energy are integrated on every accepted step (``steps``); the energy
series includes the rotational energy 1/2 I w^2, and energy + dissipated never grows.

Modal plate (``tailbeam.solvers.stream.reference.plate``: the model, exact or frozen mode
shapes). The state gains the modal coordinates [q | q'] after the balls (atol: deflections to
rtol x 1 mm, rates to rtol x 1 m/s). A ball's plate rows use the gap z - w,
w = phi(x, y) . q. What is certified: with frozen shapes (a contact's) the rows are
polynomials of degree <= 14 on a step, as on the rigid plate (``events``). With exact shapes
phi(x(s), y(s)) is not a polynomial; the 15 values are exact samples, and the certificate
and the root search act on their interpolant. Every step is bounded so that no ball moves
sideways more than 1 / k_max (k_max: the top mode's wavenumber; the step is redone shorter
otherwise): along such a path each shape's Chebyshev coefficients fall like
(k L / 4)^n / n!, and the interpolant misses the row only by products of them with the top
coefficients of the dense output (~rtol): an estimate (~1e-12 of the row's scale), not a
certificate. A crossing found on the interpolant is applied only where the true row lies
within its dead band (else the step goes on and finds it again, closer), so no event is
applied early; a dip narrower than that estimate could be missed. The modes also bound the
steps (at least MODAL_STEPS_PER_PERIOD per period of the top mode: too long a run is refused
at once).
"""

import math
from dataclasses import dataclass, field

import numpy as np

from tailbeam.errors import InputError, WorkLimitError, require_positive
from tailbeam.physics.contact_law import HERTZ_EXPONENT
from tailbeam.physics.contacts import LawOptions, contact_table
from tailbeam.physics.friction import FrictionModel
from tailbeam.physics.incline import InclinedPlate
from tailbeam.solvers.stream.reference.changes import SceneChanges
from tailbeam.solvers.stream.reference.contacts import ContactLog
from tailbeam.solvers.stream.reference.dynamics import Dynamics
from tailbeam.solvers.stream.reference.events import EventSearch
from tailbeam.solvers.stream.reference.kinematics import Kinematics
from tailbeam.solvers.stream.reference.loop import Integrator, StepLoop
from tailbeam.solvers.stream.reference.pairs import PairSet
from tailbeam.solvers.stream.reference.plate import ReferencePlate
from tailbeam.solvers.stream.reference.state import StateLayout
from tailbeam.solvers.stream.reference.steps import StepSeries
from tailbeam.solvers.stream.reference.sticking import CoulombState

MODAL_STEPS_PER_PERIOD = 5  # a lower bound of the steps per period of the top mode


@dataclass
class StreamReferenceResult:
    """What a run of the stream reference reports.

    Parameters
    ----------
    names : tuple of str
        The balls' names, in the order given.
    masses : ndarray
        The balls' masses (kg).
    contacts : list of Impact
        One record per ball per contact, in order of first touch.
    leaves : list of LeaveEvent
        The balls that left over an edge, in time order.
    events : list of Event
        The event log, in time order.
    times : ndarray
        Time (s) of the start and of every accepted step.
    energy : ndarray
        Total energy (J) of the balls present (kinetic, gravitational, elastic; on the
        modal plate also the modes') at ``times``.
    states : list of tuple
        Per entry of ``times``: names of the balls present, positions (n, 3) (m) and
        velocities (n, 3) (m/s).
    steps : int
        DOP853 steps taken, redone ones included.
    info : dict
        The solver, the plate and the duration (s).
    plate_states : list of tuple
        Modal plate: (q, q') per entry of ``times`` (m sqrt(kg), m sqrt(kg) / s); empty on
        the rigid plate.
    spins : list of ndarray
        With friction: the present balls' angular velocities (n, 3) (rad/s) per entry of
        ``times`` (the balls of ``states``); empty without.
    dissipated : ndarray
        With friction: the energy friction and rolling resistance dissipated since the start
        (J) at ``times``; empty without.
    angular_velocity : dict
        Every ball's name -> its angular velocity (3,) (rad/s) when it left or at the end (a
        ball never released: its initial one).
    """

    names: tuple
    masses: np.ndarray
    contacts: list
    leaves: list
    events: list
    times: np.ndarray
    energy: np.ndarray
    states: list
    steps: int
    info: dict
    plate_states: list = field(default_factory=list)
    spins: list = field(default_factory=list)
    dissipated: np.ndarray = field(default_factory=lambda: np.zeros(0))
    angular_velocity: dict = field(default_factory=dict)

    def contacts_of(self, ball: str) -> list:
        """The contact records of the ball named ``ball``."""
        return [c for c in self.contacts if c.ball == ball]


def simulate_stream_reference(
    balls,
    incline: InclinedPlate,
    duration: float,
    *,
    damping: float = 0.0,
    penetration: float = 1e-4,
    clamp: bool = True,
    exponent: float = HERTZ_EXPONENT,
    rtol: float = 1e-12,
    max_steps: int = 200_000,
    release_times=None,
    progress=None,
    plate: ReferencePlate | None = None,
    contacts=None,
    friction=None,
) -> StreamReferenceResult:
    """Integrate a stream of balls on an inclined plate, every pair watched (module
    docstring).

    Parameters
    ----------
    balls : sequence of Ball
        The balls (``tailbeam.Ball``), positions (m) and velocities (m/s) in the plate
        frame; names unique, centres above the plate and over it.
    incline : InclinedPlate
        The plate, its inclination and its edges.
    duration : float
        Simulated time (s), > 0.
    damping, penetration, clamp, exponent : float, float, bool, float
        The IMPACT parameters of every pair: damping c (N s/m), penetration d (m) where the
        damping ramp ends, the clamp of negative forces, exponent e (stiffness from Hertz).
    rtol : float
        DOP853's relative tolerance in [1e-14, 1e-3] (atol = rtol x 1 mm on positions,
        rtol x 1 m/s on velocities).
    max_steps : int
        Most DOP853 steps (WorkLimitError beyond).
    release_times : sequence of float, optional
        One per ball (s, default all 0): a ball enters the scene at its time, at its given
        position and velocity (event ``release``; the energy series jumps there).
    progress : callable, optional
        Called with the time (s) reached after every accepted step.
    plate : ReferencePlate, optional
        The modal plate (two-way, ``tailbeam.solvers.stream.reference.plate``); None: the
        rigid plate.
    contacts : ContactTable, optional
        The balls' contact table; its settings then replace the IMPACT parameters above.
    friction : FrictionModel, optional
        Friction and rolling resistance of every contact (``tailbeam.physics.friction``;
        rigid or modal plate); None: frictionless, the balls' angular velocities never change.

    Returns
    -------
    StreamReferenceResult
    """
    duration = require_positive("duration", duration)
    if not 1e-14 <= rtol <= 1e-3:
        raise InputError("rtol", f"must lie in [1e-14, 1e-3], got {rtol!r}")
    options = LawOptions(exponent, damping, penetration, clamp) if contacts is None else contacts
    balls = list(balls)
    release = _release_times(release_times, len(balls))
    if plate is not None:
        if not isinstance(plate, ReferencePlate):
            raise InputError("plate", "must be a ReferencePlate (a modal basis and its damping)")
        plate.check_size(incline)
        _check_modal_work(plate, duration, max_steps)
    if friction is not None and not isinstance(friction, FrictionModel):
        raise InputError("contact.friction", "must be a FrictionModel (or None: frictionless)")
    if friction is not None and friction.coulomb and plate is not None:
        raise InputError(
            "contact.friction.stiction_velocity",
            "0 (Coulomb's law) runs on the rigid plate only (no modal plate)",
        )
    _check_balls(balls, incline)
    table = contact_table(balls, options, incline.plate.material)  # the pairs' laws
    run = (balls, incline, table, release, plate, duration, rtol, max_steps, progress)
    return _simulate(*run, friction)


def _simulate(balls, incline, table, release, plate, duration, rtol, max_steps, progress,
              friction=None):  # fmt: skip
    """Wire the parts (module docstring), run them and collect the result."""
    mass = np.array([b.mass for b in balls])
    radius = np.array([b.radius for b in balls])
    present = [i for i in range(len(balls)) if release[i] <= 0.0]
    waiting = sorted((float(release[i]), i) for i in range(len(balls)) if release[i] > 0)
    n_modes = None if plate is None else plate.n_modes
    layout = StateLayout(len(balls), n_modes, present, spin=friction is not None)
    pairs = PairSet(balls, table, friction, incline.plate.material.name)
    for i in present:
        pairs.add_ball(i, present)
    kinematics = Kinematics(layout, plate)
    log = ContactLog(balls, plate)
    changes = SceneChanges(layout, pairs, kinematics, log, balls, mass, rtol, waiting)
    series = StepSeries(layout, pairs, kinematics, balls, mass, incline, plate)
    search = EventSearch(pairs, layout, kinematics, incline, plate)
    dynamics = Dynamics(layout, kinematics, pairs, mass, incline.gravity_vector, plate, radius)
    integrator = Integrator(dynamics, layout, plate, rtol, radius)
    loop = StepLoop(integrator, search, changes, series, max_steps, progress)
    if friction is not None and friction.coulomb:
        coulomb = CoulombState(layout, kinematics, pairs, mass, radius, incline.gravity_vector)
        changes.coulomb = series.coulomb = search.coulomb = coulomb
    y = _initial_state(balls, present, plate, layout.spin)
    changes.touch(list(pairs.values()), 0.0, y)
    loop.run(0.0, y, duration)
    y = loop.solver.y
    for p in pairs.values():  # the contacts still in progress
        p.write_peaks(changes.slip(p, y) if p.in_contact else float("nan"))
    info = {
        "solver": f"stream reference: scipy DOP853 rtol={rtol:g}, restarted at kinks",
        "plate": "rigid"
        if plate is None
        else f"modal, two-way: {plate.n_modes} modes, {plate.shapes} shapes",
        "duration": duration,
    }
    if friction is not None:
        info["friction"] = "Adams CONTACT friction and rolling resistance, rotation"
    return StreamReferenceResult(
        tuple(b.name for b in balls), mass, log.contacts, log.leaves, log.events,
        np.array(series.times), np.array(series.energy), series.states, loop.steps, info,
        series.plate_states, series.spins, np.array(series.dissipated),
        _final_spins(balls, layout, y, log),
    )  # fmt: skip


def _final_spins(balls, layout, y, log) -> dict:
    """Every ball's angular velocity (rad/s) when it left, at the end (present) or as given
    (never released, or frictionless: it never changes)."""
    out = {b.name: np.array(b.angular_velocity, dtype=float) for b in balls}
    out.update(log.spin_at_leave)
    w = layout.spins(y)
    if w is not None:
        out.update({balls[i].name: w[q].copy() for q, i in enumerate(layout.active)})
    return out


def _initial_state(balls, present, plate, spin=False):
    """The state vector at t = 0: the present balls' positions and velocities (and with
    ``spin`` their angular velocities), the plate at rest."""
    pos = np.array([balls[i].position for i in present], dtype=float).reshape(-1, 3)
    vel = np.array([balls[i].velocity for i in present], dtype=float).reshape(-1, 3)
    w = np.array([balls[i].angular_velocity for i in present], dtype=float).reshape(-1, 3)
    m = 0 if plate is None else plate.n_modes
    return StateLayout.join(
        pos, vel, (np.zeros(m), np.zeros(m)) if m else None, w if spin else None
    )


def _check_modal_work(plate, duration, max_steps):
    """The modes bound the steps: at least MODAL_STEPS_PER_PERIOD per period of the top mode
    (a lower bound: DOP853 takes more at the tolerances used); refuse a run that cannot fit
    max_steps before it starts."""
    estimate = MODAL_STEPS_PER_PERIOD * duration * float(np.max(plate.omega)) / (2.0 * math.pi)
    if estimate > max_steps:
        raise WorkLimitError(
            f"stream reference: the modal plate (top mode {np.max(plate.omega) / 2 / math.pi:.4g}"
            f" Hz) needs at least ~{estimate:.3g} steps for {duration:g} s, above "
            f"max_steps={max_steps}; raise max_steps, shorten the duration or keep fewer modes"
        )


def _release_times(release_times, n):
    """The release times (s) as an array of n, zeros if None (InputError if invalid)."""
    if release_times is None:
        return np.zeros(n)
    times = np.asarray(release_times, dtype=float)
    if times.shape != (n,) or not np.all(np.isfinite(times)) or np.any(times < 0.0):
        raise InputError("release_times", f"must be {n} finite times >= 0 s (one per ball)")
    return times


def _check_balls(balls, incline):
    """Names unique, centres above the plate and over it (InputError otherwise)."""
    names = set()
    for b in balls:
        field_ = f"balls[{b.name}]"
        if b.name in names:
            raise InputError(f"{field_}.name", "is used by an earlier ball")
        names.add(b.name)
        if b.position[2] <= 0.0:
            raise InputError(f"{field_}.position", "the centre must lie above the plate (z > 0)")
        if np.any(incline.edge_distances(b.position[:2]) < 0.0):
            raise InputError(f"{field_}.position", "the centre must lie over the plate")
