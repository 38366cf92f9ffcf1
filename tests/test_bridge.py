"""hubo-bridge: the daemon's channels over zenoh with mutual TLS, on loopback only.

The robot bridge runs as its own process (``hubo-bridge robot``) beside the in-process
daemon with perfect boards (`fake_daemon`); the operator is this process's
`BridgeOperator`, or a second process (``hubo-bridge operator --mirror``). Every wait is
bounded in time."""

from __future__ import annotations

import contextlib
import os
import re
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("zenoh")

sys.path.insert(0, str(Path(__file__).parent))

from fake_daemon import running_daemon  # noqa: E402

from daemon.channels import cleanup_stale, open_channel  # noqa: E402
from daemon.control_modes import RefMode  # noqa: E402
from daemon.player_control import PlayerCommand, player_lock_file, signal_player  # noqa: E402
from daemon.remote.certs import make_certificates  # noqa: E402
from daemon.remote.cli import main  # noqa: E402
from daemon.remote.keys import Topic  # noqa: E402
from daemon.remote.operator import BridgeOperator, RemoteRefusal, wait_first_state  # noqa: E402
from daemon.remote.session_config import TlsFiles  # noqa: E402
from daemon.structs import REF_DTYPE, new_sample  # noqa: E402
from robot.errors import HuboLadderError, InputError  # noqa: E402
from robot.joints import JOINT_INDEX  # noqa: E402

BRIDGE = str(Path(sys.executable).with_name("hubo-bridge"))
RSP, NKY = JOINT_INDEX["RSP"], JOINT_INDEX["NKY"]


@pytest.fixture(scope="module")
def pki(tmp_path_factory) -> Path:
    """A CA with the robot, a configured operator (op1) and one that is not (intruder)."""
    d = tmp_path_factory.mktemp("pki")
    make_certificates(d, "robot", ("op1", "intruder"))
    return d


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Bridge:
    """A ``hubo-bridge robot`` process; its stderr is kept in ``log``."""

    def __init__(self, pki: Path, instance: str, tmp: Path, *extra: str):
        self.endpoint = f"tls/127.0.0.1:{_free_port()}"
        self.log_path = tmp / f"bridge-{instance}.log"
        self._err = open(self.log_path, "w")
        self.proc = subprocess.Popen(
            [BRIDGE, "robot", "--tls-dir", str(pki), "--listen", self.endpoint,
             "--instance", instance, "--allow-writer", "op1", "-v", *extra],
            stdout=subprocess.DEVNULL, stderr=self._err)

    def stop(self) -> str:
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(10)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(5)
        self._err.close()
        return self.log_path.read_text()


@contextlib.contextmanager
def bridge_and_daemon(pki: Path, tmp: Path, name: str, *extra: str):
    """A daemon, its robot bridge, and the bridge's log once it stopped (``logs``)."""
    logs: list[str] = []
    with running_daemon(name) as (instance, loop, boards):
        bridge = Bridge(pki, instance, tmp, *extra)
        try:
            yield instance, loop, boards, bridge, logs
        finally:
            logs.append(bridge.stop())


def _operator(pki: Path, bridge: Bridge, instance: str, name: str = "op1") -> BridgeOperator:
    """A connected operator that has seen the robot's state (retries while the bridge
    process starts listening, at most 10 s)."""
    deadline = time.monotonic() + 10.0
    while True:
        try:
            op = BridgeOperator(bridge.endpoint, TlsFiles.from_dir(pki, name), instance)
            break
        except HuboLadderError:
            if time.monotonic() > deadline or bridge.proc.poll() is not None:
                raise
            time.sleep(0.2)
    wait_first_state(op, 5.0)
    return op


def _ref(rsp_rad: float, playing: bool = True) -> np.ndarray:
    r = new_sample(REF_DTYPE)
    r["mode"] = RefMode.DIRECT
    r["ref"][RSP] = rsp_rad
    r["playing"] = playing
    return r


def _until(pred, timeout_s: float) -> bool:
    deadline = time.monotonic() + timeout_s
    while not pred():
        if time.monotonic() > deadline:
            return False
        time.sleep(0.01)
    return True


