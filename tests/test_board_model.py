"""The MuJoCo board model: position loop, DC-motor PWM, trips, sensors."""

from __future__ import annotations

import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent / "fixtures"))

from daemon.joint_control import ControlOutput, JointController  # noqa: E402
from daemon.pwm import default_drc_gains  # noqa: E402
from daemon.sim.board_model import BoardModel, BoardModelConfig  # noqa: E402
from daemon.sim.board_trip import BOARDS, BoardTripConfig, BoardTripMonitor  # noqa: E402
from ladders.loader import load_ladder  # noqa: E402
from robot.errors import InputError  # noqa: E402
from robot.joints import JOINT_INDEX, NUM_JOINTS  # noqa: E402
from robot.limits import joint_limits  # noqa: E402
from robot.motors import motor_table, pwm_torque  # noqa: E402


@pytest.fixture(scope="module")
def board() -> BoardModel:
    return BoardModel(load_ladder("drc"))


def _output(ref: np.ndarray, duty: np.ndarray | None = None,
            pwm: np.ndarray | None = None) -> ControlOutput:
    z = np.zeros(NUM_JOINTS, dtype=bool)
    return ControlOutput(ref, np.zeros(NUM_JOINTS) if duty is None else duty,
                         z if pwm is None else pwm, z, z, z, z, z,
                         np.zeros(NUM_JOINTS, dtype=np.int8))


def test_position_loop_saturates_at_the_torque_limit(board):
    board.reset()
    ref = np.zeros(NUM_JOINTS)
    ref[JOINT_INDEX["LSP"]] = -1.0  # 1 rad step: far beyond the 0.02 rad saturation error
    board.apply(_output(ref))
    board.step()
    tau = board.joint_torque()
    limit = joint_limits().torque_max_nm
    j = JOINT_INDEX["LSP"]
    assert tau[j] == pytest.approx(-limit[j], rel=1e-6)
    # a small steady error stays proportional: kp = limit / 0.02 rad
    board.reset()
    ref[j] = -0.005
    board.apply(_output(ref))
    board.apply(_output(ref))  # second tick: the reference no longer moves
    mujoco.mj_forward(board.model, board.data)
    assert board.joint_torque()[j] == pytest.approx(-0.25 * limit[j], rel=0.01)


def test_pwm_duty_to_torque_sign_scale_and_battery():
    table = motor_table()
    j = JOINT_INDEX["LSP"]
    duty = np.zeros(NUM_JOINTS)
    duty[j] = -5.0  # hubo-ach sign: negative duty drives the joint positive
    zero = np.zeros(NUM_JOINTS)
    tau48 = pwm_torque(duty, zero, 48.0, table)[j]
    expected = 0.7 * 250 * 0.060 * (48.0 * 0.05) / 2.8  # η·gear·Kt·V·d/R [N·m]
    assert tau48 == pytest.approx(expected, rel=1e-9)
    assert tau48 > 0
    assert pwm_torque(duty, zero, 24.0, table)[j] == pytest.approx(tau48 / 2)
    vel = np.zeros(NUM_JOINTS)
    vel[j] = 0.1  # back-EMF opposes motion
    assert pwm_torque(duty, vel, 48.0, table)[j] < tau48


def test_board_model_pwm_actuator_is_the_motor_model(board):
    for volts in (48.0, 40.0):
        board.set_battery(volts)
        board.reset()
        j = JOINT_INDEX["LEB"]
        duty = np.zeros(NUM_JOINTS)
        duty[j] = 3.0
        pwm = np.zeros(NUM_JOINTS, dtype=bool)
        pwm[j] = True
        board.apply(_output(board.joint_pos(), duty, pwm))
        board.step()
        mujoco.mj_forward(board.model, board.data)  # forces at the current velocity
        vel = board.joint_vel()
        want = pwm_torque(duty, vel, volts, board.motors)[j]
        assert board.joint_torque()[j] == pytest.approx(want, rel=1e-6)
        assert want < 0  # positive duty pushes towards negative angles
    board.set_battery(48.0)


def test_trip_needs_sustained_overload():
    limit = np.full(NUM_JOINTS, 10.0)
    mon = BoardTripMonitor(limit, BoardTripConfig(trip_after_s=0.5))
    tau = np.zeros(NUM_JOINTS)
    tau[JOINT_INDEX["RSP"]] = 10.0
    for k in range(90):  # 0.45 s at the limit, then a dip: no trip
        assert not mon.update(tau, 0.005, k * 0.005)
    assert not mon.update(np.zeros(NUM_JOINTS), 0.005, 0.45)
    events = []
    for k in range(101):
        events += mon.update(tau, 0.005, 0.5 + k * 0.005)
    assert [e.board for e in events] == ["JMC8"]
    assert mon.tripped[JOINT_INDEX["RSR"]]  # the whole board is off
    assert not mon.tripped[JOINT_INDEX["REB"]]


def test_trip_message_names_the_threshold_used():
    """A torque just under the limit trips at 99% of it; the message says so."""
    limit = np.full(NUM_JOINTS, 60.0)
    mon = BoardTripMonitor(limit)
    tau = np.zeros(NUM_JOINTS)
    tau[JOINT_INDEX["LKN"]] = 59.9
    events = []
    for k in range(101):
        events += mon.update(tau, 0.005, k * 0.005)
    assert events[0].threshold_nm == 0.99 * 60.0
    assert "LKN held |τ| ≥ 59.4 N·m (99% of its 60 N·m limit) for 0.50 s (peak 59.9 N·m)" \
        in str(events[0])


