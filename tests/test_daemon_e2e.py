"""End to end: hubo-daemon (sim and virtual CAN) + hubo-console + play-trajectory, and faults.

The daemon and the player run as subprocesses with a unique ``--instance``; assertions
read the daemon's state log. ``HUBO_E2E_PLAN=path.traj`` plays another plan (with its
sidecar) in place of the fixture. Real time at 200 Hz on a shared 2-core machine: the tests
assert behaviour (modes, holds, stance), never timing.
"""

from __future__ import annotations

import dataclasses
import os
import select
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent / "fixtures"))

from make_fixture import cached_reach_fixture  # noqa: E402

from daemon.channels import cleanup_stale, open_channel  # noqa: E402
from daemon.console import main as console_main  # noqa: E402
from daemon.player_control import player_lock_file  # noqa: E402
from daemon.state_log import read_state_log  # noqa: E402
from daemon.structs import (  # noqa: E402
    BOARD_CMD_DTYPE,
    REF_DTYPE,
    BoardCommandType,
    StatusFlag,
    new_sample,
)
from ladders.loader import dump_ladder, load_ladder  # noqa: E402
from robot.joints import ARM_JOINTS, JOINT_INDEX, LEG_JOINTS  # noqa: E402
from robot.plan_sidecar import read_sidecar, sidecar_path  # noqa: E402
from robot.trajectory_file import read_trajectory  # noqa: E402

PY = sys.executable
ROOT = Path(__file__).resolve().parent.parent
ENV = {**os.environ, "PYTHONPATH": str(ROOT)}


@pytest.fixture(scope="module")
def plan(tmp_path_factory) -> Path:
    """The hand-built fixture, or ``HUBO_E2E_PLAN`` (a .traj with its sidecar)."""
    if os.environ.get("HUBO_E2E_PLAN"):
        return Path(os.environ["HUBO_E2E_PLAN"])
    return cached_reach_fixture(tmp_path_factory.getbasetemp())


class Daemon:
    """A hubo-daemon subprocess on its own instance, writing a state log."""

    def __init__(self, tmp: Path, name: str, *extra: str):
        self.instance = f"e2e-{name}-{os.getpid()}"
        self.log = tmp / f"{name}.log"
        self.extra = extra
        self.proc: subprocess.Popen | None = None
        self.state = None
        self.startup: list[str] = []  # stderr lines before the banner

    def start(self) -> Daemon:
        """Start; open the state channel only once the daemon has cleaned up and opened
        its channels (its banner line), and wait for its own first samples."""
        self.proc = subprocess.Popen(
            [PY, "-m", "daemon.cli", "--instance", self.instance, "--log", str(self.log),
             *self.extra], env=ENV, cwd=ROOT, stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE, text=True)
        deadline = time.monotonic() + 60
        self.startup = []
        while time.monotonic() < deadline:
            if select.select([self.proc.stderr], [], [], 0.5)[0]:
                line = self.proc.stderr.readline()
                assert line, f"the daemon exited: {self.startup}"
                self.startup.append(line)
                if line.startswith("hubo-daemon:"):
                    break
        if self.state is None:
            self.state = open_channel("state", self.instance)
        while time.monotonic() < deadline:
            s = self.state.wait_newer(0, 0.5)
            if s is not None and int(s["writer_id"]) == self.proc.pid:
                return self
            assert self.proc.poll() is None, self.startup
        raise AssertionError("the daemon did not start ticking")

    def wait_until(self, pred, timeout_s: float = 30.0) -> np.ndarray:
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            s = self.state.read_latest()
            if s is not None and pred(s):
                return s
            time.sleep(0.05)
        raise AssertionError("condition not reached on the state channel")

    def home(self) -> None:
        assert console_main(["--instance", self.instance, "-c", "homeAll"]) == 0
        self.wait_until(lambda s: s["zeroed"].all()
                        and not np.any(s["status"] & int(StatusFlag.NOT_HOMED)))

    def stop(self, sig=signal.SIGINT) -> str:
        self.proc.send_signal(sig)
        _, err = self.proc.communicate(timeout=30)
        return err

    def records(self) -> np.ndarray:
        return read_state_log(self.log)

    def close(self) -> None:
        """Stop the daemon and leave nothing of this instance in /dev/shm."""
        if self.proc is not None and self.proc.poll() is None:
            self.proc.kill()
            self.proc.communicate()
        if self.state is not None:
            self.state.close()
        cleanup_stale(self.instance)
        player_lock_file(self.instance).unlink(missing_ok=True)


