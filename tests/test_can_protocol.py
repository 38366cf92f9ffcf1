"""Hubo CAN frames: hand-computed byte vectors, sign-magnitude, round trips, cycle plan."""

from __future__ import annotations

import numpy as np
import pytest

from daemon.can import protocol as cp
from daemon.can.cycle_plan import CyclePlan
from daemon.structs import StatusFlag
from daemon.tables import load_joint_table, load_sensor_table


def _frame(msg):
    return msg.arbitration_id, bytes(msg.data).hex(" ")


def test_reference_frame_bytes():
    # 100 = 0x000064; −5 = sign bit | 5 = 0x800005; little-endian, 3 bytes each.
    assert _frame(cp.encode_ref(3, (100, -5))) == (0x13, "64 00 00 05 00 80")
    # 0x123456 and −(2²³−1): magnitude 0x7FFFFF with the sign bit = 0xFFFFFF.
    assert _frame(cp.encode_ref(0x20, (0x123456, -0x7FFFFF))) == (0x30, "56 34 12 ff ff ff")
    # second motor pair of a many-motor board: id + 0x100
    assert cp.encode_ref(0x24, (1, 0), pair=1).arbitration_id == 0x134
    assert cp.encode_ref(3, (100, -5)).dlc == 6


def test_reference_round_trip_and_range():
    rng = np.random.default_rng(1)
    for c in rng.integers(-cp.MAX_COUNTS, cp.MAX_COUNTS, size=(100, 2)):
        assert cp.decode_ref(cp.encode_ref(7, tuple(c), pair=2)) == (7, 2, tuple(int(x) for x in c))
    with pytest.raises(cp.ProtocolError, match="24-bit range"):
        cp.encode_ref(1, (1 << 23, 0))


def test_sign_magnitude_round_trip():
    w = cp.to_sign_magnitude(np.array([0, 1, -1, -8388607]))
    assert list(w) == [0, 1, 0x800001, 0xFFFFFF]
    assert [cp.from_sign_magnitude(int(x)) for x in w] == [0, 1, -1, -8388607]
    assert cp.from_sign_magnitude(0x800000) == 0  # "minus zero"


def test_command_frames_bytes():
    assert _frame(cp.encode_enc_request(0x0A)) == (0x01, "0a 03 00")
    # 12.5 % = 125 tenths = 0x07D; −100 % = 1000 = 0x3E8, dir bit 0x80 in the hi byte.
    assert _frame(cp.encode_pwm(8, (12.5, -100.0))) == (0x01, "08 0d 03 00 7d 83 e8")
    assert _frame(cp.encode_pwm(0x24, (-0.1, 0.0), pair=1, mask=1)) == (
        0x01,
        "24 0d 11 80 01 00 00",
    )
    jmc, cmd, f = cp.decode_command(cp.encode_pwm(8, (12.5, -100.0)))
    assert (jmc, cmd, f) == (8, 0x0D, {"pair": 0, "mask": 3, "duty_pct": (12.5, -100.0)})
    assert cp.decode_command(cp.encode_enc_request(5)) == (5, 3, {"ch": 0})
    with pytest.raises(cp.ProtocolError, match="outside ±100"):
        cp.encode_pwm(8, (100.1, 0.0))


def test_reply_frames_bytes():
    assert _frame(cp.encode_enc_reply(2, [1, -2])) == (0x62, "01 00 00 00 fe ff ff ff")
    assert cp.decode_enc_reply(cp.encode_enc_reply(0x22, [-70000, 5], pair=1)) == (
        0x22,
        1,
        (-70000, 5),
    )
    assert _frame(cp.encode_status_reply(9, [0x81, 0x00])) == (0x159, "81 00")
    # 1.5 A = 150 = 0x0096; −0.25 A = −25 = 0xFFE7
    assert _frame(cp.encode_current_reply(9, [1.5, -0.25])) == (0x1C9, "96 00 e7 ff")
    assert cp.decode_current_reply(cp.encode_current_reply(9, [1.5, -0.25])) == (9, (1.5, -0.25))


def test_sensor_frames_bytes():
    assert _frame(cp.encode_sensor_request(6, cp.SENSOR_FT)) == (0x02, "06 00")
    # mx 1.5 N·m = 150 = 0x0096; my −2.25 N·m = −225 = 0xFF1F; fz 400 N = 4000 = 0x0FA0
    assert _frame(cp.encode_ft_reply(1, 1.5, -2.25, 400.0)) == (0x41, "96 00 1f ff a0 0f")
    assert cp.decode_ft_reply(cp.encode_ft_reply(7, 1.5, -2.25, -400.0)) == (
        7,
        (1.5, -2.25, -400.0),
    )
    # 9.81 m/s² = 981 = 0x03D5; −0.5 rad/s = −500 = 0xFE0C
    assert _frame(cp.encode_tilt_reply(3, (0.0, 0.0, 9.81))) == (0x53, "00 00 00 00 d5 03")
    assert _frame(cp.encode_gyro_reply(3, (-0.5, 0.0, 0.0))) == (0x5B, "0c fe 00 00 00 00")
    assert cp.decode_imu_reply(cp.encode_gyro_reply(3, (-0.5, 0.25, 1.0))) == (
        3,
        "gyro",
        (-0.5, 0.25, 1.0),
    )
    # 48.0 V = 4800 = 0x12C0; −2.5 A = −250 = 0xFF06
    assert _frame(cp.encode_power_reply(48.0, -2.5)) == (0x4E, "c0 12 06 ff")
    assert cp.decode_power_reply(cp.encode_power_reply(48.0, -2.5)) == (48.0, -2.5, -120.0)
    with pytest.raises(cp.ProtocolError, match="int16"):
        cp.encode_ft_reply(1, 400.0, 0.0, 0.0)


