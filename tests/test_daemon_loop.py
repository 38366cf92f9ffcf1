"""The 200 Hz loop: deadlines, overruns, watchdog, gates, board commands, gains, log."""

from __future__ import annotations

import itertools
import time

import numpy as np
import pytest

from daemon.backend import BoardCommands, SensorFrame
from daemon.loop import DaemonChannels, DaemonLoop, LoopConfig
from daemon.state_log import LOG_DTYPE, StateLogWriter, read_state_log
from daemon.structs import (
    BOARD_CMD_DTYPE,
    PWM_GAINS_DTYPE,
    REF_DTYPE,
    BoardCommandType,
    StatusFlag,
    new_sample,
)
from robot.joints import JOINT_INDEX

_ids = itertools.count()
RSP, LSP, NKY = JOINT_INDEX["RSP"], JOINT_INDEX["LSP"], JOINT_INDEX["NKY"]


class FakeBackend:
    """Perfect boards: the position is the last reference. Records what it was told."""

    name = "fake"
    homes_to_zero = False

    def __init__(self, homed=True, clock=None, work_ns=0, slow=None):
        self.homed = homed
        self.pos = np.zeros(40)
        self.sent: list[BoardCommands] = []
        self.steps: list[float] = []
        self.commands: list[tuple] = []
        self.clock, self.work_ns, self.slow = clock, work_ns, slow or {}
        self.hook = None

    def zeroed_at_start(self):
        return np.full(40, self.homed)

    def step(self, dt_s):
        self.steps.append(dt_s)

    def read_sensors(self):
        if self.hook is not None:
            self.hook(len(self.sent))
        f = SensorFrame.zeros()
        f.pos_rad = self.pos.copy()
        return f

    def write_commands(self, cmd):
        self.sent.append(cmd)
        self.pos = np.array(cmd.ref_rad)
        if self.clock is not None:
            self.clock.now += self.work_ns + self.slow.get(len(self.sent), 0)

    def idle(self, until_ns):
        pass

    def board_command(self, kind, joint):
        self.commands.append((kind, joint))

    def close(self):
        pass


class FakeClock:
    def __init__(self):
        self.now = 1_000_000_000

    def __call__(self):
        return self.now

    def sleep_until(self, t):
        self.now = max(self.now, t)


def _loop(backend, **cfg):
    inst = f"loop{next(_ids)}"
    ch = DaemonChannels.open(inst, in_process=True)
    writer = DaemonChannels.open(inst, in_process=True, writer_id=99)
    kwargs = {"startup_ignore_s": 0.0, **cfg}
    clock = backend.clock
    loop = DaemonLoop(backend, ch, LoopConfig(**kwargs),
                      clock_ns=clock or time.monotonic_ns,
                      sleep_until=clock.sleep_until if clock else None or _real_sleep,
                      record_starts=True)
    loop.start()  # time origin now: samples written from here on count
    return loop, writer


def _real_sleep(t):
    from daemon.loop import sleep_until_ns

    sleep_until_ns(t)


def _ref(value=0.0, playing=1, **joints) -> np.ndarray:
    s = new_sample(REF_DTYPE)
    s["ref"][:] = value
    for name, v in joints.items():
        s["ref"][JOINT_INDEX[name]] = v
    s["playing"] = playing
    return s


def _cmd(kind, joint=-1, params=(), dvalues=()) -> np.ndarray:
    c = new_sample(BOARD_CMD_DTYPE)
    c["type"], c["joint"] = int(kind), joint
    c["params"][: len(params)] = params
    c["dvalues"][: len(dvalues)] = dvalues
    return c


def test_deadlines_are_absolute():
    clock = FakeClock()
    be = FakeBackend(clock=clock, work_ns=1_000_000)
    loop, _ = _loop(be)
    t0 = clock.now
    stats = loop.run(max_ticks=50)
    assert stats.ticks == 50 and stats.overruns == 0
    assert np.array_equal(np.array(stats.starts_ns) - t0, np.arange(50) * 5_000_000)
    assert be.steps == pytest.approx([0.005] * 49)


