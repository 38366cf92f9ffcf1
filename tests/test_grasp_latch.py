"""The grasp latch: latches on the rail, not off it; lets go on opening, overload, trip."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent / "fixtures"))

from make_fixture import cached_reach_fixture  # noqa: E402

from daemon.control_modes import RefMode  # noqa: E402
from daemon.joint_control import JointController  # noqa: E402
from daemon.pwm import default_drc_gains  # noqa: E402
from daemon.sim.board_model import PlacementError  # noqa: E402
from daemon.sim.grasp_latch import GripCapacity, GripConfig  # noqa: E402
from execute.validate.metrics import compute_metrics  # noqa: E402
from execute.validate.simulate import SimulationOptions, simulate  # noqa: E402
from ladders.contact_model import GripGeometry  # noqa: E402
from ladders.loader import sidecar_ladder  # noqa: E402
from robot.joints import ARM_JOINTS, FINGER_JOINTS, JOINT_INDEX, NUM_JOINTS  # noqa: E402
from robot.kinematic_tree import FINGER_CLOSED_RAD  # noqa: E402
from robot.plan_sidecar import read_sidecar, sidecar_path  # noqa: E402
from robot.trajectory_file import read_trajectory  # noqa: E402


@pytest.fixture(scope="module")
def plan(tmp_path_factory):
    path = cached_reach_fixture(tmp_path_factory.getbasetemp())
    sc = read_sidecar(sidecar_path(path))
    return read_trajectory(path, sc.rate_hz), sc, sidecar_ladder(sc, str(path))


@pytest.fixture(scope="module")
def latched_run(plan):
    traj, sc, ladder = plan
    return simulate(traj, sc, ladder, SimulationOptions(strategy="mixed", record_qpos=False))


def _holding_ref(board) -> np.ndarray:
    """The pose where the robot stands, both hands commanded closed (a latched hand's
    fingers stand on the rail, short of the closed reference)."""
    ref = board.joint_pos()
    for hand in ("left", "right"):
        ref[[JOINT_INDEX[f] for f in FINGER_JOINTS[hand]]] = FINGER_CLOSED_RAD
    return ref


def _hold(run, ticks: int, ref: np.ndarray, extra=None, limp_arm: str | None = None) -> list:
    """Keep stepping a finished run's board with the control law at ``ref``; the arm
    ``limp_arm`` in PWM with its reference on its encoder (no stiffness)."""
    board = run.board
    ctl = JointController()
    gains = default_drc_gains()
    comply = np.zeros(NUM_JOINTS, dtype=bool)
    mode = np.full(NUM_JOINTS, int(RefMode.FILTER), dtype=np.int8)
    # the fingers' sent reference is the commanded one from the first tick (a fresh
    # controller's filter would start from the encoders, which stand on the rail)
    mode[[JOINT_INDEX[f] for hand in FINGER_JOINTS.values() for f in hand]] = RefMode.DIRECT
    if limp_arm is not None:
        arm = [JOINT_INDEX[n] for n in ARM_JOINTS[limp_arm]]
        comply[arm], mode[arm] = True, RefMode.COMPLIANT
    events = []
    for k in range(ticks):
        if extra is not None:
            extra(k)
        out = ctl.tick(ref, mode, comply, board.joint_pos(), board.joint_vel(), gains)
        board.apply(out)
        events += board.step()[1]
    return events


def test_capacity_from_finger_torque():
    cfg = GripConfig()
    cap = GripCapacity.of(cfg.grip, friction=0.4, rail_radius_m=0.025)
    assert cap.radial_n == pytest.approx(5 * 5.0 / 0.06)
    assert cap.squeeze_n == pytest.approx(5 * cfg.grip.finger_squeeze_nm / 0.06)
    # fingers and palm each press the rail with the squeeze, one of them also with the load
    assert cap.along_n(100.0) == pytest.approx(0.4 * (2 * cap.squeeze_n + 100.0))
    assert cap.about_nm(100.0) == pytest.approx(cap.along_n(100.0) * 0.025)
    axis = np.array([0.0, 0.0, 1.0])
    parts = cap.utilisation(np.array([cap.radial_n * 1.5, 0, 0]), np.zeros(3), axis)
    assert parts["radial force"] == pytest.approx(1.5)
    assert max(parts, key=parts.get) == "radial force"
    # a hook that does not squeeze holds nothing along a rail nothing presses it onto
    hook = GripCapacity.of(GripGeometry(finger_squeeze_nm=0.0), friction=0.4,
                           rail_radius_m=0.025)
    along = hook.utilisation(np.array([0.0, 0.0, 10.0]), np.zeros(3), axis)
    assert along["force along the rail"] == math.inf
    assert along["torque about the rail"] == 0.0


def test_latches_on_the_rail(latched_run):
    latched = [g for g in latched_run.log.grasps if g.kind == "latched"]
    assert {g.hand for g in latched} == {"left", "right"}
    for g in latched:
        assert g.rail == f"rail_{g.hand}"
        assert g.distance_m <= 0.02 and g.angle_rad <= np.radians(20)
    assert latched_run.board.latches["left"].latched


def test_palm_off_the_rail_grasps_nothing(plan):
    traj, sc, ladder = plan
    # ladder 11.5 cm further away: the rails sit ≈ 10 cm beyond the closing palms
    run = simulate(traj, sc, ladder, SimulationOptions(
        strategy="position", placement=PlacementError(0.115, 0.0, 0.0), record_qpos=False,
        closed_loop=False))
    assert not any(g.kind == "latched" for g in run.log.grasps)
    missed = [g for g in run.log.grasps if g.kind == "missed"]
    assert missed and all(0.08 < g.distance_m < 0.12 for g in missed)
    assert run.verdict.failure.cause == "grasp_not_latched"


def test_fingers_stop_on_the_rail_they_hold(latched_run):
    """The finger encoders tell a grip on a rail from a fist: latched fingers stop where
    they meet the rail, far short of fully closed."""
    board = latched_run.board
    for hand in ("left", "right"):
        curl = board.joint_pos()[[JOINT_INDEX[f] for f in FINGER_JOINTS[hand]]]
        stop = board.latches[hand].rail_contact_curl_rad
        assert board.latches[hand].latched
        assert np.all(np.abs(curl - stop) < 0.06)  # the joint limit is a soft constraint
        assert np.all(curl < 0.5 * FINGER_CLOSED_RAD)


def test_releases_when_fingers_open(latched_run, plan):
    ref = _holding_ref(latched_run.board)
    ref[[JOINT_INDEX[f] for f in FINGER_JOINTS["left"]]] = 0.0
    events = _hold(latched_run, 200, ref)
    assert any(g.kind == "released" and g.hand == "left" and "open" in g.reason
               for g in events)
    assert not latched_run.board.latches["left"].latched
    assert latched_run.board.latches["right"].latched


def test_releases_over_load(plan):
    traj, sc, ladder = plan
    run = simulate(traj, sc, ladder, SimulationOptions(strategy="mixed", record_qpos=False))
    board = run.board
    hand = board.latches["right"].body_id
    cap = board.latches["right"].capacity
    ref = _holding_ref(board)
    # below capacity: holds
    board.data.xfrc_applied[hand, :3] = (0.0, 0.0, -0.5 * cap.radial_n)
    assert not _hold(run, 40, ref)
    # a pull of twice the radial capacity, away from the rail: it lets go
    board.data.xfrc_applied[hand, :3] = (0.0, 0.0, -2.0 * cap.radial_n)
    events = _hold(run, 40, ref)
    board.data.xfrc_applied[:] = 0.0
    rel = [g for g in events if g.kind == "released"]
    assert rel and rel[0].hand == "right" and "what the grip holds" in rel[0].reason



def _offset_from_anchor(latch, axis) -> tuple[float, float]:
    """The hand's turn about [rad] and slide along [m] the rail from the weld's anchor."""
    d, eq = latch.data, latch.model.eq_data[latch.eq_id]
    R_l = d.xmat[latch.ladder_body].reshape(3, 3)
    anchor = R_l @ eq[0:3] + d.xpos[latch.ladder_body]
    q_anchor, q_err, rotvec = np.zeros(4), np.zeros(4), np.zeros(3)
    neg = np.zeros(4)
    mujoco.mju_negQuat(neg, eq[6:10])
    mujoco.mju_mulQuat(q_anchor, d.xquat[latch.ladder_body], neg)
    mujoco.mju_negQuat(neg, q_anchor)
    mujoco.mju_mulQuat(q_err, d.xquat[latch.body_id], neg)
    mujoco.mju_quat2Vel(rotvec, q_err, 1.0)
    return float(rotvec @ axis), float((d.site_xpos[latch.palm_site] - anchor) @ axis)


def test_a_slipping_grip_moves_its_anchor_to_leave_the_capacity(latched_run):
    """Twice the friction limit about and along the rail: the weld's anchor moves half
    way to the hand in both directions (its spring then carries the capacity); within
    the limit it stays."""
    latch = latched_run.board.latches["right"]
    axis = latch._rail_axis(latch.rail)
    eq = latch.model.eq_data[latch.eq_id]
    slipped_rad, slipped_m = latch.slip_rad, latch.slip_m
    net = (latch._grasp_turn_rad, latch._grasp_slide_m)
    saved = eq.copy()
    turn = np.zeros(4)
    mujoco.mju_axisAngle2Quat(turn, axis, 0.03)  # the anchor 0.03 rad and 4 mm off
    mujoco.mju_mulQuat(eq[6:10], saved[6:10].copy(), turn)
    R_l = latch.data.xmat[latch.ladder_body].reshape(3, 3)
    eq[0:3] -= R_l.T @ axis * 0.004
    try:
        before = _offset_from_anchor(latch, axis)
        latch._slip({"force along the rail": 0.9, "torque about the rail": 0.9}, axis)
        assert _offset_from_anchor(latch, axis) == pytest.approx(before)
        latch._slip({"force along the rail": 2.0, "torque about the rail": 2.0}, axis)
        after = _offset_from_anchor(latch, axis)
        assert abs(before[0]) > 0.015 and abs(before[1]) > 0.003
        assert after == pytest.approx((before[0] / 2, before[1] / 2), rel=1e-3)
        assert latch.slip_rad - slipped_rad == pytest.approx(abs(before[0]) / 2, rel=1e-3)
        assert latch.slip_m - slipped_m == pytest.approx(abs(before[1]) / 2, rel=1e-3)
        # this grasp's net turn and slide moved by the same, signed
        assert abs(latch._grasp_turn_rad - net[0]) == pytest.approx(abs(before[0]) / 2,
                                                                     rel=1e-3)
        assert abs(latch._grasp_slide_m - net[1]) == pytest.approx(abs(before[1]) / 2, rel=1e-3)
        assert latch.max_grasp_turn_rad >= abs(latch._grasp_turn_rad)
    finally:
        eq[:] = saved



def test_a_grip_turns_on_its_rail_and_holds(plan):
    """Twice the friction limit about the rail, on a hand whose arm is limp: the closed
    hand turns on the rail, the weld carries no more than the grip's friction, and the
    hand stays latched."""
    traj, sc, ladder = plan
    run = simulate(traj, sc, ladder, SimulationOptions(strategy="mixed", record_qpos=False))
    latch = run.board.latches["right"]
    axis = latch._rail_axis(latch.rail)
    force, _ = latch.grip_load()
    radial_n = float(np.linalg.norm(force - (force @ axis) * axis))
    run.board.data.xfrc_applied[latch.body_id, 3:6] = 2.0 * latch.capacity.about_nm(radial_n) * axis
    about_rail = []

    def record(_k):
        force, torque = latch.grip_load()
        about_rail.append(latch.capacity.utilisation(force, torque, axis)["torque about the rail"])

    events = _hold(run, 100, _holding_ref(run.board), record, limp_arm="right")
    assert not events and latch.latched
    assert latch.slip_rad > 0.0
    metrics = compute_metrics(run)
    turn_deg = metrics.max_hand_turn_per_grasp_deg["right"]
    assert 0.0 < turn_deg == pytest.approx(np.degrees(latch.max_grasp_turn_rad))
    assert latch.max_grasp_turn_rad <= latch.slip_rad + 1e-12  # net of one grasp ≤ the sum
    assert max(about_rail) == pytest.approx(1.0, abs=0.05)