def test_state_goes_out_and_commands_come_in(pki, tmp_path):
    with bridge_and_daemon(pki, tmp_path, "bridge-io", "--rate-hz", "50") as (
            instance, loop, boards, bridge, logs):
        op = _operator(pki, bridge, instance)
        try:
            first = op.latest_state()
            later = op.wait_state(int(first["time_ns"]), 2.0)
            assert later is not None and int(later["tick"]) > int(first["tick"])
            # board commands, through hubo-console's checks
            done = loop.stats.cmds_done
            assert op.command(Topic.CONSOLE, "home LKN") == "done: home LKN"
            assert loop.stats.cmds_done == done + 1
            with pytest.raises(RemoteRefusal, match=r"kp 99 for RSP refused: allowed"):
                op.command(Topic.CONSOLE, "kp RSP 99")
            with pytest.raises(RemoteRefusal, match="not allowed over the bridge"):
                op.command(Topic.CONSOLE, "goto RSP 0.1")
            assert loop.stats.cmds_done == done + 1 and loop.gains.kp[RSP] != 99
            # a neck key, through hubo-neck's goals
            assert op.command(Topic.NECK, "q") == "q  NKY goal +1.000 rad"
            assert _until(lambda: abs(boards.pos[NKY] - 1.0) < 1e-3, 5.0)
            # references stream in, once each, and the daemon follows them
            for k in range(1, 31):
                op.send_ref(_ref(0.01 * k))
                time.sleep(0.01)
            assert _until(lambda: abs(boards.pos[RSP] - 0.30) < 1e-9, 2.0)
            assert not loop.holding
        finally:
            op.close()
    written, dropped = map(int, re.search(r"refs (\d+) \(dropped (\d+)", logs[0]).groups())
    assert written + dropped == 30 and written >= 1, logs[0][-400:]


def test_a_dropped_link_makes_the_daemon_hold(pki, tmp_path):
    """Two bridge processes: the robot's and an operator mirroring into a local instance.
    Refs written locally reach the daemon; state comes back into the local channel; when
    the operator's process dies, the daemon's watchdog holds the robot."""
    local = f"mirror-{os.getpid()}"
    with bridge_and_daemon(pki, tmp_path, "bridge-drop") as (instance, loop, boards, bridge,
                                                               logs):
        ref, state = open_channel("ref", local), open_channel("state", local)
        mirror = None
        try:
            deadline = time.monotonic() + 15.0
            while state.read_latest() is None and time.monotonic() < deadline:
                if mirror is None or mirror.poll() is not None:  # until the robot listens
                    mirror = subprocess.Popen(
                        [BRIDGE, "operator", "--tls-dir", str(pki), "--name", "op1",
                         "--connect", bridge.endpoint, "--instance", instance,
                         "--mirror", local], stdout=subprocess.DEVNULL,
                        stderr=subprocess.DEVNULL)
                time.sleep(0.2)
            s = state.read_latest()
            assert s is not None, "no state mirrored"
            assert state.wait_newer(int(s["time_ns"]), 2.0)["tick"] > s["tick"]
            k = 0
            while k < 50:  # 0.5 s of playing references through the mirror
                k += 1
                ref.write(_ref(0.002 * k))
                time.sleep(0.01)
            assert _until(lambda: abs(boards.pos[RSP] - 0.1) < 1e-9, 2.0), boards.pos[RSP]
            assert not loop.holding and loop.stats.watchdog_trips == 0
            mirror.kill()  # the link drops; the local player goes on writing
            mirror.wait(5)
            for _ in range(60):
                k += 1
                ref.write(_ref(0.002 * k))
                time.sleep(0.01)
            assert loop.holding and loop.stats.watchdog_trips == 1
            assert boards.pos[RSP] == pytest.approx(0.1, abs=1e-9)
        finally:
            if mirror is not None and mirror.poll() is None:
                mirror.kill()
                mirror.wait(5)
            ref.close()
            state.close()
            cleanup_stale(local)


