"""The stream driver's time and the run's work counters."""

COUNTERS = (
    "heap_events",  # heap events handled
    "stale",  # heap predictions skipped: their ball's motion changed since
    "set_events",  # events the active set returned
    "set_calls",  # calls of the active set
    "epochs",  # epochs of the broad phase
    "late_starts",  # balls that entered the set already overlapping (must stay 0)
    "postponed_releases",  # particles released later: no free place in their release volume
    "moved_releases",  # particles released at their time at another free place of the volume
)


class Clock:
    """Time (s) the driver has reached and the run's counters (``StreamRun.stats``).

    Parameters
    ----------
    duration : float
        Simulated time (s).
    """

    def __init__(self, duration: float):
        self.t = 0.0
        self.duration = duration
        self.stats = dict.fromkeys(COUNTERS, 0)

    def count(self, key: str, n: int = 1) -> None:
        """Add n to counter ``key`` (created at 0)."""
        self.stats[key] = self.stats.get(key, 0) + n
