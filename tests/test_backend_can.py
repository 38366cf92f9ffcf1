"""The CAN backend on python-can's virtual buses, against the board emulator."""

from __future__ import annotations

import itertools
import sys
import time

import can
import numpy as np
import pytest

from daemon.backend import BoardCommands
from daemon.can import protocol as cp
from daemon.can.backend import CanBackend, parse_channels
from daemon.can.emulator import BoardEmulator
from daemon.loop import DaemonChannels, DaemonLoop, LoopConfig
from daemon.structs import REF_DTYPE, BoardCommandType, StatusFlag, new_sample
from daemon.tables import load_joint_table, load_sensor_table
from robot.errors import InputError
from robot.joints import JOINT_INDEX

_ids = itertools.count()


@pytest.fixture()
def rig():
    k = next(_ids)
    chans = (f"bcan{k}-0", f"bcan{k}-1")
    joints, sensors = load_joint_table(), load_sensor_table()
    emu = BoardEmulator(joints, sensors, {0: chans[0], 1: chans[1]}).start()
    sniff = {b: can.Bus(interface="virtual", channel=c) for b, c in enumerate(chans)}
    be = CanBackend("virtual", chans)
    old = sys.getswitchinterval()
    sys.setswitchinterval(0.0005)
    yield be, emu, sniff
    sys.setswitchinterval(old)
    be.close()
    emu.stop()
    for bus in sniff.values():
        bus.shutdown()


def _sent(sniff) -> dict[int, list[can.Message]]:
    out = {}
    for b, bus in sniff.items():
        out[b] = []
        while (m := bus.recv(0.0)) is not None:
            out[b].append(m)
    return out


def _ours(msgs):
    """Frames the daemon sent (requests, references, commands), not the boards' replies."""
    return [m for m in msgs if m.arbitration_id < 0x40 or cp.REF_BASE <=
            m.arbitration_id % cp.PAIR_STRIDE < cp.REF_BASE + 0x30 and m.dlc == 6]