def test_status_bits_to_flags():
    assert cp.board_status_to_flags(0x81) == StatusFlag.OK
    f = cp.board_status_to_flags(0x40)
    assert f & StatusFlag.NOT_HOMED and f & StatusFlag.OVER_CURRENT and f & StatusFlag.TRIPPED


@pytest.fixture(scope="module")
def plan():
    return CyclePlan(load_joint_table(), load_sensor_table())


def test_cycle_plan_budget_and_offsets(plan):
    assert set(plan.buses) == {0, 1}
    assert plan.within_budget()
    assert 0.5 < plan.buses[0].load <= 1.0 and 0.5 < plan.buses[1].load <= 1.0
    n = sum(len(p.frames) for p in plan.buses.values())
    assert 75 <= n <= 90  # hubo-facts: "about 87 frames per 5 ms cycle"
    for p in plan.buses.values():
        offs = [f.offset_s for f in p.tx_frames]
        assert offs[0] == 0.0 and offs[-1] < 0.005
        assert np.allclose(np.diff(offs), 0.005 / len(offs))
    assert "load" in plan.report() and "OVER" not in plan.report()
    legs = {f.arbitration_id for f in plan.buses[0].tx_frames if f.kind == "ref"}
    assert legs == {0x10 + j for j in range(8)} | {0x33}
    extra = plan.housekeeping(0)
    assert all(len(plan.buses[b].frames) + 2 * len(m) <= plan.max_frames for b, m in extra.items())


def test_cycle_encode_decode_round_trip(plan):
    t = plan.joints
    rng = np.random.default_rng(2)
    ref = rng.uniform(-1.5, 1.5, 40)
    tx = plan.encode(ref)
    for b, msgs in tx.items():
        planned = [f.arbitration_id for f in plan.buses[b].tx_frames]
        assert [m.arbitration_id for m in msgs] == planned
    # Boards answer with the counts they were sent.
    rx: dict[int, list] = {0: [], 1: []}
    for b, msgs in tx.items():
        for m in msgs:
            if m.arbitration_id not in (cp.CMD_ID, cp.SENSOR_REQ_ID):
                jmc, pair, counts = cp.decode_ref(m)
                rx[b].append(cp.encode_enc_reply(jmc, counts, pair))
    rx[0].append(cp.encode_ft_reply(2, 0.5, -0.25, 300.0))
    rx[1].append(cp.encode_power_reply(47.5, 3.0))
    rx[1].append(cp.encode_status_reply(8, [0x81, 0x40]))
    r = plan.decode(rx)
    assert r.got_enc.all() and r.unknown == 0
    assert np.array_equal(r.enc, t.rad_to_enc(ref))
    assert np.all(np.abs(r.pos_rad - ref) <= np.abs(t.rad_per_count) / 2 + 1e-12)
    assert tuple(r.ft[1]) == (0.5, -0.25, 300.0) and np.isnan(r.ft[0]).all()
    assert tuple(r.power) == (47.5, 3.0, 142.5)
    rsp, rsr = t["RSP"].index, t["RSR"].index
    assert r.status[rsp] == 0 and r.status[rsr] & StatusFlag.TRIPPED
    assert r.status[0] == StatusFlag.NO_REPLY


def test_cycle_pwm_replaces_reference_frames(plan):
    t = plan.joints
    mask = np.zeros(40, bool)
    arm = [t[n].index for n in ("RSP", "RSR", "RSY", "REB", "RWY", "RWR", "RWP")]
    mask[arm] = True
    duty = np.full(40, 2.5)
    tx = plan.encode(np.zeros(40), duty, mask)[1]
    ids = [m.arbitration_id for m in tx]
    assert 0x18 not in ids and 0x19 not in ids and 0x30 not in ids  # replaced by PWM
    assert 0x34 in ids  # finger board pair 0 keeps its reference (RF1 is not compliant)
    pwm = [cp.decode_command(m) for m in tx if m.arbitration_id == 1 and m.data[1] == 0x0D]
    assert (0x24, 0x0D, {"pair": 0, "mask": 1, "duty_pct": (2.5, 0.0)}) in pwm
    assert len(pwm) == 4
