"""Grip bending relief: a compliant gripping arm takes a grip's bending above the onset
off by feed-forward, on the bending it senses through its motor currents."""

from __future__ import annotations

import numpy as np
import pytest

from execute.motion.grip_bending_relief import GripBendingRelief
from execute.motion.robot_model import MotionRobotModel
from robot.joints import ARM_JOINTS, JOINT_INDEX, NUM_JOINTS

TICK_S = 0.005
CAPACITY_NM = 9.0
RAIL = np.array([0.0, 0.0, 1.0])  # the rail's axis, world (pelvis upright)
LEFT = [JOINT_INDEX[n] for n in ARM_JOINTS["left"]]


@pytest.fixture(scope="module")
def model():
    return MotionRobotModel()


def _gripping_arm() -> np.ndarray:
    q = np.zeros(NUM_JOINTS)
    q[JOINT_INDEX["LSP"]], q[JOINT_INDEX["LSR"]] = -1.2, 0.2
    q[JOINT_INDEX["LEB"]], q[JOINT_INDEX["LWP"]] = -0.8, 0.3
    return q


def _closed_chain(model, q, rail_wrench: np.ndarray):
    """A held arm that does not move: the arm's own torques (its PWM law's pull on its
    reference), fixed, that make the rail push the palm with ``rail_wrench`` (f, m); the
    motor torques the currents read are those plus whatever feed-forward is added, and
    the rail's wrench follows from ``τ = g − Jᵀw`` (statics of the closed chain)."""
    g = model.gravity_torques(q, np.eye(3))
    jt = model.wrench_torques(q, np.eye(3), "left_hand", rail_wrench[:3], rail_wrench[3:])
    return g - jt  # the torques that hold that wrench


def _bending(model, q, torque_nm) -> tuple[float, float]:
    """(bending across the rail, moment about it) the currents say [N·m]."""
    m = model.hand_wrench(q, np.eye(3), "left_hand", torque_nm)[3:]
    along = float(m @ RAIL)
    return float(np.linalg.norm(m - along * RAIL)), along


def test_the_bending_above_the_onset_is_taken_off_and_the_twist_left(model):
    q = _gripping_arm()
    wrench = np.array([5.0, -10.0, 30.0, 6.0, -4.0, 0.8])  # 7.2 N·m across, 0.8 about
    held = _closed_chain(model, q, wrench)
    assert _bending(model, q, held)[0] == pytest.approx(np.hypot(6.0, 4.0), rel=1e-3)
    relief = GripBendingRelief(model, CAPACITY_NM, onset_share=0.45, release_share=0.3)
    torque = held
    for _ in range(400):  # 2 s
        relief.update("left", True, q, np.eye(3), torque, RAIL, TICK_S)
        torque = held + relief.feedforward_nm("left", q, np.eye(3))
    bending, along = _bending(model, q, torque)
    assert bending == pytest.approx(0.45 * CAPACITY_NM, rel=0.02)  # back at the onset
    assert along == pytest.approx(0.8, abs=1e-3)
    ff = relief.feedforward_nm("left", q, np.eye(3))
    others = np.setdiff1d(np.arange(NUM_JOINTS), LEFT)
    assert ff[LEFT].any() and not ff[others].any()  # the holding arm's joints only
    assert "left" in relief.active and relief.peak_moment_nm > 0.0


def test_below_the_onset_nothing_is_added(model):
    q = _gripping_arm()
    held = _closed_chain(model, q, np.array([0.0, 0.0, 30.0, 2.0, 1.0, 0.5]))
    relief = GripBendingRelief(model, CAPACITY_NM, onset_share=0.45, release_share=0.3)
    for _ in range(100):
        relief.update("left", True, q, np.eye(3), held, RAIL, TICK_S)
    assert not relief.feedforward_nm("left", q, np.eye(3)).any()
    assert "left" not in relief.active


