"""A real `DaemonLoop` on shared-memory channels, in a thread, with perfect boards: the
commands that talk to a daemon (``hubo-console``, ``play-trajectory``) run against it
in-process, in real time, without MuJoCo."""

from __future__ import annotations

import os
import threading
import time
from contextlib import contextmanager

import numpy as np

from daemon.backend import SensorFrame
from daemon.loop import DaemonChannels, DaemonLoop, LoopConfig


class PerfectBoards:
    """Every joint homed; the position is the last reference sent. Records the references."""

    name = "fake"
    homes_to_zero = False

    def __init__(self, pos_rad: np.ndarray | None = None):
        self.pos = np.zeros(40) if pos_rad is None else np.array(pos_rad, float)
        self.sent: list[np.ndarray] = []
        self.lock = threading.Lock()

    def zeroed_at_start(self):
        return np.ones(40, bool)

    def step(self, dt_s):
        pass

    def read_sensors(self):
        f = SensorFrame.zeros()
        f.pos_rad = self.pos.copy()
        f.power = np.array([48.0, 0.0, 0.0])
        return f

    def write_commands(self, cmd):
        with self.lock:
            self.sent.append(np.array(cmd.ref_rad))
        self.pos = np.array(cmd.ref_rad)

    def idle(self, until_ns):
        pass

    def board_command(self, kind, joint):
        pass

    def close(self):
        pass


@contextmanager
def running_daemon(name: str, pos_rad: np.ndarray | None = None):
    """A ticking daemon on a fresh instance; yields ``(instance, loop, boards)``."""
    from daemon.channels import cleanup_stale

    instance = f"{name}-{os.getpid()}-{time.monotonic_ns() % 10**9}"
    boards = PerfectBoards(pos_rad)
    channels = DaemonChannels.open(instance)
    loop = DaemonLoop(boards, channels, LoopConfig(startup_ignore_s=0.0))
    stop = threading.Event()
    thread = threading.Thread(target=loop.run, kwargs={"stop": stop}, daemon=True)
    thread.start()
    try:
        deadline = time.monotonic() + 5.0
        while loop.stats.ticks < 5 and time.monotonic() < deadline:
            time.sleep(0.01)
        yield instance, loop, boards
    finally:
        stop.set()
        thread.join(5.0)
        channels.close()
        cleanup_stale(instance)
        from execute.play.lock import player_lock_path

        player_lock_path(instance).unlink(missing_ok=True)  # left by play-trajectory runs
