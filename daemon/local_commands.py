"""The operator's commands carried out on the daemon's own computer, by the local tools'
code and with their checks: what hubo-init's page (`daemon.station.local_link`) and the
robot's side of hubo-bridge (`daemon.remote.robot`) both run.

- board commands: `daemon.console.Console.execute` (its refusals of positions beyond a
  joint's limits and of gains beyond the safety limits);
- neck keys: `daemon.neck.press` (bounded by the neck's limits);
- the player's pause and stop: `daemon.player_control` (signals to the process that holds
  the instance's player lock, on this computer).

Each returns the text to show the operator: what the tool printed, or what was done.
"""

from __future__ import annotations

import io

from daemon.neck import NeckConfig, NeckLink, default_config, press
from daemon.player_control import PlayerCommand, signal_player
from robot.errors import InputError

__all__ = ["LocalCommands"]

_SIGNAL_DONE = {PlayerCommand.PAUSE: "pause toggled: SIGUSR1 to play-trajectory pid {pid}",
                PlayerCommand.STOP: "stopped: SIGTERM to play-trajectory pid {pid}; the "
                                    "robot holds the last reference"}


class LocalCommands:
    """The commands of daemon ``instance`` (module docstring). Not thread-safe: callers
    run one command at a time.

    Args:
        instance: the daemon's channel namespace.
        robot: whose joint limits goto, comp and the neck keys respect.
        neck: the neck steps [rad]; the thesis's when None.
    """

    def __init__(self, instance: str = "default", robot: str = "drc-hubo",
                 neck: NeckConfig | None = None):
        self.instance = instance
        self.neck_config = neck or default_config()
        self._out = io.StringIO()
        self._link = NeckLink(instance, robot)  # holds the Console
        self._link.console.out = self._out

    def _printed(self, job) -> str:
        """Run ``job`` with the tools' output captured; what they printed."""
        self._out.seek(0)
        self._out.truncate()
        job()
        return self._out.getvalue().strip()

    def console(self, line: str) -> str:
        """One hubo-console command line.

        Raises:
            InputError: refused by the console (nothing was sent), or ``quit``, which is
                for the terminal.
            HuboLadderError: the daemon did not acknowledge.
        """
        def job() -> None:
            if not self._link.console.execute(line):
                raise InputError("quit is for the terminal: nothing was sent")

        return self._printed(job) or f"done: {line}"

    def neck(self, key: str) -> str:
        """Press one of hubo-neck's keys; its line (goal, ``at its limit``).

        Raises:
            InputError: not one key, not one of hubo-neck's, or its quit key.
        """
        if len(key) != 1:
            raise InputError(f"neck command {key!r}: send one key at a time")

        def job() -> None:
            if not press(self._link, key, self.neck_config, out=self._out):
                raise InputError("quit is for the terminal: nothing was sent")

        return self._printed(job)

    def player(self, command: PlayerCommand) -> str:
        """Signal the player that holds the instance's lock; what was sent to whom."""
        return _SIGNAL_DONE[command].format(pid=signal_player(self.instance, command))

    def close(self) -> None:
        self._link.close()
