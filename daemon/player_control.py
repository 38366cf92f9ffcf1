"""Pause and stop the running ``play-trajectory`` from another process (the bridge, a page).

The player takes an exclusive ``flock`` on ``/dev/shm/hubo-ladder-player.<instance>.lock``
for its lifetime (`execute.play.lock`) and reacts to signals: SIGUSR1 toggles pause when
it was started with ``-p``, SIGTERM stops it with the last reference held
(``playing`` cleared). These are the two controls the thesis's operator had.

Which process is the player is read from the kernel's table of locks (``/proc/locks``),
not from the pid written in the file: a killed player leaves its pid behind but no lock,
and taking the lock ourselves to test it would refuse a player starting at that moment.
A pause is sent only to a player that handles SIGUSR1 (``/proc/<pid>/status``,
``SigCgt``): without ``-p`` the signal's default action would kill the player.

The lock file's name is defined here (`player_lock_file`), on the robot side, and
`execute.play.lock` takes it from here.
"""

from __future__ import annotations

import enum
import logging
import os
import signal
from pathlib import Path

from robot.errors import HuboLadderError, InputError

__all__ = ["PlayerCommand", "player_lock_file", "playing_pid", "signal_player"]

log = logging.getLogger(__name__)

LOCK_DIR = Path("/dev/shm")  #: next to the daemon's channel files
LOCK_PREFIX = "hubo-ladder-player."
PROC_LOCKS = Path("/proc/locks")


class PlayerCommand(enum.Enum):
    """What may be asked of a running player."""

    PAUSE = "pause"  #: toggle pause (the player's ``-p`` feature): SIGUSR1
    STOP = "stop"  #: stop and hold the last reference: SIGTERM


_SIGNALS = {PlayerCommand.PAUSE: signal.SIGUSR1, PlayerCommand.STOP: signal.SIGTERM}


def player_lock_file(instance: str) -> Path:
    """The lock file the player of daemon ``instance`` holds while it plays."""
    return LOCK_DIR / f"{LOCK_PREFIX}{instance}.lock"


def playing_pid(instance: str) -> int | None:
    """The pid of the process holding the player lock of ``instance``, or None (no player).

    Read from ``/proc/locks``: the ``FLOCK`` entry on the lock file's device and inode.
    """
    try:
        st = player_lock_file(instance).stat()
    except FileNotFoundError:
        return None
    for line in PROC_LOCKS.read_text().splitlines():
        fields = line.split()
        # "1: FLOCK  ADVISORY  WRITE 12345 00:19:1234 0 EOF"; blocked waiters carry "->"
        if len(fields) < 6 or fields[1] != "FLOCK" or fields[0] == "->":
            continue
        major, minor, inode = fields[5].split(":")
        if int(inode) == st.st_ino and os.makedev(int(major, 16), int(minor, 16)) == st.st_dev:
            return int(fields[4])
    return None


def _catches(pid: int, signum: int) -> bool:
    """Whether process ``pid`` installed a handler for ``signum`` (its ``SigCgt`` mask)."""
    try:
        text = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return False
    for line in text.splitlines():
        if line.startswith("SigCgt:"):
            return bool(int(line.split()[1], 16) >> (signum - 1) & 1)
    return False


def signal_player(instance: str, command: PlayerCommand) -> int:
    """Send ``command`` to the player of daemon ``instance``; returns the player's pid.

    Raises:
        InputError: no player is playing on ``instance``, or a pause to a player started
            without ``-p`` (the signal would kill it); nothing is sent.
        HuboLadderError: the signal could not be sent (the player just ended, or it
            belongs to another user).
    """
    pid = playing_pid(instance)
    if pid is None:
        raise InputError(f"{command.value} refused: no play-trajectory is playing on "
                         f"instance {instance!r}")
    signum = _SIGNALS[command]
    if not _catches(pid, signum):
        raise InputError(f"{command.value} refused: the player (pid {pid}) does not handle "
                         f"{signal.Signals(signum).name}; pause needs play-trajectory -p")
    try:
        os.kill(pid, signum)
    except OSError as exc:
        raise HuboLadderError(f"{command.value}: cannot signal the player (pid {pid}): "
                              f"{exc.strerror}") from None
    log.info("player pid %d on instance %r: %s", pid, instance, command.value)
    return pid