def test_an_overrun_skips_to_the_next_deadline_and_is_counted():
    clock = FakeClock()
    be = FakeBackend(clock=clock, work_ns=1_000_000, slow={10: 11_000_000})  # tick 10: 12 ms
    loop, _ = _loop(be)
    t0 = clock.now
    stats = loop.run(max_ticks=20)
    starts = (np.array(stats.starts_ns) - t0) / 5e6
    assert stats.overruns == 2  # deadlines 10 and 11 passed during tick 9's 12 ms
    assert list(starts[8:12]) == [8, 9, 12, 13]  # no back-to-back catch-up ticks
    assert be.steps[9] == pytest.approx(0.015)  # the boards ran the whole gap
    assert int(loop.state["overruns"]) == 2


def test_watchdog_holds_when_a_playing_reference_goes_stale():
    be = FakeBackend()
    loop, w = _loop(be, watchdog_s=0.05)

    def ramp(k):
        if k < 40:
            w.ref.write(_ref(RSP=-0.01 * k))

    be.hook = ramp
    loop.run(max_ticks=100)
    refs = np.array([c.ref_rad[RSP] for c in be.sent])
    assert loop.stats.watchdog_trips == 1 and loop.holding
    hold_from = 40 + 12  # 50 ms after the last sample (10 ticks) plus slack
    assert np.ptp(refs[hold_from:]) == 0.0  # exactly still
    assert np.max(np.abs(np.diff(refs))) < 0.02  # nothing jumped
    assert refs[-1] < -0.05  # it held where the filter had got to, not at the start


def test_finished_player_reference_is_kept_not_a_watchdog_hold():
    be = FakeBackend()
    loop, w = _loop(be, watchdog_s=0.02)
    w.ref.write(_ref(playing=0, RSP=-0.3))
    loop.run(max_ticks=80)
    assert loop.stats.watchdog_trips == 0
    assert be.sent[-1].ref_rad[RSP] == pytest.approx(-0.3, abs=0.05)


def test_stale_reference_from_before_start_and_malformed_ones_are_ignored():
    be = FakeBackend()
    inst = f"loop{next(_ids)}"
    w = DaemonChannels.open(inst, in_process=True, writer_id=5)
    w.ref.write(_ref(playing=0, RSP=-1.0))  # left over from an earlier session
    loop = DaemonLoop(be, DaemonChannels.open(inst, in_process=True),
                      LoopConfig(startup_ignore_s=0.0))
    loop.run(max_ticks=10)
    assert np.all(be.sent[-1].ref_rad == 0.0)
    # The state tells its readers (hubo-neck, the station) which samples are stale: its
    # write stamp less time_s is later than the start by each tick's work.
    start_ns = int(loop.state["start_ns"])
    assert int(w.ref.read_latest()["time_ns"]) < start_ns <= int(loop.state["time_ns"])
    bad = _ref(playing=0, RSP=-1.0)
    bad["mode"][3] = 7
    w.ref.write(bad)
    loop.run(max_ticks=20)  # no exception: refused and held
    assert np.all(be.sent[-1].ref_rad == 0.0)


def test_neck_channel_overrides_the_neck():
    be = FakeBackend()
    loop, w = _loop(be)
    w.ref.write(_ref(playing=0, NKY=0.2, RSP=-0.2))
    w.ref_neck.write(_ref(playing=0, NKY=-0.3))
    loop.run(max_ticks=300)
    assert be.sent[-1].ref_rad[NKY] == pytest.approx(-0.3, abs=0.01)
    assert be.sent[-1].ref_rad[RSP] == pytest.approx(-0.2, abs=0.01)