def play(instance: str, *args: str, wait: bool = True):
    cmd = [PY, "-m", "execute.play.cli", "--instance", instance, "-q", *args]
    if not wait:
        return subprocess.Popen(cmd, env=ENV, cwd=ROOT, stderr=subprocess.PIPE, text=True)
    return subprocess.run(cmd, env=ENV, cwd=ROOT, capture_output=True, text=True, timeout=120)


def _line_of(ref_cmd: np.ndarray, traj: np.ndarray) -> int:
    """1-based line whose row the commanded reference is."""
    return int(np.argmin(np.abs(traj - ref_cmd).max(axis=1))) + 1


def _check_mode_switches(rec: np.ndarray, plan: Path) -> None:
    sc = read_sidecar(sidecar_path(plan))
    traj = read_trajectory(plan, sc.rate_hz)
    for arm in ("left", "right"):
        pwm_runs = [r for r in sc.arm_modes[arm] if r[2] == "pwm"]
        cols = [JOINT_INDEX[n] for n in ARM_JOINTS[arm] if n[1:] != "WR"]  # WR cannot comply
        comply = rec["comply"][:, cols].all(axis=1)
        assert not rec["comply"][:, cols].any(axis=1)[comply.argmax() - 1]
        first = int(np.argmax(comply))
        assert comply[first], f"{arm} arm never went compliant"
        assert _line_of(rec["ref_cmd"][first], traj) == pwm_runs[0][0]
        assert _line_of(rec["ref_cmd"][first - 1], traj) == pwm_runs[0][0] - 1
        assert comply[first:].all()  # and stays so to the end, as the sidecar says


def test_sim_daemon_plays_the_fixture_with_automatic_modes(plan, tmp_path):
    d = Daemon(tmp_path, "sim", "--backend", "sim", "--ladder", "drc")
    try:
        d.start()
        # a malformed trajectory: exit 2 naming file:line, nothing sent
        bad = tmp_path / "bad.traj"
        lines = plan.read_text().splitlines()
        cols = lines[6].split()
        cols[3] = "oops"
        lines[6] = " ".join(cols)
        bad.write_text("\n".join(lines) + "\n")
        r = play(d.instance, "-n", str(bad), "-i")
        assert r.returncode == 2 and f"{bad}:7:" in r.stderr
        ref = open_channel("ref", d.instance)
        assert ref.read_latest() is None  # nothing was ever sent
        ref.close()
        # not homed yet: refused
        r = play(d.instance, "-n", str(plan), "-i")
        assert r.returncode == 1 and "not homed" in r.stderr
        d.home()
        # gains above the limits: the console refuses with the range, the daemon too
        assert console_main(["--instance", d.instance, "-c", "kp RSP 80"]) == 2
        cmd = open_channel("board-cmd", d.instance)
        c = new_sample(BOARD_CMD_DTYPE)
        c["type"], c["joint"], c["dvalues"][:3] = BoardCommandType.SET_GAINS, 12, (80, 0, 9)
        cmd.write(c)
        cmd.close()
        time.sleep(0.1)
        r = play(d.instance, "-n", str(plan), "-i")
        assert r.returncode == 0, r.stderr
        time.sleep(1.0)
        err = d.stop()
        assert "stopped after" in err
    finally:
        d.close()
    rec = d.records()
    # the refused gains changed nothing; the closed-loop player set the motion layer's
    # arm gains (clamps at the safety ceiling) once
    assert rec["cmds_refused"][-1] == 1 and rec["gains_version"][-1] == 1
    _check_mode_switches(rec, plan)
    assert rec["latched"][-1].all(), "both hands latched on their rails at the end"
    assert np.all(rec["ft"]["fz"][-1, :2] > 100.0)  # still standing on both feet
    legs = [JOINT_INDEX[n] for side in ("left", "right") for n in LEG_JOINTS[side]]
    assert np.abs(rec["pos"][-1, legs]).max() < 0.05


#: The last cycles of a run [ticks] (2 s at 200 Hz) in which every board must answer.
NO_REPLY_WINDOW = 400