def test_fingers_stalling_do_not_trip_but_their_wrist_roll_does():
    limit = joint_limits().torque_max_nm
    mon = BoardTripMonitor(limit)
    tau = np.zeros(NUM_JOINTS)
    tau[JOINT_INDEX["LF1"]] = limit[JOINT_INDEX["LF1"]]
    for k in range(200):
        assert not mon.update(tau, 0.005, k * 0.005)
    tau[JOINT_INDEX["LWR"]] = -limit[JOINT_INDEX["LWR"]]
    events = []
    for k in range(101):
        events += mon.update(tau, 0.005, 1 + k * 0.005)
    assert [e.board for e in events] == ["EJMC5"]
    assert all(mon.tripped[JOINT_INDEX[j]] for j in BOARDS["EJMC5"])


def test_tripped_board_has_no_torque(board):
    board.reset()
    j = JOINT_INDEX["RKN"]
    board.trips.tripped[j] = True
    ref = np.zeros(NUM_JOINTS)
    ref[j] = 1.0
    board.apply(_output(ref))
    board.step()
    assert board.joint_torque()[j] == 0.0
    assert not board.state().active[j]
    board.reset()


def test_the_gyros_read_their_bias(board):
    """MuJoCo's gyro is exact; the simulated one reads the configured bias on top."""
    from daemon.sim.sensors import SensorIndex, read_sensors

    board.reset()
    board.step()
    index = SensorIndex(board.model)
    bias = np.asarray(board.config.gyro_bias_rad_s)
    assert np.abs(bias).max() > 0.0
    exact = read_sensors(board.data, index).imu
    biased = read_sensors(board.data, index, bias).imu
    assert np.allclose(biased[:, 3:] - exact[:, 3:], bias)
    assert np.array_equal(biased[:, :3], exact[:, :3])
    assert np.allclose(board.state().sensors.imu, biased)


def test_sensors_in_state_units(board):
    board.reset()
    ctl = JointController()
    gains = default_drc_gains()
    for _ in range(200):  # 1 s standing
        out = ctl.tick(np.zeros(NUM_JOINTS), 0, np.zeros(NUM_JOINTS, bool), board.joint_pos(),
                       board.joint_vel(), gains)
        board.apply(out)
        board.step()
    s = board.state()
    mass = 44.4
    ft = s.sensors.ft
    # each foot carries about half the weight, less the foot below the sensor (1.2 kg)
    assert ft[0, 2] == pytest.approx(ft[1, 2], rel=0.05)
    assert ft[0, 2] + ft[1, 2] == pytest.approx((mass - 2 * 1.17) * 9.81, rel=0.05)
    assert np.allclose(s.sensors.imu[:, 2], 9.81, atol=0.1)  # specific force at rest
    assert np.abs(s.sensors.imu[:, 3:]).max() < 0.05  # [rad/s]
    assert s.power_v == 48.0 and s.power_a >= 0 and s.power_w == pytest.approx(48 * s.power_a)
    sample = np.zeros((), dtype=__import__("daemon.structs", fromlist=["STATE_DTYPE"]).STATE_DTYPE)
    board.fill_state(sample)
    assert sample["ft"][1]["fz"] == pytest.approx(ft[1, 2])
    assert sample["power"]["V"] == 48.0


def test_config_refuses_bad_values():
    with pytest.raises(InputError, match="battery"):
        BoardModelConfig(battery_v=500.0)
    with pytest.raises(InputError, match="divide"):
        BoardModelConfig(physics_dt_s=0.002)


def _yaw_deg(R: np.ndarray) -> float:
    return float(np.degrees(np.arctan2(R[1, 0], R[0, 0])))


def test_reset_stands_the_soles_flat_facing_x_with_the_pelvis_turned_as_the_pose_has_it(board):
    """A plan for a ladder placed at a yaw starts with the pelvis turned towards it on
    straight feet (both hip yaws turned). The simulated robot must start in that stance,
    not with an upright pelvis that turns the feet, and the robot, away from its plan."""
    q = np.zeros(NUM_JOINTS)
    q[JOINT_INDEX["LHY"]] = q[JOINT_INDEX["RHY"]] = 0.05  # the pelvis 0.05 rad from the feet
    soles = {"left": np.array([0.0, 0.0885, 0.0]), "right": np.array([0.0, -0.0885, 0.0])}
    board.reset(q, soles)
    d = board.data
    sole_yaws = [_yaw_deg(d.site(f"{s}_sole").xmat.reshape(3, 3)) for s in "LR"]
    assert sole_yaws == pytest.approx([0.0, 0.0], abs=1e-6)
    for s in "LR":
        assert d.site(f"{s}_sole").xmat.reshape(3, 3)[2, 2] == pytest.approx(1.0, abs=1e-9)
    R_pelvis = np.zeros(9)
    mujoco.mju_quat2Mat(R_pelvis, d.qpos[3:7])
    assert abs(_yaw_deg(R_pelvis.reshape(3, 3))) == pytest.approx(np.degrees(0.05), abs=1e-6)
    mean = (d.site("L_sole").xpos + d.site("R_sole").xpos) / 2
    assert mean[:2] == pytest.approx([0.0, 0.0], abs=1e-9)
    assert min(d.site("L_sole").xpos[2], d.site("R_sole").xpos[2]) == pytest.approx(0.0, abs=1e-9)
