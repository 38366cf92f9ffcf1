"""One player at a time per daemon instance: an exclusive lock next to the channel files.

Two players on one daemon interleave their samples on the latest-value ``ref`` channel:
the robot follows whichever sample is newest, and the reference jumps between the two
files every tick. ``play-trajectory`` therefore takes `PlayerLock` before it writes
anything:

- the lock is ``flock(LOCK_EX | LOCK_NB)`` on ``/dev/shm/hubo-ladder-player.INSTANCE.lock``,
  held for the player's lifetime; the file holds the holder's pid, for the message;
- a second player is refused (`PlayerBusyError`, exit 2) with the first one's pid;
- the kernel releases a flock when its process dies, however it dies: a player killed
  with SIGKILL leaves a file with its pid but no lock, and the next player takes it and
  says whose lock it recovered. A file whose pid names no running process is the same
  case (a stale pid file): only the flock decides.

The file's name does not start with the channel prefix (``hubo-ladder.``), so the daemon's
start-up cleanup of stale channel files (`daemon.channels.cleanup_stale`) never removes
the lock of a running player. The file is never removed (removing a flock file races
with the next player opening it); a player that ends normally empties it.
"""

from __future__ import annotations

import errno
import fcntl
import logging
import os
import re
from pathlib import Path

from daemon.player_control import player_lock_file
from robot.errors import HuboLadderError, InputError

__all__ = ["PlayerBusyError", "PlayerLock", "player_lock_path"]

log = logging.getLogger(__name__)

_INSTANCE_RE = re.compile(r"^[A-Za-z0-9_-]{1,40}$")  # as the channels' instance names


class PlayerBusyError(InputError):
    """Another player holds the instance's lock (exit 2); ``pid`` is its process id."""

    def __init__(self, instance: str, pid: int | None, path: Path):
        self.instance, self.pid, self.path = instance, pid, path
        who = f"pid {pid}" if pid else "a process whose pid is not recorded"
        super().__init__(f"another play-trajectory ({who}) is playing on instance "
                         f"{instance!r} (lock {path}); stop it first, or pick another "
                         "--instance")


def player_lock_path(instance: str) -> Path:
    """The lock file of daemon ``instance``'s player.

    Raises:
        InputError: an instance name the channels would refuse.
    """
    if not _INSTANCE_RE.match(instance):
        raise InputError(f"--instance {instance!r}: use 1–40 characters of A–Z a–z 0–9 _ -")
    return player_lock_file(instance)


def _pid_running(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # someone else's process: it exists
        return True
    return True


def _read_pid(fd: int) -> int | None:
    os.lseek(fd, 0, os.SEEK_SET)
    text = os.read(fd, 64).decode("ascii", "replace").strip()
    return int(text) if text.isdigit() else None


class PlayerLock:
    """The exclusive player lock of one daemon instance (see the module docstring).

    Use as a context manager, or `acquire` and `release`.

    Args:
        instance: the daemon instance (the ``--instance`` of the player and the daemon).

    Attributes:
        path: the lock file.
        recovered_pid: after `acquire`, the pid left in the file by a player that ended
            without releasing it (killed), else None.
    """

    def __init__(self, instance: str):
        self.instance = instance
        self.path = player_lock_path(instance)
        self.recovered_pid: int | None = None
        self._fd: int | None = None

    def acquire(self) -> PlayerLock:
        """Take the lock, or refuse.

        Raises:
            PlayerBusyError: another live process holds it.
            HuboLadderError: the lock file cannot be opened.
        """
        if self._fd is not None:
            return self
        try:
            fd = os.open(self.path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
        except OSError as exc:
            raise HuboLadderError(f"cannot open the player lock {self.path}: "
                                  f"{exc.strerror}") from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError as exc:
            pid = _read_pid(fd)
            os.close(fd)
            if exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN):
                raise PlayerBusyError(self.instance, pid, self.path) from None
            raise HuboLadderError(f"cannot lock {self.path}: {exc.strerror}") from None
        left = _read_pid(fd)
        if left is not None and left != os.getpid():
            self.recovered_pid = left
            state = "still runs but does not hold it" if _pid_running(left) else "is gone"
            log.warning("recovered the player lock of instance %r left by pid %d, which %s",
                        self.instance, left, state)
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode(), 0)
        self._fd = fd
        return self

    def release(self) -> None:
        """Empty the file and drop the lock (also done by the kernel at exit)."""
        if self._fd is None:
            return
        try:
            os.ftruncate(self._fd, 0)
        finally:
            os.close(self._fd)  # closing the last descriptor releases the flock
            self._fd = None

    @property
    def held(self) -> bool:
        """This object holds the lock."""
        return self._fd is not None

    def __enter__(self) -> PlayerLock:
        return self.acquire()

    def __exit__(self, *exc) -> None:
        self.release()
