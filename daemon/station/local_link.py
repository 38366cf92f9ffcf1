"""The page on the daemon's own computer: state from the shared-memory channels, commands
through the local tools' code (`daemon.local_commands`).

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

from daemon.local_commands import LocalCommands
from daemon.neck import NeckConfig
from daemon.player_control import PlayerCommand
from daemon.station.link import StateReading, StationLink

__all__ = ["LocalLink"]

#: The daemon writes the state every 5 ms: a sample older than this means it stopped [s].
STALE_AFTER_S = 0.5


class LocalLink(StationLink):
    """Daemon ``instance`` on this computer (see the module docstring); the arguments are
    `daemon.local_commands.LocalCommands`'s."""

    def __init__(self, instance: str = "default", robot: str = "drc-hubo",
                 neck: NeckConfig | None = None):
        super().__init__(instance, f"hubo-daemon instance {instance!r}", STALE_AFTER_S,
                         "no hubo-daemon is ticking")
        self.commands = LocalCommands(instance, robot, neck)
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
        mode = r["mode"] if r is not None and int(r["time_ns"]) >= int(s["start_ns"]) else None
        return StateReading(s, mode, int(s["time_ns"]))

    def _console(self, line: str) -> str:
        return self.commands.console(line)

    def _neck(self, key: str) -> str:
        return self.commands.neck(key)

    def _player(self, command: PlayerCommand) -> str:
        return self.commands.player(command)

    def close(self) -> None:
        with self._lock:
            self.commands.close()
            for c in self._channels.values():
                c.close()
            self._channels.clear()