def _longest_run(flags: np.ndarray) -> int:
    """Longest run of True down the rows of ``flags`` (cycles × joints), any column."""
    longest = 0
    run = np.zeros(flags.shape[1], dtype=int)
    for row in flags:
        run = np.where(row, run + 1, 0)
        longest = max(longest, int(run.max()))
    return longest


def test_can_daemon_plays_the_fixture_over_virtual_buses(plan, tmp_path):
    tag = f"{os.getpid()}"
    d = Daemon(tmp_path, "can", "--backend", "can", "--can-interface", "virtual",
               "--channels", f"e2e{tag}-0,e2e{tag}-1", "--emulate-boards")
    try:
        d.start()
        d.home()
        # Emulated boards have no ladder: closed loop, the fingers close on nothing and
        # the motion layer (rightly) stops at the first grasp; the CAN path is the subject.
        r = play(d.instance, "-n", str(plan), "-i", "--open-loop")
        assert r.returncode == 0, r.stderr
        time.sleep(1.5)
        d.stop()
    finally:
        d.close()
    rec = d.records()
    _check_mode_switches(rec, plan)
    sc = read_sidecar(sidecar_path(plan))
    last = read_trajectory(plan, sc.rate_hz)[-1]
    # Every board keeps answering. The emulator's threads share the GIL and the host's
    # cores with the loop, so a reply now and then lands after the tick has read the bus
    # (NO_REPLY for that cycle, as with a late board on a real bus): 1–22 % of a joint's
    # cycles here depending on the host's load, a real board answering in ~0.1 ms
    # whatever it is. A silent board misses every one: the bound tells the two apart
    # without measuring the host.
    missed = (rec["status"][-NO_REPLY_WINDOW:] & int(StatusFlag.NO_REPLY)) != 0
    assert missed.mean(axis=0).max() < 0.5
    assert _longest_run(missed) <= 10
    rigid = ~rec["comply"][-1].astype(bool)
    # encoders decoded from the emulator's replies follow the encoded references
    assert np.abs(rec["pos"][-1, rigid] - last[rigid]).max() < 0.02
    assert np.abs(rec["pos"][-1] - last).max() < 0.15  # compliant arms: PWM tracking


def test_faults_player_killed_two_writers_and_a_daemon_restart(plan, tmp_path):
    d = Daemon(tmp_path, "faults", "--backend", "sim", "--homed", "--watchdog-s", "0.2")
    try:
        d.start()
        d.wait_until(lambda s: not np.any(s["status"] & int(StatusFlag.NOT_HOMED)))
        p = play(d.instance, "-n", str(plan), wait=False)
        d.wait_until(lambda s: s["ref"][JOINT_INDEX["LSR"]] > 0.3, timeout_s=30)
        p.kill()  # SIGKILL mid-reach: the player cannot say goodbye
        p.wait()
        # the watchdog (0.2 s = 40 ticks) and the 150-tick hold checked below pass before
        # the two writers start: counted in the daemon's ticks, which a loaded machine
        # slows (in wall time the writers' step once fell inside the hold)
        tick0 = int(d.wait_until(lambda s: True)["tick"])
        d.wait_until(lambda s: int(s["tick"]) > tick0 + 250, timeout_s=60)
        # two writers on ref: the newest sample wins, whoever wrote it
        a = open_channel("ref", d.instance, writer_id=101)
        b = open_channel("ref", d.instance, writer_id=102)
        s = new_sample(REF_DTYPE)
        s["ref"] = d.state.read_latest()["ref"]
        s["mode"][:] = 1
        s["ref"][JOINT_INDEX["NKY"]] = 0.3
        a.write(s)
        s["ref"][JOINT_INDEX["NKY"]] = -0.3
        b.write(s)
        d.wait_until(lambda st: abs(st["ref"][JOINT_INDEX["NKY"]] + 0.3) < 1e-9, 10)
        s["ref"][JOINT_INDEX["NKY"]] = 0.1
        a.write(s)
        d.wait_until(lambda st: abs(st["ref"][JOINT_INDEX["NKY"]] - 0.1) < 1e-9, 10)
        a.close()
        b.close()
        d.proc.kill()  # a crash: no clean-up at all
        d.proc.communicate()
        rec = d.records()
        d.state.close()
        d.state = None
        stale = list(Path("/dev/shm").glob(f"hubo-ladder.{d.instance}.*"))
        assert stale  # the crash left its channel files behind
        # restart on the same instance: stale channels are cleaned, it ticks again
        d.log = tmp_path / "restart.log"
        d.start()
        assert any("stale channel file" in line for line in d.startup)
        s2 = d.wait_until(lambda st: int(st["tick"]) > 50)
        assert s2["pos"][JOINT_INDEX["NKY"]] == pytest.approx(0.0, abs=1e-3)  # fresh robot
        d.stop()
    finally:
        d.close()
    killed = int(np.argmax(rec["watchdog"]))
    assert rec["watchdog"][killed] and rec["playing"][killed]
    ref = rec["ref"][: killed + 150]  # before the two writers' DIRECT steps
    jumps = np.abs(np.diff(ref, axis=0)).max(axis=1)
    assert jumps.max() < 0.05  # nothing jumps, neither playing nor at the hold
    hold = slice(killed, killed + 150)
    assert np.ptp(ref[hold], axis=0).max() < 1e-9  # held exactly still
    assert ref[killed, JOINT_INDEX["LSR"]] > 0.3  # where it was, not back at the start
    rec2 = read_state_log(tmp_path / "restart.log")
    assert rec2["tick"][0] == 1 and len(rec2) > 50


