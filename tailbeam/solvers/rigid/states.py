"""The balls' states of a rigid-plate run at any time: the ``states`` part of its Result."""

from dataclasses import dataclass


@dataclass(frozen=True)
class RigidStates:
    """Each ball's stored piecewise solution (closed form in flight, the integrator's dense
    output in contact, ``tailbeam.solvers.rigid.trajectory.Trajectory``), evaluated exactly at
    any times, and when each ball came to rest.

    Parameters
    ----------
    trajectories : dict
        Ball name -> its ``Trajectory``.
    rest_time : dict
        Ball name -> time (s) it came to rest on the plate, nan if it did not.
    """

    trajectories: dict
    rest_time: dict

    def sample(self, times) -> dict:
        """States at ``times`` (s): name -> {"z" centre height m, "vz" vertical velocity m/s,
        "force" contact force on the ball N} arrays; independent of any output rate."""
        out = {}
        for name, traj in self.trajectories.items():
            z, vz, force = traj.sample(times)
            out[name] = {"z": z, "vz": vz, "force": force}
        return out