def test_the_term_shrinks_once_the_bending_is_low_and_is_dropped_when_the_hand_lets_go(model):
    q = _gripping_arm()
    relief = GripBendingRelief(model, CAPACITY_NM, onset_share=0.45, release_share=0.3,
                               decay_nm_per_s=1.0)
    high = _closed_chain(model, q, np.array([0.0, 0.0, 30.0, 8.0, 0.0, 0.0]))
    for _ in range(200):
        relief.update("left", True, q, np.eye(3), high, RAIL, TICK_S)
    grown = float(np.linalg.norm(relief.moment_nm["left"]))
    assert grown > 1.0
    low = _closed_chain(model, q, np.zeros(6))  # the load gone: the term alone bends
    for _ in range(100):  # 0.5 s at 1 N·m/s
        relief.update("left", True, q, np.eye(3), low, RAIL, TICK_S)
    assert float(np.linalg.norm(relief.moment_nm["left"])) == pytest.approx(grown - 0.5,
                                                                              abs=0.02)
    relief.update("left", False, q, np.eye(3), low, RAIL, TICK_S)
    assert not relief.feedforward_nm("left", q, np.eye(3)).any()
    assert "left" not in relief.active


def test_the_term_is_bounded(model):
    q = _gripping_arm()
    relief = GripBendingRelief(model, CAPACITY_NM, max_moment_share=0.5)
    stuck = _closed_chain(model, q, np.array([0.0, 0.0, 30.0, 20.0, 0.0, 0.0]))
    for _ in range(2000):  # the currents never change: a saturated arm
        relief.update("left", True, q, np.eye(3), stuck, RAIL, TICK_S)
    assert float(np.linalg.norm(relief.moment_nm["left"])) == pytest.approx(4.5)


def test_an_onset_below_its_release_is_refused(model):
    with pytest.raises(ValueError):
        GripBendingRelief(model, CAPACITY_NM, onset_share=0.3, release_share=0.45)



def test_the_term_loads_no_stance_leg_joint_near_its_limit(model):
    """The moment taken off a grip goes to the legs: with the left knee above the guard,
    no step of the term raises the knee's torque (∂τ/∂m = b, the knee's angular column
    of the sole's Jacobian), and the term keeps no part along the rail. The knee alone
    hot, the bending across the knee's axis is still taken off."""
    q = _gripping_arm()
    q[JOINT_INDEX["LHP"]], q[JOINT_INDEX["LKN"]], q[JOINT_INDEX["LAP"]] = -0.4, 0.8, -0.4
    knee = JOINT_INDEX["LKN"]
    relief = GripBendingRelief(model, CAPACITY_NM, onset_share=0.35, release_share=0.23,
                               leg_guard_share=0.85)
    bent = _closed_chain(model, q, np.array([0.0, 0.0, 30.0, 5.0, 5.0, 0.0]))  # 0.79
    b = model.stance_moment_gradient(q, np.eye(3), np.array([knee]), "left_foot")[0]
    assert abs(b[1]) > 0.9  # the knee turns about y: a moment about y loads it
    for knee_sign, stance in ((1.0, ("left",)), (-1.0, ("left",)), (1.0, ())):
        relief.update("left", False, q, np.eye(3), bent, RAIL, TICK_S)  # a fresh term
        torque = bent.copy()
        for _ in range(400):
            torque[knee] = knee_sign * 0.9 * relief.limit_nm[knee]
            relief.update("left", True, q, np.eye(3), torque, RAIL, TICK_S, stance)
            torque = bent + relief.feedforward_nm("left", q, np.eye(3))
        term = relief.moment_nm["left"]
        assert abs(term @ RAIL) < 1e-6
        if stance:
            assert knee_sign * (b @ term) <= 1e-6  # the hot knee is not loaded further
            assert abs(term[0]) > 1.0  # the bending about x is still taken off
        else:  # no stance leg: the whole excess is taken off
            assert _bending(model, q, torque)[0] == pytest.approx(0.35 * CAPACITY_NM,
                                                                  rel=0.02)
