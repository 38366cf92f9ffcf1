"""Ach's push and pull: the robot's channels mirrored on the operator's computer.

`Mirror` makes a local daemon instance on the operator's computer look like the robot's:

- pull: each ``state`` sample from the robot is written into the local ``state``
  channel, so ``hubo-read``, ``hubo-console status`` and ``play-trajectory`` (which reads
  the state) see the robot;
- push: each ``ref`` sample written into the local ``ref`` channel after the mirror
  started (by ``play-trajectory``, say) is sent to the robot once, as it is written.

Nothing is repeated: when the local player stops, or the link drops, the robot's ``ref``
channel ages and its daemon's watchdog holds. Local state samples are stamped on the
operator's clock when written; their ``tick`` and ``time_s`` are the robot's.
"""

from __future__ import annotations

import logging
import threading
import time

import numpy as np

from daemon.remote.operator import BridgeOperator
from robot.errors import HuboLadderError

__all__ = ["Mirror"]

log = logging.getLogger(__name__)


class Mirror:
    """Mirror a robot bridge's channels into local daemon instance ``local_instance``.

    Args:
        operator_factory: opens the `BridgeOperator` given its ``on_state`` callback.
        local_instance: the local channels' instance name.
    """

    def __init__(self, operator_factory, local_instance: str):
        from daemon.channels import open_channel

        self.refs_sent = 0
        self.refs_unsent = 0  # written locally before the robot's first state
        self._state = open_channel("state", local_instance)
        self._ref = open_channel("ref", local_instance)
        self._lock = threading.Lock()
        try:
            self.operator: BridgeOperator = operator_factory(self._write_state)
        except BaseException:
            self._state.close()
            self._ref.close()
            raise

    def _write_state(self, state: np.ndarray) -> None:
        with self._lock:
            self._state.write(state)

    def run(self, stop: threading.Event | None = None, duration_s: float | None = None) -> None:
        """Forward local ``ref`` samples until ``stop`` is set or ``duration_s`` passed."""
        end = None if duration_s is None else time.monotonic() + duration_s
        last_ns = time.monotonic_ns()  # samples from before the start are never sent
        while not (stop is not None and stop.is_set()):
            if end is not None and time.monotonic() >= end:
                break
            s = self._ref.wait_newer(last_ns, 0.1)
            if s is None:
                continue
            last_ns = int(s["time_ns"])
            try:
                self.operator.send_ref(s)
            except HuboLadderError as exc:
                if self.refs_unsent == 0:
                    log.warning("ref not sent: %s", exc)
                self.refs_unsent += 1
            else:
                self.refs_sent += 1

    def close(self) -> None:
        self.operator.close()
        self._state.close()
        self._ref.close()
