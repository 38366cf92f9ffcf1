"""The page on the operator's computer: the robot's state and commands through
``hubo-bridge``.

A `daemon.remote.operator.BridgeOperator` (a zenoh client with the operator's
certificate) carries both ways:

- state: each sample the robot bridge publishes (``--rate-hz`` there), stamped with its
  arrival on this computer's clock, since the robot's clock is not ours. The ``ref``
  channel does not come back, so the page shows no reference mode;
- commands: the bridge's command topics (``cmd/console``, ``cmd/neck``,
  ``cmd/player``). The robot side runs each through its local tool and answers: done
  with the tool's text, or refused with the tool's reason, which the page shows as it
  shows a local refusal. The bridge refuses ``goto``, ``comp`` and ``status`` over the
  network (`daemon.remote.robot`), and drops a command sent on too old a state
  (``stale``). A certificate the robot does not list as a writer gets no answer.

zenoh is imported when the link opens, not when this module is.
"""

from __future__ import annotations

import threading
import time

import numpy as np

from daemon.player_control import PlayerCommand
from daemon.remote.keys import Topic
from daemon.remote.operator import BridgeOperator, RemoteRefusal
from daemon.remote.robot import RATE_RANGE_HZ
from daemon.remote.session_config import TlsFiles
from daemon.station.link import StateReading, StationLink
from robot.errors import InputError

__all__ = ["BridgeLink"]

#: The robot bridge publishes at 1 Hz at the slowest; a sample older than one such period
#: and a link allowance means nothing is arriving [s].
STALE_AFTER_S = 1.0 / RATE_RANGE_HZ[0] + 0.5


class BridgeLink(StationLink):
    """Robot daemon ``instance`` through the robot bridge at ``connect``.

    Args:
        connect: the robot bridge's endpoint, ``tls/HOST:PORT``.
        tls: this operator's TLS files (its certificate's name must be one of the
            robot's ``--allow-writer`` names for the commands to be answered).
        instance: the daemon instance on the robot.

    Raises:
        InputError: ``connect`` is not ``tls/HOST:PORT``.
        HuboLadderError: zenoh could not connect (no bridge listening, a certificate
            the robot's CA did not sign).
    """

    def __init__(self, connect: str, tls: TlsFiles, instance: str = "default"):
        super().__init__(instance, f"instance {instance!r} through hubo-bridge at {connect}",
                         STALE_AFTER_S, "the link is down, or the robot's daemon or bridge "
                         "stopped")
        self._arrived_lock = threading.Lock()
        self._arrived: StateReading | None = None
        self.operator = BridgeOperator(connect, tls, instance, on_state=self._on_state)

    def _on_state(self, state: np.ndarray) -> None:
        """zenoh's thread: keep the sample with its arrival time."""
        reading = StateReading(state, None, time.monotonic_ns())
        with self._arrived_lock:
            self._arrived = reading

    def read(self) -> StateReading | None:
        with self._arrived_lock:
            return self._arrived

    def _ask(self, topic: Topic, text: str) -> str:
        """The robot's answer to one command; its refusal as the local tool words it."""
        try:
            return self.operator.command(topic, text)
        except RemoteRefusal as exc:
            raise InputError(exc.reason) from None

    def _console(self, line: str) -> str:
        return self._ask(Topic.CONSOLE, line)

    def _neck(self, key: str) -> str:
        return self._ask(Topic.NECK, key)

    def _player(self, command: PlayerCommand) -> str:
        return self._ask(Topic.PLAYER, command.value)

    def close(self) -> None:
        self.operator.close()
