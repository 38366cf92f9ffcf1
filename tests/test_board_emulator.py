"""The virtual-bus board emulator: references in, encoder replies follow; silent boards."""

from __future__ import annotations

import itertools
import time

import can
import numpy as np
import pytest

from daemon.can import protocol as cp
from daemon.can.cycle_plan import CyclePlan
from daemon.can.emulator import BoardEmulator
from daemon.tables import load_joint_table, load_sensor_table

_ids = itertools.count()


@pytest.fixture()
def rig():
    joints, sensors = load_joint_table(), load_sensor_table()
    k = next(_ids)
    channels = {0: f"emu{k}-can0", 1: f"emu{k}-can1"}
    buses = {b: can.Bus(interface="virtual", channel=c) for b, c in channels.items()}
    emu = BoardEmulator(joints, sensors, channels).start()
    plan = CyclePlan(joints, sensors)
    yield emu, buses, plan
    emu.stop()
    for bus in buses.values():
        bus.shutdown()


def _cycle(buses, frames, wait_s=0.02):
    for b, msgs in frames.items():
        for m in msgs:
            buses[b].send(m)
    rx = {b: [] for b in buses}
    deadline = time.monotonic() + wait_s
    while time.monotonic() < deadline:
        for b, bus in buses.items():
            m = bus.recv(timeout=0.001)
            if m is not None:
                rx[b].append(m)
    return rx


def test_encoder_replies_follow_the_reference(rig):
    emu, buses, plan = rig
    ref = np.linspace(-0.5, 0.5, 40)
    first = plan.decode(_cycle(buses, plan.encode(ref), 0.01))
    assert first.got_enc.all()
    assert np.all(np.abs(first.pos_rad - ref) > 1e-3)  # a first-order lag, not a jump
    deadline = time.monotonic() + 3.0
    while time.monotonic() < deadline:
        r = plan.decode(_cycle(buses, plan.encode(ref), 0.01))
        if np.allclose(r.pos_rad, ref, atol=1e-3):
            break
    assert np.allclose(r.pos_rad, ref, atol=1e-3)
    assert np.all(np.abs(r.pos_rad[:12]) <= np.abs(ref[:12]) + 1e-3)  # approached from 0


def test_sensors_and_housekeeping(rig):
    emu, buses, plan = rig
    emu.set_ft("LHFT", 1.25, -0.5, 20.0)
    emu.set_imu("IMU", (0.1, 0.0, 9.8), (0.0, 0.5, 0.0))
    emu.set_power(50.0, 4.0)
    r = plan.decode(_cycle(buses, plan.encode(np.zeros(40))))
    assert tuple(r.ft[3]) == (1.25, -0.5, 20.0)
    assert np.allclose(r.imu[0], (0.1, 0.0, 9.8, 0.0, 0.5, 0.0))
    assert tuple(r.power) == (50.0, 4.0, 200.0)
    hk = {b: [cp.encode_status_request(0)] for b in (0,)}
    rx = _cycle(buses, hk)
    assert [cp.decode_status_reply(m) for m in rx[0]] == [(0, (0x81, 0x81))]


def test_pwm_moves_at_a_velocity(rig):
    emu, buses, plan = rig
    t = plan.joints
    mask = np.zeros(40, bool)
    mask[t["RSP"].index] = True
    duty = np.zeros(40)
    duty[t["RSP"].index] = -50.0  # −50 % × 0.02 rad/s/% = +1 rad/s (hubo-ach sign)
    _cycle(buses, plan.encode(np.zeros(40), duty, mask), 0.0)
    time.sleep(0.2)
    _cycle(buses, {1: [cp.encode_enc_request(8)]}, 0.01)
    pos = emu.position("RSP")
    assert 0.1 < pos < 0.5
    assert emu.position("RSR") == pytest.approx(0.0, abs=1e-9)


def test_silent_board_does_not_reply(rig):
    emu, buses, plan = rig
    emu.silence(3, can_bus=0)  # JMC3: RAP, RAR
    emu.silence(6, sensor=True)  # right-hand FT board (not JMC6, the left knee)
    r = plan.decode(_cycle(buses, plan.encode(np.zeros(40))))
    silent = {plan.joints["RAP"].index, plan.joints["RAR"].index}
    assert set(np.flatnonzero(~r.got_enc)) == silent
    assert np.isnan(r.ft[2]).all() and not np.isnan(r.ft[3]).any()
    emu.silence(3, can_bus=0, silent=False)
    r = plan.decode(_cycle(buses, plan.encode(np.zeros(40))))
    assert r.got_enc.all()


def test_stop_is_clean_and_idempotent():
    joints, sensors = load_joint_table(), load_sensor_table()
    emu = BoardEmulator(joints, sensors, {0: "emu-stop-0"})
    with emu:
        assert all(s.thread.is_alive() for s in emu._sims)
        threads = [s.thread for s in emu._sims]
    assert not any(t.is_alive() for t in threads)
    emu.stop()
