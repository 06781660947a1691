"""simulate_rigid: balls on a rigid plate, fast (compiled contact integrator, closed-form flight).

Flights between contacts are ballistic (closed form; contact start from a cancellation-free
quadratic root, model.time_to_contact). Each contact is integrated by the numba DOP853 kernel
(kernel.py) with every kink of the IMPACT law located as an event and the peak force and
maximum penetration located on the dense output. The event queue over contact pairs is in
driver.py. Work is bounded by ``max_contacts`` (per ball) and ``max_steps`` (integrator steps
per ball); the first call compiles the kernel (cached on disk by numba afterwards).
"""

import numpy as np

from tailbeam.errors import WorkLimitError
from tailbeam.physics.bodies import STANDARD_GRAVITY
from tailbeam.results.records import End, EventCode
from tailbeam.solvers.numerics.dop853 import dop853_tables
from tailbeam.solvers.rigid import driver, kernel
from tailbeam.solvers.rigid.model import (
    DEFAULT_MAX_CONTACTS,
    DEFAULT_MAX_STEPS,
    DEFAULT_REST_SPEED,
    check_rtol,
)

_ENDS = {kernel.ST_SEPARATED: End.SEPARATED, kernel.ST_REST: End.REST,
         kernel.ST_DURATION: End.DURATION}  # fmt: skip


def simulate_rigid(
    balls,
    plate,
    laws,
    duration,
    *,
    rtol=1e-10,
    gravity=STANDARD_GRAVITY,
    rest_speed=DEFAULT_REST_SPEED,
    max_contacts=DEFAULT_MAX_CONTACTS,
    max_steps=DEFAULT_MAX_STEPS,
    labels=(),
    info=None,
):
    """Simulate ``balls`` (sequence of Ball) dropping on a rigid ``plate`` (Plate) on
    [0, ``duration``] s; ``laws``: the balls' ``ContactTable`` (``Scene.contacts()``,
    tailbeam.physics.contacts) or one ball-plate ImpactLaw per ball.

    rtol: relative tolerance of the contact integration (errors in peak force, restitution
    and apex height come out near rtol); gravity in m/s^2; rest_speed in m/s (see
    tailbeam.solvers.rigid.model for the rest rules, 0 disables them); max_contacts: contacts per
    ball; max_steps: integrator steps per ball; labels: coal / gangue per ball (empty: from
    the material); info: more entries for ``Result.info``. Returns a ``tailbeam.Result`` whose
    ``states`` are exact at any time.
    """
    rtol = check_rtol(rtol)
    solver = f"tailbeam DOP853 (numba) rtol={rtol:g}, restarted at kinks"
    return driver.simulate_balls(
        balls, plate, laws, duration, _KernelIntegrator(rtol), gravity=gravity,
        rest_speed=rest_speed, max_contacts=max_contacts, max_steps=max_steps, labels=labels,
        info={"solver": solver, **(info or {})},
    )  # fmt: skip


class _KernelIntegrator:
    """Calls the compiled contact kernel. Pieces of all contacts are written one after the
    other into shared buffers (grown by reallocation: earlier contacts keep views of the old
    ones), so a contact costs no copies."""

    def __init__(self, rtol):
        self.rtol = rtol
        self.tables = dop853_tables()
        self._alloc(4096, 512)
        self.res = np.zeros(5)
        self.ires = np.zeros(6, dtype=np.int64)
        self.par = {}

    def _alloc(self, n_pieces, n_events):
        self.p_tau = np.zeros(n_pieces)
        self.p_h = np.zeros(n_pieces)
        self.p_y = np.zeros((n_pieces, 2))
        self.p_coef = np.zeros((n_pieces, 7, 2))
        self.ev_tau = np.zeros(n_events)
        self.ev_kind = np.zeros(n_events, dtype=np.int64)
        self.off_p = self.off_e = 0

    def _params(self, p):
        par = self.par.get(p.name)
        if par is None:
            par = np.array(
                [p.k, p.e, p.c, p.d, float(p.clamp), p.mass, p.gravity, p.e_rest, p.e_trap]
            )
            self.par[p.name] = par
        return par

    def __call__(self, p, v_in, tau_max, steps_left):
        delta_s, v_s, t_s = p.scales(v_in)
        # first step: where the tau^(e+2) term of delta reaches rtol, and within the ramp
        h0 = min(t_s * self.rtol ** (1.0 / (p.e + 2.0)), 0.5 * p.d / v_s)
        while True:
            op, oe = self.off_p, self.off_e
            kernel.integrate_contact(
                self._params(p), v_in, tau_max, self.rtol, self.rtol * delta_s,
                self.rtol * v_s, h0, t_s, steps_left, *self.tables,
                self.p_tau[op:], self.p_h[op:], self.p_y[op:], self.p_coef[op:],
                self.ev_tau[oe:], self.ev_kind[oe:], self.res, self.ires,
            )  # fmt: skip
            status = int(self.ires[0])
            if status != kernel.ST_BUFFER_FULL:
                break
            self._alloc(4 * self.p_tau.size, 4 * self.ev_tau.size)
        if status == kernel.ST_STEP_LIMIT:
            raise WorkLimitError(
                f"ball {p.name!r}: the contact integration reached max_steps (integrator steps "
                "per ball); raise max_steps, or shorten duration"
            )
        if status == kernel.ST_STEP_TINY:
            raise RuntimeError(f"ball {p.name!r}: contact step size underflow (please report)")
        n, m = int(self.ires[1]), int(self.ires[2])
        self.off_p, self.off_e = op + n, oe + m
        tau_end, v_out, peak, tau_peak, pen = self.res.tolist()
        tau_start = self.p_tau[op : op + n]
        return driver.ContactOutcome(
            status=_ENDS[status],
            tau_end=tau_end,
            v_out=v_out,
            peak_force=peak,
            tau_peak=tau_peak,
            max_penetration=pen,
            events=[
                (t, EventCode(k).kind)
                for t, k in zip(
                    self.ev_tau[oe : oe + m].tolist(),
                    self.ev_kind[oe : oe + m].tolist(),
                    strict=True,
                )
            ],
            tau_start=tau_start,
            tau_old=tau_start,
            step=self.p_h[op : op + n],
            y_old=self.p_y[op : op + n],
            coef=self.p_coef[op : op + n],
            nfev=int(self.ires[3]),
            n_steps=int(self.ires[4]),
        )