def test_unhomed_joints_do_not_move_until_homed_and_the_gate_ends():
    # the loop's own clock (5 ms a tick), so that the gate ends on a tick whatever the
    # host's load: in wall time a loaded host once spent the 0.1 s within 20 ticks
    be = FakeBackend(homed=False, clock=FakeClock())
    loop, w = _loop(be, home_ignore_s=0.3)
    w.ref.write(_ref(-0.2, playing=0))
    loop.run(max_ticks=30)
    assert np.all(be.sent[-1].ref_rad == 0.0)
    assert np.all(loop.state["status"] & int(StatusFlag.NOT_HOMED))
    w.board_cmd.write(_cmd(BoardCommandType.HOME, RSP))
    loop.run(max_ticks=50)  # 20 ticks (0.1 s) into the 0.3 s gate
    assert be.commands == [(BoardCommandType.HOME, RSP)]
    assert loop.zeroed[RSP] and loop.zeroed.sum() == 1
    assert be.sent[-1].ref_rad[RSP] == 0.0
    loop.run(max_ticks=150)
    assert be.sent[-1].ref_rad[RSP] < -0.1  # follows the reference now
    others = np.delete(be.sent[-1].ref_rad, RSP)
    assert np.all(others == 0.0)
    assert not loop.state["status"][RSP] & int(StatusFlag.NOT_HOMED)


def test_board_commands():
    be = FakeBackend()
    loop, w = _loop(be)
    w.ref.write(_ref(playing=0, LSP=0.3))
    loop.run(max_ticks=5)
    for kind in (BoardCommandType.INIT_SENSORS, BoardCommandType.RESET):
        w.board_cmd.write(_cmd(kind, LSP))
        loop.run(max_ticks=loop.stats.ticks + 2)
    w.board_cmd.write(_cmd(BoardCommandType.CONTROL_OFF, LSP))
    loop.run(max_ticks=loop.stats.ticks + 3)
    last = be.sent[-1]
    assert last.pwm[LSP] and last.duty_pct[LSP] == 0.0 and not loop.state["active"][LSP]
    w.board_cmd.write(_cmd(BoardCommandType.CONTROL_ON, LSP))
    loop.run(max_ticks=loop.stats.ticks + 3)
    assert not be.sent[-1].pwm[LSP] and loop.state["active"][LSP]
    w.board_cmd.write(_cmd(BoardCommandType.HOME_ALL))
    loop.run(max_ticks=loop.stats.ticks + 3)
    assert [k for k, _ in be.commands] == [
        BoardCommandType.INIT_SENSORS, BoardCommandType.RESET, BoardCommandType.CONTROL_OFF,
        BoardCommandType.CONTROL_ON, BoardCommandType.HOME_ALL]
    assert loop.stats.cmds_done == 5 and loop.stats.cmds_refused == 0
    w.board_cmd.write(_cmd(99))
    loop.run(max_ticks=loop.stats.ticks + 2)
    w.board_cmd.write(_cmd(BoardCommandType.HOME, 77))
    loop.run(max_ticks=loop.stats.ticks + 2)
    assert loop.stats.cmds_refused == 2


def test_gains_over_the_limits_are_refused_and_the_old_ones_kept():
    be = FakeBackend()
    loop, w = _loop(be)
    kp0 = loop.gains.kp.copy()
    w.board_cmd.write(_cmd(BoardCommandType.SET_GAINS, RSP, params=[1], dvalues=[80.0]))
    loop.run(max_ticks=3)
    assert loop.stats.cmds_refused == 1 and np.array_equal(loop.gains.kp, kp0)
    w.board_cmd.write(_cmd(BoardCommandType.SET_GAINS, RSP, params=[1], dvalues=[50.0]))
    loop.run(max_ticks=6)
    assert loop.gains.kp[RSP] == 50.0 and loop.gains.max_pwm_pct[RSP] == 7.9
    g = new_sample(PWM_GAINS_DTYPE)
    g["max_pwm"][LSP] = 9.0
    w.pwm_gains.write(g)
    loop.run(max_ticks=9)
    assert loop.stats.cmds_refused == 2 and loop.gains.kp[RSP] == 50.0
    g["max_pwm"][LSP] = 5.0
    w.pwm_gains.write(g)
    loop.run(max_ticks=12)
    assert loop.gains.max_pwm_pct[LSP] == 5.0 and loop.stats.gains_version == 2