def test_a_misplaced_ladder_stops_the_player_which_writes_it_and_retraces_the_plan(
        plan, tmp_path):
    """``play-trajectory --replan-beyond`` on a ladder 1.2 cm from the plan's: both grasps
    find it there, the motion layer stops before the ladder takes any weight, the ladder
    as measured is written, the hands open and the arms retrace the plan to its first
    line; exit 1 with the command that plans again."""
    spec = load_ladder("drc")
    real = dataclasses.replace(spec, placement_y_m=spec.placement_y_m + 0.012)
    dump_ladder(real, tmp_path / "real.yaml")
    measured = tmp_path / "measured.yaml"
    d = Daemon(tmp_path, "replan", "--backend", "sim", "--homed",
               "--ladder", str(tmp_path / "real.yaml"))
    try:
        d.start()
        d.wait_until(lambda s: not np.any(s["status"] & int(StatusFlag.NOT_HOMED)))
        r = play(d.instance, "-n", str(plan), "-i", "--replan-beyond", "0.005",
                 "--measured-ladder", str(measured))
        sc = read_sidecar(sidecar_path(plan))
        first = read_trajectory(plan, sc.rate_hz)[0]
        arms = [JOINT_INDEX[n] for side in ("left", "right") for n in ARM_JOINTS[side]]
        if r.returncode == 1:  # the daemon's filter brings the arms onto the last line
            d.wait_until(lambda s: np.abs(s["pos"][arms] - first[arms]).max() < 0.05)
        d.stop()
    finally:
        d.close()
    assert r.returncode == 1, r.stderr
    assert "ladder_misplaced" not in r.stderr  # said in words, not as a code
    assert "the weight was not moved onto the ladder" in r.stderr
    assert f"wrote the ladder as the hands found it to {measured}" in r.stderr
    assert "back at the plan's start" in r.stderr and f"plan-ladder {measured}" in r.stderr
    found = load_ladder(str(measured))
    # A hand reads its rail once its palm stands still in the grip, the grip having drawn
    # it onto the rail's axis: within 0.3 mm alone and beside two busy loops (read as
    # soon as the fingers stopped, 0.5 cm off alone and 2 cm off under the suite's load,
    # 2026-11-29). The rest of the ladder is the spec's.
    assert abs(found.placement_y_m - real.placement_y_m) < 0.005
    assert abs(found.placement_x_m - real.placement_x_m) < 0.005
    assert (found.rung_spacing_m, found.num_rungs) == (real.rung_spacing_m, real.num_rungs)
    rec = d.records()
    assert rec["latched"].any(axis=0).all(), "both hands held their rails on the way"
    assert not rec["latched"][-1].any(), "and let go of them"
    assert np.all(rec["ft"]["fz"][-1, :2] > 100.0)  # standing on both feet throughout
    assert np.abs(rec["pos"][-1, arms] - first[arms]).max() < 0.05  # back at the start
