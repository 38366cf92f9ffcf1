"""One player at a time: a second ``play-trajectory`` is refused naming the first one's pid,
and a lock left by a killed player is recovered."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from daemon.channels import cleanup_stale
from execute.play.cli import main as play_main
from execute.play.lock import PlayerBusyError, PlayerLock, player_lock_path
from robot.trajectory_file import write_trajectory

ROOT = Path(__file__).resolve().parents[1]
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}


@pytest.fixture
def instance():
    name = f"lock-{os.getpid()}-{time.monotonic_ns() % 10**9}"
    yield name
    player_lock_path(name).unlink(missing_ok=True)
    cleanup_stale(name)  # the channels a player opened to wait for a daemon


@pytest.fixture
def traj(tmp_path):
    path = tmp_path / "still.traj"
    write_trajectory(path, np.zeros((10, 40)))
    return path


def _first_player(instance: str, traj: Path) -> subprocess.Popen:
    """A real play-trajectory that holds the lock while it waits for a daemon (none runs)."""
    p = subprocess.Popen([sys.executable, "-m", "execute.play.cli", "-n", str(traj),
                          "--instance", instance, "-q"], cwd=ROOT, env=ENV,
                         stderr=subprocess.PIPE, text=True)
    path = player_lock_path(instance)
    deadline = time.monotonic() + 20.0
    while time.monotonic() < deadline:
        if path.exists() and path.read_text().strip() == str(p.pid):
            return p
        if p.poll() is not None:
            pytest.fail(f"the first player ended early: {p.stderr.read()}")
        time.sleep(0.02)
    p.kill()
    pytest.fail("the first player never took the lock")


def test_a_second_player_is_refused_naming_the_first_ones_pid(instance, traj, capsys):
    first = _first_player(instance, traj)
    try:
        code = play_main(["-n", str(traj), "--instance", instance, "-q"])
        err = capsys.readouterr().err
        assert code == 2
        assert f"pid {first.pid}" in err and repr(instance) in err
    finally:
        first.kill()
        first.wait()


def test_a_lock_left_by_a_killed_player_is_recovered(instance, traj, capsys):
    first = _first_player(instance, traj)
    first.send_signal(signal.SIGKILL)
    first.wait()
    assert player_lock_path(instance).read_text().strip() == str(first.pid)  # left behind
    # The next player takes the lock: it gets as far as looking for the daemon (exit 1).
    code = play_main(["-n", str(traj), "--instance", instance, "-q"])
    err = capsys.readouterr().err
    assert code == 1 and "no hubo-daemon" in err and "another play-trajectory" not in err
    with PlayerLock(instance) as lock:
        assert lock.held and lock.recovered_pid is None  # the clean exit emptied the file


def test_a_stale_pid_file_is_recovered_and_a_held_lock_refused(instance):
    path = player_lock_path(instance)
    path.write_text("999999999\n")  # a pid no process has
    with PlayerLock(instance) as lock:
        assert lock.recovered_pid == 999999999
        assert path.read_text().strip() == str(os.getpid())
        with pytest.raises(PlayerBusyError) as err:
            PlayerLock(instance).acquire()  # another open file description: refused
        assert err.value.pid == os.getpid() and f"pid {os.getpid()}" in str(err.value)
    assert path.read_text() == ""
    with PlayerLock(instance) as again:
        assert again.recovered_pid is None


def test_the_daemons_stale_channel_cleanup_never_removes_the_lock(instance):
    from daemon.channels import cleanup_stale

    with PlayerLock(instance):
        cleanup_stale(instance)
        assert player_lock_path(instance).exists()
