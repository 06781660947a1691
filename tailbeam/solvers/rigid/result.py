"""What a rigid-plate simulation returns: the impact table, the events and exact states.

A ``tailbeam.results.result.Result`` (the common interface: impacts_table, particles_table,
events_of, time_grid, ...): ``impacts`` and ``events`` are the located events,
``sample(times)`` evaluates the stored piecewise solution (closed form in flight, dense output
in contact) at any times, ``nfev``/``n_steps`` count the work, ``status``/``message`` report
how it ended.
"""

from dataclasses import dataclass, field

from tailbeam.results.records import EventKind, Impact  # noqa: F401 - Impact: its old home
from tailbeam.results.result import BallsResult

EVENT_KINDS = (EventKind.CONTACT_START, EventKind.FULL_DAMPING, EventKind.CLAMP_ON,
               EventKind.CLAMP_OFF, EventKind.CONTACT_END, EventKind.REST)  # fmt: skip


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
