"""What the page talks to: a state source and a command sink, the same for a daemon on this
computer and for a robot behind ``hubo-bridge``.

The page (`daemon.station.page`) has one code path. It reads `StateReading`\\ s and calls
the named commands of a `StationLink`; two implementations carry them:

- `daemon.station.local_link.LocalLink`: the daemon's shared-memory channels, and the
  local tools' code (`daemon.console.Console`, `daemon.neck.press`,
  `daemon.player_control`);
- `daemon.station.bridge_link.BridgeLink`: a `daemon.remote.operator.BridgeOperator`,
  whose commands the robot side runs through the same local tools and answers.

Each command returns an `Outcome`: done with the tool's text, or refused with its reason.
Nothing is checked here, so the page refuses exactly what the tools refuse, with their
words. Commands run one at a time (a lock), as in a terminal; each blocks until the
daemon (or the robot's bridge) has answered, at most a few seconds, so the page runs them
in a worker thread.
"""

from __future__ import annotations

import abc
import threading
import time
from typing import NamedTuple

import numpy as np

from daemon.player_control import PlayerCommand
from robot.errors import HuboLadderError, InputError

__all__ = ["Outcome", "StateReading", "StationLink"]


class Outcome(NamedTuple):
    """The result of one command: ``ok`` False when refused or unanswered; ``text`` what
    was done, or the refusal with its reason."""

    command: str
    ok: bool
    text: str

    def line(self) -> str:
        """One line for the page's log."""
        return f"{self.command}: {self.text}" if self.ok else \
            f"{self.command} REFUSED: {self.text}"


class StateReading(NamedTuple):
    """The newest state sample as the page's process has it.

    Attributes:
        state: a ``state`` channel sample (the daemon's struct).
        ref_mode: the ``mode`` array (`daemon.control_modes.RefMode` per joint) of the
            newest ``ref`` sample the daemon follows; None when there is none (the daemon
            holds) or when it is not known here (the bridge carries no ``ref`` channel
            back).
        received_ns: when the sample reached this process, on its ``CLOCK_MONOTONIC``
            [ns]. Shared memory: the write's own stamp. Through the bridge: the arrival,
            because the robot's clock is not this computer's.
    """

    state: np.ndarray
    ref_mode: np.ndarray | None
    received_ns: int

    def age_s(self) -> float:
        """How long ago the sample reached this process [s]."""
        return (time.monotonic_ns() - self.received_ns) / 1e9


class StationLink(abc.ABC):
    """A state source and a command sink for the page (see the module docstring).

    Subclasses give `read`, the three kinds of command (`_console`, `_neck`, `_player`,
    each returning the text of a done command or raising the tool's refusal) and `close`;
    the named commands of the page's buttons are built here once, on those three.

    Attributes:
        instance: the daemon's instance (channel namespace; on the robot, through the
            bridge).
        where: what the page's title and its "no state" line call the daemon.
        stale_after_s: a sample that reached this process longer ago than this means
            nothing is arriving [s].
        silent_means: what the page says is the likely cause when nothing arrives.
    """

    def __init__(self, instance: str, where: str, stale_after_s: float, silent_means: str):
        self.instance = instance
        self.where = where
        self.stale_after_s = stale_after_s
        self.silent_means = silent_means
        self._lock = threading.Lock()

    # ------------------------------------------------------------------ the source
    @abc.abstractmethod
    def read(self) -> StateReading | None:
        """The newest state sample, or None before the first."""

    def latest_state(self) -> np.ndarray | None:
        """The newest state sample alone (the head camera poses the robot with it)."""
        reading = self.read()
        return None if reading is None else reading.state

    # ------------------------------------------------------------------ the sink
    @abc.abstractmethod
    def _console(self, line: str) -> str:
        """Run one hubo-console command line; the text to show.

        Raises:
            InputError: refused, with the console's reason; nothing was sent.
            HuboLadderError: the daemon (or the robot's bridge) did not answer.
        """

    @abc.abstractmethod
    def _neck(self, key: str) -> str:
        """Press one of hubo-neck's keys; its line (goal, ``at its limit``)."""

    @abc.abstractmethod
    def _player(self, command: PlayerCommand) -> str:
        """Signal the player that holds the instance's lock; what was sent to whom."""

    @abc.abstractmethod
    def close(self) -> None:
        """Release the channels or the network session; idempotent."""

    def _run(self, command: str, job, *args) -> Outcome:
        """``job(*args)`` under the lock; the project's errors become a refusal."""
        with self._lock:
            try:
                text = job(*args)
            except (InputError, HuboLadderError) as exc:
                return Outcome(command, False, str(exc))
        return Outcome(command, True, text or "done")

    def console_line(self, line: str) -> Outcome:
        """One hubo-console command line, e.g. ``goto RKN 0.5`` or ``kp RSP 20``."""
        line = line.strip()
        return self._run(line or "(empty)", self._console, line)

    def home_all(self) -> Outcome:
        """Home every joint (the daemon then ignores references for 3 s)."""
        return self.console_line("homeAll")

    def home(self, joint: str) -> Outcome:
        """Home one joint (by name)."""
        return self.console_line(f"home {joint}")

    def reset(self, joint: str) -> Outcome:
        """Reset one joint's board (clears a trip)."""
        return self.console_line(f"reset {joint}")

    def init_sensors(self) -> Outcome:
        """Zero the F/T and IMU offsets (the robot hanging still)."""
        return self.console_line("iniSensors")

    def neck_key(self, key: str) -> Outcome:
        """One of hubo-neck's keys (``w s a d q e c``)."""
        return self._run(f"neck {key}", self._neck, key)

    def pause_player(self) -> Outcome:
        """Toggle the running player's pause (SIGUSR1; refused unless it runs with -p)."""
        return self._run("pause", self._player, PlayerCommand.PAUSE)

    def stop_player(self) -> Outcome:
        """Stop the running player (SIGTERM); the robot holds its last reference."""
        return self._run("stop", self._player, PlayerCommand.STOP)
