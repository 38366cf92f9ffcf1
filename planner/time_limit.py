"""A hard wall-clock limit around a planning run.

The search checks its own time limit only between samples, and one sample can take
seconds; this raises `TimeLimitExceeded` from the alarm signal when the limit (plus a
grace) is over. It only works in a process's main thread (the CLI, process-pool workers);
elsewhere (Dask worker threads) the search's own check is all there is.
"""

from __future__ import annotations

import contextlib
import signal
import threading

from robot.errors import HuboLadderError

#: Planning is stopped this long after its time limit when the search overruns it [s].
HARD_LIMIT_GRACE_S = 0.5


class TimeLimitExceeded(HuboLadderError):
    """Raised by the alarm signal when the planning time is over.

    Attributes:
        limit_s: the wall-clock limit that ran out (the planning limit plus the grace) [s].
    """

    def __init__(self, limit_s: float):
        super().__init__(f"planning stopped after its hard time limit of {limit_s:g} s")
        self.limit_s = limit_s


@contextlib.contextmanager
def hard_time_limit(seconds: float):
    """Raise `TimeLimitExceeded` in the main thread after ``seconds`` (no-op elsewhere)."""
    if threading.current_thread() is not threading.main_thread() or \
            not hasattr(signal, "setitimer"):
        yield
        return

    def on_alarm(signum, frame):
        raise TimeLimitExceeded(seconds)

    previous = signal.signal(signal.SIGALRM, on_alarm)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
