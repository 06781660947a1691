"""The compiled active-set integrator of the fast stream solver: Python wrapper.

The fast stream solver's driver advances balls in free flight in closed form and hands the
"active set" (balls in contact plus nearby flying balls, and the pairs to watch) to
``ActiveSet.advance``, which integrates them with a compiled DOP853 (8th order, dense output;
``kernel``) until the first structural event or ``t_stop``:

* returns at contact START / END (pair index), LEAVE (ball, edge in
  ``tailbeam.physics.incline.EDGES`` order), SETTLE (ball: ``EventCode.REST``), or ``t_stop``
  (``EventCode.NONE``);
* handles inside (and logs) the kinks of the IMPACT law: penetration = d (when c > 0) and
  clamp on/off; no accepted step straddles a kink;
* all events are located on the dense output: squared distances, plate gaps and edge
  distances are polynomials of degree <= 14 on a step, certified positive by their
  Chebyshev coefficients or searched for their first crossing
  (``tailbeam.solvers.numerics.chebyshev``), so a grazing approach and retreat inside one step
  is not missed;
* the rows whose events were applied at the time t a call returns at are carried into the
  next call from t (``KernelIO.fresh_rows``, ``set_fresh``): one found crossing again right
  at t while back on its side just after is searched again (``kernel.advance``);
* SETTLE is checked at accepted step ends only: a ball whose only touching pair is the plate
  and whose normal excess energy over the static state (``pairs.settle_excess``)
  falls below its settle energy;
* a growing buffer of plate force rows (t, pair, F): every accepted step end, ``nodes_per_step``
  equally spaced interior points of each step (dense output), contact start and end (the end
  row repeats the time of the last step end); and a log of the kinks (t, ``EventCode``,
  pair).

Optional modal plate (two-way): m mass-normalised modes (omega, zeta), state q, q' after the
balls; each plate pair has the mode shapes phi (m,) at its contact point (fixed per contact,
given by the caller); the plate under the ball deflects by w = phi . q, the penetration is
r - (z - w), the ball's force F (+z) loads the modes with -phi F; constant dead loads f_dead
(m,) on the modes. The plate gap z - w is still a polynomial on a step, so events are located
as on the rigid plate. Residual flexibility (optional): each plate pair may have the static
compliance C (m/N) of the truncated modes at its contact point in series with the contact
(``compliance``, ``Model.set_compliance``; ``pairs.plate_force_with_residual``). Without
modes (and C = 0) every result is bit-for-bit the rigid plate's.

``ActiveSet`` holds the state and composes its parts, each passed to the kernel as it takes
them: ``model.Model`` (balls, pairs, laws, plate, modes), ``contact_states.ContactStates``
(per-pair region flags and accumulators), ``tolerances.Tolerances`` and ``kernel_io.KernelIO``
(force rows, kink log, integer outputs, fresh rows).

Everything in the plate frame (x downhill, z the plate normal, surface z = 0), SI units.
Cost per step: O(balls + pairs watched). The first call compiles the kernel (cached on disk).
"""

import functools

import numpy as np

from tailbeam.physics.contact_law import LAW_E, LAW_K
from tailbeam.physics.contacts import PLATE, ContactTable, LawOptions
from tailbeam.solvers.numerics.chebyshev import tables as cheb_tables
from tailbeam.solvers.numerics.dop853 import dop853_tables
from tailbeam.solvers.stream.active.compiled import kernel as ak
from tailbeam.solvers.stream.active.compiled.friction import pair_friction, spin_offset
from tailbeam.solvers.stream.active.compiled.pairs import (
    GONE,
    L_CRES,
    contact_energies,
    pair_force,
    pair_state,
    plate_contact_energy,
)
from tailbeam.solvers.stream.active.integrator.contact_states import ContactStates
from tailbeam.solvers.stream.active.integrator.kernel_io import KernelIO, Outcome
from tailbeam.solvers.stream.active.integrator.modal_block import ModalBlock
from tailbeam.solvers.stream.active.integrator.model import Model
from tailbeam.solvers.stream.active.integrator.tolerances import Tolerances

DEFAULT_NODES = 40  # interior force rows per step: linear interpolation < 1e-5 of the peak


def pair_laws(balls, pairs, plate_material, **options):
    """Laws of ``pairs`` ((i, j), j = -1 the plate) of ``balls`` (tailbeam.Ball): their rows
    of the balls' contact table (``tailbeam.physics.contacts``) with the IMPACT ``options``
    (exponent, damping, penetration, clamp)."""
    table = ContactTable.from_settings(balls, plate_material, LawOptions(**options))
    return [table.law(i, PLATE if j < 0 else j) for i, j in pairs]