def test_frames_carry_the_expected_ids_and_encodings(rig):
    be, emu, sniff = rig
    joints = be.joints
    ref = np.linspace(-0.4, 0.4, 40)
    pwm = np.zeros(40, bool)
    pwm[JOINT_INDEX["LSP"]] = pwm[JOINT_INDEX["LSR"]] = True
    duty = np.zeros(40)
    duty[JOINT_INDEX["LSP"]], duty[JOINT_INDEX["LSR"]] = -3.5, 2.0
    _sent(sniff)
    be.write_commands(BoardCommands(ref, duty, pwm))
    be.idle(time.monotonic_ns() + 10_000_000)
    time.sleep(0.01)
    frames = _sent(sniff)
    refs = {}
    pwms = []
    for b, msgs in frames.items():
        for m in msgs:
            if m.arbitration_id == cp.CMD_ID and m.data[1] == cp.CMD_PWM:
                pwms.append((b, cp.decode_command(m)))
            elif cp.REF_BASE <= m.arbitration_id % cp.PAIR_STRIDE < cp.REF_BASE + 0x30 \
                    and m.dlc == 6:
                jmc, pair, counts = cp.decode_ref(m)
                refs[(b, jmc, pair)] = counts
    for (b, jmc), chans in joints.boards().items():
        for pair in range((len(chans) + 1) // 2):
            two = chans[2 * pair: 2 * pair + 2]
            if any(j >= 0 and pwm[j] for j in two):
                continue
            counts = refs[(b, jmc, pair)]
            for k, j in enumerate(two):
                if j >= 0:
                    assert counts[k] == joints.rad_to_enc(ref[[j]], np.array([j]))[0]
    lsp = joints["LSP"]
    assert pwms == [(1, (lsp.jmc, cp.CMD_PWM, {"pair": 0, "mask": 3,
                                                "duty_pct": (-3.5, 2.0)}))]
    assert (1, lsp.jmc, 0) not in refs  # the PWM frame replaced the pair's reference


def test_sends_are_spread_over_the_period(rig):
    be, emu, sniff = rig
    _sent(sniff)
    t0 = time.monotonic_ns()
    be.write_commands(BoardCommands(np.zeros(40), np.zeros(40), np.zeros(40, bool)))
    first = len(_ours(_sent(sniff)[1]))  # the first slot goes out at once
    be.idle(t0 + 5_000_000)
    rest = len(_ours(_sent(sniff)[1]))
    assert 0 < first < rest  # most frames wait for their slot in the period
    assert be.tx_errors == 0 and not be._queue


def test_board_command_frames(rig):
    be, emu, sniff = rig
    _sent(sniff)
    be.board_command(BoardCommandType.HOME, JOINT_INDEX["RKN"])
    time.sleep(0.01)
    msgs = [m for m in _sent(sniff)[0] if m.arbitration_id == cp.CMD_ID]
    rkn = be.joints["RKN"]
    assert [bytes(m.data) for m in msgs] == [bytes([rkn.jmc, 0x11, rkn.mot_no + 1])]


def _run_ticks(loop, n_ticks):
    """Run the loop for ``n_ticks`` more ticks: counted, not timed, so a loaded machine
    (a late tick is skipped, not run) does not shorten the test's window."""
    loop.run(max_ticks=loop.stats.ticks + n_ticks)


def test_encoders_follow_and_a_silent_board_is_flagged_not_fatal(rig):
    be, emu, sniff = rig
    inst = f"bcanloop{next(_ids)}"
    loop = DaemonLoop(be, DaemonChannels.open(inst, in_process=True),
                      LoopConfig(startup_ignore_s=0.0))
    loop.zeroed[:] = True
    w = DaemonChannels.open(inst, in_process=True, writer_id=3)
    loop.start()
    r = new_sample(REF_DTYPE)
    r["ref"][JOINT_INDEX["RKN"]] = 0.5
    r["ref"][JOINT_INDEX["LEB"]] = -0.4
    r["mode"][:] = 1  # direct
    w.ref.write(r)
    _run_ticks(loop, 160)
    s = loop.state
    assert s["pos"][JOINT_INDEX["RKN"]] == pytest.approx(0.5, abs=0.01)
    assert s["pos"][JOINT_INDEX["LEB"]] == pytest.approx(-0.4, abs=0.01)
    rap, rar = JOINT_INDEX["RAP"], JOINT_INDEX["RAR"]
    # a late reply (a loaded machine) may flag a tick here and there, a silent board every one
    emu.silence(be.joints["RAP"].jmc, can_bus=0)
    ticks, misses = loop.stats.ticks, be.no_reply_ticks.copy()
    _run_ticks(loop, 60)
    n = loop.stats.ticks - ticks
    assert n == 60  # the loop went on
    missed = be.no_reply_ticks - misses
    assert missed[rap] >= n - 2 and missed[rar] >= n - 2
    assert np.delete(missed, [rap, rar]).max() < n / 2
    s = loop.state
    assert s["status"][rap] & int(StatusFlag.NO_REPLY) and not s["active"][rap]
    assert s["pos"][JOINT_INDEX["RKN"]] == pytest.approx(0.5, abs=0.01)
    emu.silence(be.joints["RAP"].jmc, can_bus=0, silent=False)
    _run_ticks(loop, 20)
    ticks, misses = loop.stats.ticks, be.no_reply_ticks.copy()
    _run_ticks(loop, 60)
    assert (be.no_reply_ticks - misses)[rap] < (loop.stats.ticks - ticks) / 2


def test_bad_channels_and_interfaces_are_input_errors():
    with pytest.raises(InputError, match="two channel names"):
        parse_channels("can0")
    with pytest.raises(InputError, match="cannot open CAN bus 0"):
        CanBackend("no-such-interface", ("a", "b"))
