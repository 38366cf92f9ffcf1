"""Pause and stop the running ``play-trajectory`` from the operator's page.

The player listens on no channel: it pauses on SIGUSR1 (when started with ``-p``) and
stops and holds on SIGTERM (docs/daemon.md, "The player"). It names itself in its lock
file, ``/dev/shm/hubo-ladder-player.<instance>.lock`` (`execute.play.lock`, which the
daemon may not import; ``tests/test_station.py`` checks the two paths agree). A signal is
sent only to a process that holds that lock now (a shared ``flock`` on the file is
refused), never to a stale pid, and pause only when the player catches SIGUSR1: a player
started without ``-p`` would be killed by it. So it works on the machine the player runs
on (the robot's); through the network it needs the bridge.
"""

from __future__ import annotations

import errno
import fcntl
import os
import signal
from pathlib import Path

from robot.errors import HuboLadderError

__all__ = ["PlayerControlRefused", "pause_player", "player_pid", "stop_player"]

LOCK_DIR = Path("/dev/shm")  # as execute.play.lock.LOCK_DIR
LOCK_PREFIX = "hubo-ladder-player."  # as execute.play.lock.LOCK_PREFIX


class PlayerControlRefused(HuboLadderError):
    """No player to signal, or it cannot take this signal; the message says which."""


def lock_path(instance: str) -> Path:
    """The player lock file of daemon ``instance``."""
    return LOCK_DIR / f"{LOCK_PREFIX}{instance}.lock"


def player_pid(instance: str) -> int:
    """The pid of the ``play-trajectory`` that holds ``instance``'s lock now.

    Raises:
        PlayerControlRefused: no player holds it.
    """
    path = lock_path(instance)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_CLOEXEC)
    except FileNotFoundError:
        raise PlayerControlRefused(f"no play-trajectory runs on instance {instance!r} "
                                   f"(no lock {path})") from None
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
        except OSError as exc:
            if exc.errno not in (errno.EWOULDBLOCK, errno.EAGAIN):
                raise
            text = os.pread(fd, 64, 0).decode("ascii", "replace").strip()
            if text.isdigit():
                return int(text)
            raise PlayerControlRefused(f"the player lock {path} is held but names no "
                                       "pid") from None
        fcntl.flock(fd, fcntl.LOCK_UN)
        raise PlayerControlRefused(f"no play-trajectory runs on instance {instance!r} "
                                   f"(its lock {path} is free)")
    finally:
        os.close(fd)


def _catches(pid: int, signum: int) -> bool:
    """Whether process ``pid`` has a handler for ``signum`` (``SigCgt`` of /proc)."""
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("SigCgt:"):
                return bool(int(line.split()[1], 16) >> (signum - 1) & 1)
    return False


def _signal(pid: int, signum: int) -> None:
    try:
        os.kill(pid, signum)
    except ProcessLookupError:
        raise PlayerControlRefused(f"the player (pid {pid}) has just ended") from None
    except PermissionError:
        raise PlayerControlRefused(f"not allowed to signal the player (pid {pid}): it "
                                   "runs as another user") from None


def pause_player(instance: str) -> str:
    """Toggle pause of the player on ``instance`` (SIGUSR1); returns what was done.

    Raises:
        PlayerControlRefused: no player, or one started without ``-p``.
    """
    pid = player_pid(instance)
    if not _catches(pid, signal.SIGUSR1):
        raise PlayerControlRefused(f"the player (pid {pid}) was started without -p: it "
                                   "cannot pause (SIGUSR1 would kill it); nothing sent")
    _signal(pid, signal.SIGUSR1)
    return f"pause toggled: SIGUSR1 to play-trajectory pid {pid}"


def stop_player(instance: str) -> str:
    """Stop the player on ``instance`` (SIGTERM: it stops and the robot holds the last
    reference); returns what was done.

    Raises:
        PlayerControlRefused: no player.
    """
    pid = player_pid(instance)
    _signal(pid, signal.SIGTERM)
    return f"stop: SIGTERM to play-trajectory pid {pid}; the robot holds the last reference"