@functools.cache
def method_tables() -> tuple:
    """The kernel's constant tables, shared by every set: DOP853 (A, B, E3, E5, D), the 15
    Chebyshev step fractions and the inverse Chebyshev-Vandermonde matrix."""
    a, b, _, e3, e5, d = dop853_tables()
    pts, vinv = cheb_tables()
    return (a, b, e3, e5, d), pts, vinv


class ActiveSet:
    """n balls and P watched pairs, advanced by the compiled kernel.

    The one object the driver and the tests talk to. It holds the state (``y`` and its views)
    and the step suggested to the next call, and composes its parts: what is integrated
    (``model``), the pairs' contact state (``contacts``), the error control (``tol``) and the
    kernel's buffers (``io``).

    Parameters
    ----------
    x, v : array_like, shape (n, 3)
        Positions (m) and velocities (m/s) of the balls.
    mass, radius : array_like, shape (n,)
        kg, m.
    pairs : array_like, shape (P, 2)
        Ball indices of the watched pairs (j = -1: the plate).
    laws : sequence of ImpactLaw or ndarray, shape (P, LAW_COLUMNS)
        The pairs' laws, or their ``law_table``.
    gravity : array_like, shape (3,)
        m/s^2, in the plate frame.
    half_sizes : array_like, shape (2,)
        a/2, b/2 of the plate (m).
    settle_energy : array_like, shape (n,), optional
        J below which a ball's plate contact settles (0 = never, the default).
    rtol : float
        Relative tolerance.
    atol_x, atol_v : float, optional
        Absolute tolerances of positions (m) and velocities (m/s); default rtol x 1 mm,
        rtol x 1 m/s, as the reference.
    max_steps : int
        Accepted steps allowed per ``advance`` call.
    nodes_per_step : int
        Interior force rows per step.
    row_capacity, log_capacity : int
        Initial sizes of the force-row and kink buffers (grown as needed).
    omega, zeta : array_like, shape (m,), optional
        Modal plate: frequencies (rad/s) and damping ratios of all m modes.
    q, qd : array_like, shape (m,), optional
        Initial modal state (m sqrt(kg), m sqrt(kg)/s; default 0).
    phi : array_like, shape (P, m), optional
        Mode shapes at each pair's contact point (1/sqrt(kg); rows of ball-ball pairs
        ignored; ``model.set_phi`` changes a row for a new contact).
    f_dead : array_like, shape (m,), optional
        Constant modal forces (N/sqrt(kg)): balls resting quasi-statically elsewhere.
    atol_q, atol_qd : float, optional
        Absolute tolerances of the modes (``Tolerances.build``; pass them when phi is only
        set later).
    compliance : array_like, shape (P,), optional
        Residual compliance (m/N) of each plate pair (default 0; entries of ball-ball pairs
        ignored; ``model.set_compliance`` changes one).
    friction : array_like, shape (P, F_COLUMNS), optional
        The pairs' friction table (``compiled.friction``; rigid plate): the state then holds
        the balls' angular velocities after the modal block. None: frictionless.
    w : array_like, shape (n, 3), optional
        With friction: the balls' angular velocities (rad/s; default 0).

    Attributes
    ----------
    y : ndarray, shape (6 n + 2 m,) (+ 3 n with friction)
        The state (in/out): positions, velocities, modal coordinates, their rates (and the
        angular velocities).
    x, v : ndarray, shape (n, 3)
        Views of the positions (m) and velocities (m/s) in ``y``.
    q, qd : ndarray, shape (m,)
        Views of the modal state in ``y``.
    w : ndarray, shape (n, 3) (with friction) or (0, 3)
        View of the angular velocities (rad/s) in ``y``.
    model : Model
        Balls, pairs, laws, plate and modes (``alive``: balls still integrated).
    contacts : ContactStates
        Per pair (in/out): touching, ramp, clamped, peak (N), t_peak (s), pen (m).
    tol : Tolerances
        rtol and the absolute tolerance of each state component.
    io : KernelIO
        Force rows, kink log, work counters and the fresh rows carried between calls.
    h : float
        The first step (s) of the next call (0: none suggested yet).

    Notes
    -----
    Pairs overlapping at construction start touching (``open_overlapping``, region from the
    state, accumulators reset): overwrite their ``contacts`` to carry a contact over from another
    set. After a START the next call's first step is the small start-up step (``h``; pass it
    on as ``h`` if the set is rebuilt). START/END leave the pair's accumulators (peak,
    t_peak, pen) for the caller to read. After a LEAVE call ``remove_ball``.
    """

    def __init__(self, x, v, mass, radius, pairs, laws, gravity, half_sizes, *,
                 settle_energy=None, rtol=1e-10, atol_x=None, atol_v=None, max_steps=100_000,
                 nodes_per_step=DEFAULT_NODES, row_capacity=4096, log_capacity=256,
                 omega=None, zeta=None, q=None, qd=None, phi=None, f_dead=None, atol_q=None,
                 atol_qd=None, compliance=None, friction=None, w=None):  # fmt: skip
        x = np.asarray(x, dtype=float).reshape(-1, 3)
        n = x.shape[0]
        modes = ModalBlock.build(np.asarray(pairs).reshape(-1, 2).shape[0], omega, zeta, q, qd,
                                 phi, f_dead)  # fmt: skip
        nm = modes.omega.shape[0]
        spins = [] if friction is None else [np.zeros(3 * n) if w is None else np.ravel(w)]
        self.y = np.concatenate(
            [x.ravel(), np.asarray(v, dtype=float).reshape(n, 3).ravel(), modes.q, modes.qd,
             *spins]
        )  # fmt: skip
        self.x = self.y[: 3 * n].reshape(n, 3)
        self.v = self.y[3 * n : 6 * n].reshape(n, 3)
        self.q = self.y[6 * n : 6 * n + nm]
        self.qd = self.y[6 * n + nm : 6 * n + 2 * nm]
        self.w = self.y[6 * n + 2 * nm :].reshape(-1, 3)  # (0, 3) without friction
        self.model = Model(n, mass, radius, pairs, laws, gravity, half_sizes, settle_energy,
                           compliance, modes, friction)  # fmt: skip
        self.tol = Tolerances.build(rtol, n, modes.phi, atol_x, atol_v, atol_q, atol_qd,
                                    self.model.radius if spins else None)  # fmt: skip
        self.io = KernelIO(max_steps, nodes_per_step, row_capacity, log_capacity)
        self.contacts = ContactStates(len(self.model.pi))
        self.h = 0.0
        self.open_overlapping()

    @classmethod
    def from_balls(cls, balls, pairs, incline, *, damping=0.0, penetration=1e-4, clamp=True,
                   exponent=1.5, **kwargs):  # fmt: skip
        """From ``tailbeam.Ball``s (plate-frame positions, velocities) on an ``InclinedPlate``;
        laws from ``contact_law`` with the given IMPACT parameters."""
        options = dict(damping=damping, penetration=penetration, clamp=clamp, exponent=exponent)
        laws = pair_laws(balls, pairs, incline.plate.material, **options)
        return cls(
            [b.position for b in balls], [b.velocity for b in balls],
            [b.mass for b in balls], [b.radius for b in balls], pairs, laws,
            incline.gravity_vector, incline.half_sizes, **kwargs,
        )  # fmt: skip

    # --- state -----------------------------------------------------------------------------
    def penetration(self, p: int) -> tuple[float, float]:
        """(delta m, rate m/s) of pair p now."""
        m = self.model
        d, rate, _, _, _ = pair_state(self.y, len(m.mass), m.pi[p], m.pj[p], m.rsum[p], m.phi,
                                      p)  # fmt: skip
        return float(d), float(rate)

    def contact_energy(self, p: int) -> float:
        """Elastic energy (J) of pair p now (0 when not touching; a plate pair's includes its
        residual spring's C F^2 / 2)."""
        if not self.contacts.touching[p]:
            return 0.0
        delta, _ = self.penetration(p)
        law = self.model.law
        k, e, cres = law[p, LAW_K], law[p, LAW_E], law[p, L_CRES]
        return float(plate_contact_energy(delta, k, e, cres if self.model.pj[p] < 0 else 0.0))

    def contact_loads(self, p: int) -> tuple:
        """Pair p's loads now (touching): (force (3,) N and torque (3,) N m about its centre
        on ball i, the same on ball j, or on the plate) in the plate frame: the normal force
        of its law and, with friction, its friction force and rolling torque."""
        m = self.model
        n, i, j = len(m.mass), int(m.pi[p]), int(m.pj[p])
        c = self.contacts
        f, _, nx, ny, nz = pair_force(self.y, n, p, m.pi, m.pj, m.law, m.rsum, c.ramp, c.clamped,
                                      m.phi, m.mass, m.g, m.omega, m.zeta, m.f_dead)  # fmt: skip
        normal = f * np.array([nx, ny, nz])
        force_i, torque_i, torque_j = normal.copy(), np.zeros(3), np.zeros(3)
        if m.friction:
            off = spin_offset(n, m.omega.shape[0])
            r = pair_friction(self.y, n, off, i, j, p, nx, ny, nz, f, m.fric)
            force_i += np.array(r[0:3])
            torque_i, torque_j = np.array(r[3:6]), np.array(r[6:9])
        return force_i, torque_i, -force_i, torque_j

    def contact_energies(self) -> np.ndarray:
        """Elastic energy (J, (P,)) of every pair now: ``contact_energy`` of each."""
        m = self.model
        out = np.zeros(len(m.pi))
        contact_energies(self.y, len(m.mass), m.pi, m.pj, m.rsum, m.phi, m.law,
                         self.contacts.touching, out)  # fmt: skip
        return out

    def modal_energy(self) -> float:
        """Kinetic + strain energy of the modes now, J: 1/2 (q'^2 + omega^2 q^2) summed."""
        return float(0.5 * np.sum(self.qd**2 + (self.model.omega * self.q) ** 2))

    def open_overlapping(self):
        """Pairs overlapping now start touching, in their region (a ball placed at its static
        penetration), as ``tailbeam.solvers.stream.reference``'s ``touch``."""
        m, c = self.model, self.contacts
        for p in range(len(m.pi)):
            if c.touching[p] or not m.alive[m.pi[p]]:
                continue
            delta, rate = self.penetration(p)
            if delta > 0.0:
                c.open(p, delta, rate, m.law[p])

    def remove_ball(self, b: int):
        """Stop integrating ball b (after a leave): its touching pairs end."""
        m = self.model
        m.alive[b] = GONE
        self.contacts.touching[(m.pi == b) | (m.pj == b)] = False
        for p in np.flatnonzero((m.pi == b) | (m.pj == b)):
            self.io.forget_fresh(int(p))

    # --- integration -----------------------------------------------------------------------
    def advance(self, t0: float, t_stop: float, h: float | None = None) -> Outcome:
        """Integrate from t0 until the first returning event or t_stop; see the module
        docstring.

        Parameters
        ----------
        t0, t_stop : float
            Start and end (s).
        h : float, optional
            First step (s; default: the step suggested by the previous call, or 1e-5 s).

        Returns
        -------
        Outcome
            The event returned at, or ``EventCode.NONE`` at t_stop.

        Notes
        -----
        Grows the force-row and log buffers as needed. A call that starts at the time the
        previous one returned at carries the rows whose events were applied then
        (``io.fresh_rows``): one whose crossing sits on 0 there is not applied again at once
        (``kernel.advance``).
        """
        io, tol = self.io, self.tol
        tio = np.array([float(t0), float(h or self.h or 1e-5)])
        io.begin(tio[0])
        tab, pts, vinv = method_tables()
        while True:
            io.iout[ak.IO_STATUS] = -1
            ak.advance(
                tio, self.y, float(t_stop), tol.rtol, tol.atol, io.max_steps, io.nodes,
                self.model.arrays(), self.contacts.arrays(), tab, pts, vinv, io.rows, io.log,
                io.iout, io.fresh,
            )  # fmt: skip
            if not io.buffer_full():
                break
            io.grow(len(self.model.pi))
        self.h = float(tio[1])
        return io.outcome(float(tio[0]))

    def snapshot(self) -> tuple:
        """What ``advance`` changes (state, contact states, integer outputs and counters,
        fresh rows, next step), for ``restore``: a call undone (an island of the driver's
        active set advanced past another island's event, ``islands``)."""
        io = self.io
        return (self.y.copy(), tuple(a.copy() for a in self.contacts.arrays()),
                io.iout.copy(), io.fresh.copy(), io.t_fresh, self.h)  # fmt: skip

    def restore(self, snap) -> None:
        """Put back what ``snapshot`` kept (in place: the views of ``y`` stay valid; the
        force rows and kinks written since are dropped with the counts in ``iout``)."""
        y, contacts, iout, fresh, t_fresh, h = snap
        self.y[:] = y
        for a, b in zip(self.contacts.arrays(), contacts, strict=True):
            a[...] = b
        self.io.iout[:] = iout
        self.io.fresh[:] = fresh
        self.io.t_fresh, self.h = t_fresh, h

    # --- the results of the calls so far (kept in ``io``) ----------------------------------
    def force_rows(self) -> np.ndarray:
        """(R, 3) rows (t s, pair, F N) of the plate forces written so far."""
        return self.io.force_rows()

    def kink_log(self) -> list:
        """(t s, ``EventKind``, pair) of the kinks handled inside so far."""
        return self.io.kink_log()

    def clear_outputs(self, rows: bool = True):
        """Forget the kink log and (``rows``) the force rows: the caller has consumed them.
        Rows kept stay in the buffer for a later call's rows to follow them (``restore``
        keeps those written before its ``snapshot``)."""
        self.io.clear_outputs(rows)

    @property
    def stats(self) -> dict:
        """Accepted steps, attempted steps, right-hand-side evaluations and events found
        again at the instant they were applied (``KernelIO.stats``)."""
        return self.io.stats