def test_compliant_joints_get_pwm_duty():
    be = FakeBackend()
    loop, w = _loop(be)
    s = _ref(playing=0, LSP=0.1)
    s["comply"][LSP] = 1
    w.ref.write(s)
    loop.run(max_ticks=5)
    assert be.sent[-1].pwm[LSP] and loop.state["comply"][LSP]
    assert loop.state["status"][LSP] & int(StatusFlag.COMPLIANT)


def test_state_log_is_written_every_tick(tmp_path):
    be = FakeBackend()
    loop, w = _loop(be)
    path = tmp_path / "state.log"
    loop.state_log = StateLogWriter(path, meta={"backend": "fake"})
    w.ref.write(_ref(playing=1, RSP=-0.1))
    loop.run(max_ticks=25)
    loop.state_log.close()
    rec = read_state_log(path)
    assert rec.dtype == LOG_DTYPE and len(rec) == 25
    assert list(rec["tick"]) == list(range(1, 26))
    assert np.all(rec["ref_cmd"][:, RSP] == -0.1) and rec["playing"].all()
    assert np.all(np.diff(rec["tick_start_ns"]) > 0)
    with open(path, "ab") as f:
        f.write(b"\0" * 100)  # a partial record from a kill mid-write
    assert len(read_state_log(path)) == 25


def test_the_players_feed_forward_adds_to_compliant_joints_only_and_is_bounded():
    be = FakeBackend()
    loop, w = _loop(be)
    s = _ref(playing=0)
    s["comply"][LSP] = 1
    s["pwm_command"][LSP] = 2.0
    s["pwm_command"][JOINT_INDEX["RSP"]] = 3.0  # not compliant: ignored
    w.ref.write(s)
    loop.run(max_ticks=5)
    # On its reference a compliant joint's duty is −pwm_command (hubo-ach sign).
    assert be.sent[-1].duty_pct[LSP] == pytest.approx(-2.0)
    assert be.sent[-1].duty_pct[JOINT_INDEX["RSP"]] == 0.0
    s["pwm_command"][LSP] = np.nan  # refused whole: the last good reference holds
    w.ref.write(s)
    loop.run(max_ticks=10)
    assert be.sent[-1].duty_pct[LSP] == 0.0 and not be.sent[-1].pwm[LSP]


def test_a_reference_beyond_a_limit_from_any_writer_is_rejected_and_counted(caplog):
    be = FakeBackend()
    loop, w = _loop(be)
    RKN, REB = JOINT_INDEX["RKN"], JOINT_INDEX["REB"]
    w.ref.write(_ref(playing=0, RKN=1.0, RSP=-0.2))
    loop.run(max_ticks=200)
    assert be.sent[-1].ref_rad[RKN] == pytest.approx(1.0, abs=0.01)
    with caplog.at_level("ERROR", logger="daemon.loop"):
        w.ref.write(_ref(playing=0, RKN=3.0, REB=0.5, RSP=-0.4))  # RKN ≤ 2.61, REB ≤ 0
        loop.run(max_ticks=400)
    last = be.sent[-1].ref_rad
    assert last[RKN] == pytest.approx(1.0, abs=0.01)  # held where it was, not 2.61
    assert last[REB] == pytest.approx(0.0)
    assert last[RSP] == pytest.approx(-0.4, abs=0.01)  # the rest of the sample is followed
    assert loop.stats.refs_rejected == 1  # one sample, counted once however long it stands
    s = loop.state
    assert int(s["refs_rejected"]) == 1
    flagged = np.flatnonzero(np.asarray(s["status"]) & int(StatusFlag.REF_REJECTED))
    assert sorted(flagged.tolist()) == sorted([RKN, REB])
    msg = caplog.text
    assert "writer 99" in msg and "RKN 3 rad (allowed [0, 2.61])" in msg and "REB 0.5 rad" in msg
    w.ref.write(_ref(playing=0, RKN=1.5))  # a good sample clears the flags; the count stays
    loop.run(max_ticks=500)
    assert not (np.asarray(loop.state["status"]) & int(StatusFlag.REF_REJECTED)).any()
    assert int(loop.state["refs_rejected"]) == 1
