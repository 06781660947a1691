"""What a rigid-plate simulation returns: the impact table, the events and exact states.

In the spirit of scipy's OdeResult: ``impacts`` and ``events`` are the located events,
``sample(times)`` evaluates the stored piecewise solution (closed form in flight, dense output
in contact) at any times, ``nfev``/``n_steps`` count the work, ``status``/``message`` report
how it ended.
"""

import math
from dataclasses import dataclass, field

import numpy as np

from tailbeam.errors import InputError, require_positive
from tailbeam.solvers.records import EventKind

EVENT_KINDS = (EventKind.CONTACT_START, EventKind.FULL_DAMPING, EventKind.CLAMP_ON,
               EventKind.CLAMP_OFF, EventKind.CONTACT_END, EventKind.REST)  # fmt: skip


@dataclass(frozen=True)
class Impact:
    """One contact of a ball with the plate (times in s, speeds in m/s, SI throughout).

    v_in/v_out are magnitudes; v_out = 0.0 if the ball did not separate (declared at rest in
    contact) and nan if the simulation ended during the contact. restitution = v_out / v_in
    (nan if v_in = 0 or v_out is nan). next_apex_height: height in m of the ball's lowest point
    above the plate at the apex of the following flight (nan if there is none).
    """

    ball: str
    index: int
    t_start: float
    t_end: float
    v_in: float
    v_out: float
    restitution: float
    peak_force: float
    t_peak: float
    max_penetration: float
    next_apex_height: float
    ends_at_rest: bool

    def as_dict(self) -> dict:
        return {name: getattr(self, name) for name in self.__dataclass_fields__}


@dataclass
class RigidResult:
    """Result of ``simulate_rigid`` (or the reference solver); see the module docstring."""

    balls: tuple
    laws: tuple
    duration: float
    gravity: float
    impacts: list
    events: list
    rest_time: dict
    trajectories: dict = field(repr=False)
    nfev: int = 0
    n_steps: int = 0
    status: int = 0
    message: str = ""
    info: dict = field(default_factory=dict)

    def impacts_of(self, name: str) -> list:
        """Impacts of the ball called ``name``, in time order."""
        if name not in self.trajectories:
            raise InputError("name", f"no ball called {name!r}; balls: {list(self.trajectories)}")
        return [imp for imp in self.impacts if imp.ball == name]

    def events_of(self, name: str, kind: str | None = None) -> list:
        """(t, kind) of the ball's events, optionally only those of ``kind``."""
        return [(t, k) for t, b, k in self.events if b == name and (kind is None or k == kind)]

    def sample(self, times) -> dict:
        """States at ``times`` (s, within [0, duration]): name -> {"z", "vz", "force"} arrays.

        z is the centre height (m), vz the vertical velocity (m/s), force the contact force on
        the ball (N). Exact evaluation of the stored solution; independent of any output rate.
        """
        t = np.atleast_1d(np.asarray(times, dtype=float))
        if t.ndim != 1:
            raise InputError("times", "must be a 1-D array of times in s")
        if not np.all(np.isfinite(t)):
            raise InputError("times", "must be finite")
        if t.size and (t.min() < 0.0 or t.max() > self.duration):
            raise InputError("times", f"must lie within [0, duration = {self.duration!r}] s")
        out = {}
        for name, traj in self.trajectories.items():
            z, vz, force = traj.sample(t)
            out[name] = {"z": z, "vz": vz, "force": force}
        return out

    def time_grid(self, sample_rate: float) -> np.ndarray:
        """Uniform times at ``sample_rate`` (Hz) on [0, duration] merged with every t_peak."""
        rate = require_positive("sample_rate", sample_rate)
        n = int(math.floor(self.duration * rate * (1.0 + 1e-12))) + 1
        grid = np.arange(n, dtype=float) / rate
        peaks = [imp.t_peak for imp in self.impacts if 0.0 <= imp.t_peak <= self.duration]
        return np.unique(np.concatenate([grid[grid <= self.duration], np.asarray(peaks)]))

    def table(self) -> list:
        """The impact table as a list of dicts (one per impact)."""
        return [imp.as_dict() for imp in self.impacts]
