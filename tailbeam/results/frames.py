"""The balls' positions and velocities at a few frame times: the ``frames`` part of a Result.

A run asked for frames (``tailbeam.simulate(scene, frames=times)``) keeps, for every frame
time and every body, the centre's position (m) and velocity (m/s) in the plate frame; nan
where the body is not on the plate (not released yet, or gone over an edge). Memory is
frames x bodies x 6 floats, bounded by the caller (``frame_bytes``), never steps x bodies.

The stream solver records them as it runs (it stops its integration at each frame time);
the single-ball solvers, which keep each ball's whole solution, sample it
(``BallFrames.from_states``).
"""

import math
from dataclasses import dataclass, field

import numpy as np

from tailbeam.errors import InputError

BYTES_PER_VALUE = 8.0


def frame_bytes(n_frames: int, n_bodies: int) -> float:
    """Bytes (float64) the frames of ``n_bodies`` bodies at ``n_frames`` times keep."""
    return BYTES_PER_VALUE * 6.0 * n_frames * n_bodies


def check_frame_times(times, duration: float, field_name: str = "frames") -> tuple:
    """``times`` (s) as a tuple of increasing finite floats in [0, duration]; InputError
    naming ``field_name`` otherwise."""
    t = np.atleast_1d(np.asarray(times, dtype=float))
    bad = (
        t.ndim != 1
        or t.size == 0
        or not np.all(np.isfinite(t))
        or np.any(np.diff(t) <= 0.0)
        or t[0] < 0.0
        or t[-1] > duration * (1.0 + 1e-12)
    )
    if bad:
        raise InputError(
            field_name, f"must be increasing finite times (s) within [0, {duration!r}] s"
        )
    return tuple(float(v) for v in t)


@dataclass(frozen=True, eq=False)
class BallFrames:
    """Every body's state at the frame times (plate frame; nan where it is not on the plate).

    Parameters
    ----------
    times : (F,) array
        Frame times, s.
    position : (F, n, 3) array
        Centre positions, m, bodies in the order of ``Result.particles``.
    velocity : (F, n, 3) array
        Centre velocities, m/s.
    """

    times: np.ndarray
    position: np.ndarray = field(repr=False)
    velocity: np.ndarray = field(repr=False)

    @classmethod
    def empty(cls, times, n_bodies: int) -> "BallFrames":
        """Frames at ``times`` with every body absent (nan), to be filled."""
        t = np.asarray(times, dtype=float)
        shape = (len(t), n_bodies, 3)
        return cls(t, np.full(shape, math.nan), np.full(shape, math.nan))

    def present(self, k: int) -> np.ndarray:
        """Indices of the bodies on the plate at frame ``k``."""
        return np.flatnonzero(np.isfinite(self.position[k, :, 0]))

    @classmethod
    def from_states(cls, result, times) -> "BallFrames":
        """Frames of a single-ball result (``result.sample``): the height and vertical speed
        from its solution, the horizontal motion uniform at the release velocity (the
        single-ball solvers' horizontal frictionless plate), each ball on the plate from its
        release until it leaves over an edge (``result.leaves``)."""
        frames = cls.empty(times, len(result.particles))
        states = result.sample(frames.times)
        leave = {e.ball: e.time for e in result.leaves}
        t = frames.times
        for b, p in enumerate(result.particles):
            s = states[p.name]
            dt = t - p.t_release
            on = (dt >= 0.0) & (t < leave.get(p.name, math.inf))
            x0, v0 = np.asarray(p.position, dtype=float), np.asarray(p.velocity, dtype=float)
            frames.position[on, b, 0] = x0[0] + v0[0] * dt[on]
            frames.position[on, b, 1] = x0[1] + v0[1] * dt[on]
            frames.position[on, b, 2] = s["z"][on]
            frames.velocity[on, b, :2] = v0[:2]
            frames.velocity[on, b, 2] = s["vz"][on]
        return frames
