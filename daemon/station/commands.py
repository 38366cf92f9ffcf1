"""What the page's buttons, keys and command line do: each runs one command and returns an
`Outcome` with the text the operator reads, refusals with their reason.

The commands are hubo-console's (`daemon.console.Console.execute`: home, homeAll, reset,
iniSensors, goto, comp, kp, kd, maxPWM, with its refusals of positions beyond a joint's
limits and gains beyond the safety limits) and hubo-neck's keys
(`daemon.neck.press`, bounded by the neck's limits); the player's pause and stop go
through `daemon.player_control` (the signals hubo-bridge sends too). Nothing is checked
twice here, so the page refuses exactly what the terminal tools refuse, with the same
words.

Each command blocks until the daemon has ticked past it (at most about a second); the page
runs them in a worker thread, one at a time (a lock), as a terminal would.
"""

from __future__ import annotations

import io
import threading
from typing import NamedTuple

from daemon.console import Console
from daemon.neck import NeckConfig, NeckLink, default_config, press
from daemon.player_control import PlayerCommand, signal_player
from robot.errors import HuboLadderError, InputError

__all__ = ["Outcome", "StationCommands"]


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


class StationCommands:
    """The commands of one page process on daemon ``instance``.

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
        self.console = Console(instance, out=self._out, robot=robot)
        self._neck: NeckLink | None = None
        self._robot = robot
        self._lock = threading.Lock()

    def close(self) -> None:
        with self._lock:
            self.console.close()
            if self._neck is not None:
                self._neck.close()

    def _run(self, command: str, job) -> Outcome:
        """Run ``job`` (returning the text of a done command, or None to use what the
        console printed) under the lock; project errors become a refusal."""
        with self._lock:
            self._out.seek(0)
            self._out.truncate()
            try:
                text = job()
            except (InputError, HuboLadderError) as exc:
                return Outcome(command, False, str(exc))
            printed = self._out.getvalue().strip()
        return Outcome(command, True, text or printed or "done")

    def console_line(self, line: str) -> Outcome:
        """One hubo-console command line, e.g. ``goto RKN 0.5`` or ``kp RSP 20``."""
        line = line.strip()

        def job():
            if not self.console.execute(line):
                raise InputError("quit is for the terminal; the page stays")
            return None

        return self._run(line or "(empty)", job)

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

        def job():
            if self._neck is None:
                self._neck = NeckLink(self.instance, self._robot)
            press(self._neck, key, self.neck_config, out=self._out)
            return None

        return self._run(f"neck {key}", job)

    def pause_player(self) -> Outcome:
        """Toggle the running player's pause (SIGUSR1; refused unless it runs with -p)."""
        return self._run("pause", lambda: "pause toggled: SIGUSR1 to play-trajectory pid "
                         f"{signal_player(self.instance, PlayerCommand.PAUSE)}")

    def stop_player(self) -> Outcome:
        """Stop the running player (SIGTERM); the robot holds its last reference."""
        return self._run("stop", lambda: "stopped: SIGTERM to play-trajectory pid "
                         f"{signal_player(self.instance, PlayerCommand.STOP)}; the robot "
                         "holds the last reference")
