"""What a rigid-plate simulation returns: the impact table, the events and exact states.

A ``tailbeam.result.Result`` (the common interface: impacts_table, particles_table,
events_of, time_grid, ...): ``impacts`` and ``events`` are the located events,
``sample(times)`` evaluates the stored piecewise solution (closed form in flight, dense output
in contact) at any times, ``nfev``/``n_steps`` count the work, ``status``/``message`` report
how it ended.
"""

from dataclasses import dataclass, field

from tailbeam.result import BallsResult
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
class RigidResult(BallsResult):
    """Result of ``simulate_rigid`` (or the reference solver); see the module docstring.

    plate: the ``tailbeam.physics.bodies.Plate`` (for the leave times of ``particles_table``);
    labels: coal / gangue per ball (empty: ``tailbeam.scene.default_label``).
    """

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
    plate: object = None
    labels: tuple = ()

    def _plate(self):
        return self.plate

    def sample(self, times) -> dict:
        """States at ``times`` (s, within [0, duration]): name -> {"z", "vz", "force"} arrays.

        z is the centre height (m), vz the vertical velocity (m/s), force the contact force on
        the ball (N). Exact evaluation of the stored solution; independent of any output rate.
        """
        t = self._times(times)
        out = {}
        for name, traj in self.trajectories.items():
            z, vz, force = traj.sample(t)
            out[name] = {"z": z, "vz": vz, "force": force}
        return out

    def table(self) -> list:
        """The impact table as a list of dicts (one per impact)."""
        return [imp.as_dict() for imp in self.impacts]
