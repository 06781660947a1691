"""The stream driver's frames: every ball's state at the frame times asked of a run.

The loop stops at each frame time as at an event (``next_time``), so the active set is
integrated exactly up to it, then ``take`` records every ball on the plate: the closed-form
balls from their motion, the active set's members from its state. Memory: frames x balls x 6
floats (``tailbeam.results.frames.BallFrames``).
"""

import math

import numpy as np

from tailbeam.results.frames import BallFrames
from tailbeam.solvers.stream.driver.balls import GONE, PENDING


class FrameRecorder:
    """Records ``BallFrames`` at ``times`` (s, increasing; empty: records nothing).

    Parameters
    ----------
    times : sequence of float
        The frame times, s.
    balls : Balls
        The stream's balls.
    act : ActiveMembers
        The active set (the states of its members).
    """

    def __init__(self, times, balls, act):
        self.frames = BallFrames.empty(np.asarray(times, dtype=float), len(balls.names))
        self.balls, self.act, self.k = balls, act, 0

    @property
    def next_time(self) -> float:
        """The next frame time not yet recorded, s (inf after the last)."""
        t = self.frames.times
        return float(t[self.k]) if self.k < len(t) else math.inf

    def take(self, t: float) -> None:
        """Record the frame due at ``t`` (s), the loop's time, if one is."""
        if t < self.next_time:
            return
        b, act, k = self.balls, self.act, self.k
        for i in np.flatnonzero((b.status != GONE) & (b.status != PENDING)):
            i = int(i)
            x, v = act.state(i) if b.in_set[i] else b.state(i, t)
            self.frames.position[k, i], self.frames.velocity[k, i] = x, v
        self.k += 1
