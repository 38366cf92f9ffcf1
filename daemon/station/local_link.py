"""The page on the daemon's own computer: state from the shared-memory channels, commands
through the local tools' code.

- state: the ``state`` channel, and the reference mode of the newest ``ref`` sample
  written since the daemon started;
- board commands: `daemon.console.Console.execute` (home, homeAll, reset, iniSensors,
  goto, comp, kp, kd, maxPWM, with its refusals of positions beyond a joint's limits and
  gains beyond the safety limits);
- neck keys: `daemon.neck.press` (bounded by the neck's limits);
- the player's pause and stop: `daemon.player_control` (the signals hubo-bridge sends
  too). Signals reach a player on this computer only.
"""

from __future__ import annotations

import io

from daemon.console import Console
from daemon.neck import NeckConfig, NeckLink, default_config, press
from daemon.player_control import PlayerCommand, signal_player
from daemon.station.link import StateReading, StationLink
from robot.errors import InputError

__all__ = ["LocalLink"]

#: The daemon writes the state every 5 ms: a sample older than this means it stopped [s].
STALE_AFTER_S = 0.5

_SIGNAL_DONE = {PlayerCommand.PAUSE: "pause toggled: SIGUSR1 to play-trajectory pid {pid}",
                PlayerCommand.STOP: "stopped: SIGTERM to play-trajectory pid {pid}; the "
                                    "robot holds the last reference"}


class LocalLink(StationLink):
    """Daemon ``instance`` on this computer (see the module docstring).

    Args:
        instance: the daemon's channel namespace.
        robot: whose joint limits goto, comp and the neck keys respect.
        neck: the neck steps [rad]; the thesis's when None.
    """

    def __init__(self, instance: str = "default", robot: str = "drc-hubo",
                 neck: NeckConfig | None = None):
        super().__init__(instance, f"hubo-daemon instance {instance!r}", STALE_AFTER_S,
                         "no hubo-daemon is ticking")
        self.neck_config = neck or default_config()
        self._out = io.StringIO()
        self.console = Console(instance, out=self._out, robot=robot)
        self._neck_link: NeckLink | None = None
        self._robot = robot
        self._channels: dict = {}

    def _channel(self, name: str):
        """This process's reader of channel ``name`` (opened on first use)."""
        if name not in self._channels:
            from daemon.channels import open_channel

            self._channels[name] = open_channel(name, self.instance)
        return self._channels[name]

    def read(self) -> StateReading | None:
        """The newest state sample, and the ``mode`` of the newest ``ref`` sample written
        since the daemon started (None when none was: the daemon holds)."""
        s = self._channel("state").read_latest()
        if s is None:
            return None
        r = self._channel("ref").read_latest()
        start_ns = int(s["time_ns"]) - round(float(s["time_s"]) * 1e9)
        mode = r["mode"] if r is not None and int(r["time_ns"]) >= start_ns else None
        return StateReading(s, mode, int(s["time_ns"]))

    def _printed(self, job) -> str:
        """Run ``job`` with the tools' output captured; what they printed."""
        self._out.seek(0)
        self._out.truncate()
        job()
        return self._out.getvalue().strip()

    def _console(self, line: str) -> str:
        def job() -> None:
            if not self.console.execute(line):
                raise InputError("quit is for the terminal; the page stays")

        return self._printed(job)

    def _neck(self, key: str) -> str:
        if self._neck_link is None:
            self._neck_link = NeckLink(self.instance, self._robot)
        return self._printed(lambda: press(self._neck_link, key, self.neck_config,
                                           out=self._out))

    def _player(self, command: PlayerCommand) -> str:
        return _SIGNAL_DONE[command].format(pid=signal_player(self.instance, command))

    def close(self) -> None:
        with self._lock:
            self.console.close()
            if self._neck_link is not None:
                self._neck_link.close()
            for c in self._channels.values():
                c.close()
            self._channels.clear()