def test_a_peer_that_is_not_configured_cannot_write(pki, tmp_path, tmp_path_factory):
    with bridge_and_daemon(pki, tmp_path, "bridge-acl") as (instance, loop, boards, bridge,
                                                             logs):
        op = _operator(pki, bridge, instance, "intruder")  # it may read the state
        try:
            op.timeout_s = 1.0
            done = loop.stats.cmds_done
            with pytest.raises(HuboLadderError, match="no answer from the robot bridge"):
                op.command(Topic.CONSOLE, "homeAll")
            for k in range(1, 21):
                op.send_ref(_ref(0.01 * k))
                time.sleep(0.01)
            time.sleep(0.3)
            assert loop.stats.cmds_done == done
            with open_channel("ref", instance) as ref:
                assert ref.read_latest() is None
            assert not boards.pos.any()
        finally:
            op.close()
        # a certificate from another authority does not even connect, whatever its name
        other = tmp_path_factory.mktemp("other-ca")
        make_certificates(other, "robot", ("op1",))
        with pytest.raises(HuboLadderError):
            BridgeOperator(bridge.endpoint, TlsFiles.from_dir(other, "op1"), instance)
    assert "peer 'intruder' connected" in logs[0]
    assert "read-only peers 1," in logs[0]


def _fake_player(instance: str, pause: bool) -> subprocess.Popen:
    """A process holding the player lock, answering SIGUSR1 (with ``pause``) and SIGTERM
    by printing their names."""
    code = f"""
import fcntl, os, signal, sys, time
fd = os.open({str(player_lock_file(instance))!r}, os.O_RDWR | os.O_CREAT, 0o644)
fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
def say(n, f):
    print(signal.Signals(n).name, flush=True)
    if n == signal.SIGTERM:
        sys.exit(0)
if {pause}:
    signal.signal(signal.SIGUSR1, say)
signal.signal(signal.SIGTERM, say)
print("ready", flush=True)
time.sleep(20)
"""
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "ready"
    return p


def test_pause_and_stop_reach_the_player(pki, tmp_path):
    with bridge_and_daemon(pki, tmp_path, "bridge-player") as (instance, loop, boards, bridge,
                                                                logs):
        op = _operator(pki, bridge, instance)
        try:
            with pytest.raises(RemoteRefusal, match="no play-trajectory is playing"):
                op.command(Topic.PLAYER, "stop")
            player = _fake_player(instance, pause=False)
            try:
                with pytest.raises(RemoteRefusal, match="pause needs play-trajectory -p"):
                    op.command(Topic.PLAYER, "pause")
                assert f"pid {player.pid}" in op.command(Topic.PLAYER, "stop")
                assert player.stdout.readline().strip() == "SIGTERM"
                assert player.wait(5) == 0
            finally:
                player.kill()
                player.wait(5)
            player = _fake_player(instance, pause=True)
            try:
                op.command(Topic.PLAYER, "pause")
                assert player.stdout.readline().strip() == "SIGUSR1"
                assert player.poll() is None  # paused, not killed
            finally:
                player.kill()
                player.wait(5)
        finally:
            op.close()
            player_lock_file(instance).unlink(missing_ok=True)


def test_a_player_lock_left_by_a_dead_player_names_no_player(tmp_path):
    instance = f"player-gone-{os.getpid()}"
    path = player_lock_file(instance)
    path.write_text("999999\n")  # a pid, but nobody holds the lock
    try:
        with pytest.raises(InputError, match="no play-trajectory is playing"):
            signal_player(instance, PlayerCommand.STOP)
    finally:
        path.unlink()


@pytest.mark.parametrize(("argv", "message"), [
    (["--rate-hz", "0.5"], "--rate-hz 0.5 refused: allowed [1, 200] Hz"),
    (["--rate-hz", "201"], "--rate-hz 201 refused: allowed [1, 200] Hz"),
    (["--max-delay-s", "0"], "--max-delay-s 0 refused: allowed (0, 1] s"),
    (["--listen", "tcp/127.0.0.1:7447"], "--listen 'tcp/127.0.0.1:7447' refused: use tls/"),
    (["--name", "nobody"], "--tls-dir"),
    (["--duration-s", "-1"], "--duration-s -1 refused"),
])
def test_bad_robot_options_exit_2_naming_the_option(pki, capsys, argv, message):
    assert main(["robot", "--tls-dir", str(pki), "--listen", "tls/127.0.0.1:1",
                 *argv]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"hubo-bridge: {message}") and len(err.splitlines()) == 1


def test_bad_operator_options_exit_2(pki, capsys):
    assert main(["operator", "--tls-dir", str(pki), "--name", "op1", "--connect",
                 "tcp/127.0.0.1:7447", "-c", "homeAll"]) == 2
    assert "--connect 'tcp/127.0.0.1:7447' refused" in capsys.readouterr().err
