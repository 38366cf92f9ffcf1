"""Grip bending relief: a compliant gripping arm takes a grip's bending above the onset
off by feed-forward on its shoulder and elbow, on the bending it senses through its motor
currents.

The arm is held at its wrist's yaw–roll alignment (wrist pitch 0), where the grips bend:
there the wrist cannot turn about one direction ``u``, its joints carry no torque for a
moment about ``u``, and the shoulder and elbow alone hold it, so a rigid closed chain is
the arm's statics for that moment.
"""

from __future__ import annotations

import numpy as np
import pytest

from execute.motion.grip_bending_relief import GripBendingRelief
from execute.motion.robot_model import MotionRobotModel
from robot.joints import ARM_JOINTS, JOINT_INDEX, NUM_JOINTS

TICK_S = 0.005
CAPACITY_NM = 9.0
LEFT = [JOINT_INDEX[n] for n in ARM_JOINTS["left"]]
WRIST = [JOINT_INDEX[n] for n in ("LWY", "LWR", "LWP")]


@pytest.fixture(scope="module")
def model():
    return MotionRobotModel()


@pytest.fixture(scope="module")
def aligned(model):
    """(q, u, rail): a left arm on a rail at wrist pitch 0, the stance leg bent; ``u``
    the direction the wrist cannot turn about, ``rail`` the rail's axis (the wrist
    pitch's, across ``u``)."""
    q = np.zeros(NUM_JOINTS)
    q[JOINT_INDEX["LSP"]], q[JOINT_INDEX["LSR"]], q[JOINT_INDEX["LEB"]] = -1.2, 0.2, -0.8
    q[JOINT_INDEX["LHP"]], q[JOINT_INDEX["LKN"]], q[JOINT_INDEX["LAP"]] = -0.4, 0.8, -0.4
    axes = np.array([model.wrench_torques(q, np.eye(3), "left_hand", np.zeros(3), e)[WRIST]
                     for e in np.eye(3)]).T  # rows: the wrist joints' axes, world
    assert np.allclose(axes[0], axes[1])  # yaw and roll in line
    u = np.cross(axes[0], axes[2])
    return q, u / np.linalg.norm(u), axes[2] / np.linalg.norm(axes[2])


def _closed_chain(model, q, rail_wrench: np.ndarray):
    """A held arm that does not move: the arm's own torques (its PWM law's pull on its
    reference), fixed, that make the rail push the palm with ``rail_wrench`` (f, m); the
    motor torques the currents read are those plus whatever feed-forward is added, and
    the rail's wrench follows from ``τ = g − Jᵀw`` (statics of the closed chain)."""
    g = model.gravity_torques(q, np.eye(3))
    jt = model.wrench_torques(q, np.eye(3), "left_hand", rail_wrench[:3], rail_wrench[3:])
    return g - jt  # the torques that hold that wrench


def _bending(model, q, torque_nm, rail) -> tuple[float, float]:
    """(bending across the rail, moment about it) the currents say [N·m]."""
    m = model.hand_wrench(q, np.eye(3), "left_hand", torque_nm)[3:]
    along = float(m @ rail)
    return float(np.linalg.norm(m - along * rail)), along


def test_the_bending_above_the_onset_is_taken_off_and_the_twist_left(model, aligned):
    q, u, rail = aligned
    wrench = np.r_[5.0, -10.0, 30.0, 7.2 * u + 0.8 * rail]
    held = _closed_chain(model, q, wrench)
    assert _bending(model, q, held, rail)[0] == pytest.approx(7.2, rel=1e-3)
    relief = GripBendingRelief(model, CAPACITY_NM, onset_share=0.45, release_share=0.3)
    torque = held
    for _ in range(400):  # 2 s
        relief.update("left", True, q, np.eye(3), torque, rail, TICK_S)
        torque = held + relief.feedforward_nm("left", q, np.eye(3))
    bending, along = _bending(model, q, torque, rail)
    assert bending == pytest.approx(0.45 * CAPACITY_NM, rel=0.02)  # back at the onset
    assert along == pytest.approx(0.8, abs=1e-3)
    ff = relief.feedforward_nm("left", q, np.eye(3))
    shoulder_and_elbow = [c for c in LEFT if c not in WRIST]
    assert np.abs(ff[shoulder_and_elbow]).max() > 0.5
    assert not ff[np.setdiff1d(np.arange(NUM_JOINTS), shoulder_and_elbow)].any()
    assert "left" in relief.active and relief.peak_moment_nm > 0.0


def test_below_the_onset_nothing_is_added(model, aligned):
    q, u, rail = aligned
    held = _closed_chain(model, q, np.r_[0.0, 0.0, 30.0, 2.5 * u + 0.5 * rail])
    relief = GripBendingRelief(model, CAPACITY_NM, onset_share=0.45, release_share=0.3)
    for _ in range(100):
        relief.update("left", True, q, np.eye(3), held, rail, TICK_S)
    assert not relief.feedforward_nm("left", q, np.eye(3)).any()
    assert "left" not in relief.active


def test_the_term_shrinks_once_the_bending_is_low_and_is_dropped_when_the_hand_lets_go(
        model, aligned):
    q, u, rail = aligned
    relief = GripBendingRelief(model, CAPACITY_NM, onset_share=0.45, release_share=0.3,
                               decay_nm_per_s=1.0)
    high = _closed_chain(model, q, np.r_[0.0, 0.0, 30.0, 8.0 * u])
    for _ in range(200):
        relief.update("left", True, q, np.eye(3), high, rail, TICK_S)
    grown = float(np.linalg.norm(relief.moment_nm["left"]))
    assert grown > 1.0
    low = _closed_chain(model, q, np.zeros(6))  # the load gone: the term alone bends
    for _ in range(100):  # 0.5 s at 1 N·m/s
        relief.update("left", True, q, np.eye(3), low, rail, TICK_S)
    assert float(np.linalg.norm(relief.moment_nm["left"])) == pytest.approx(grown - 0.5,
                                                                              abs=0.02)
    relief.update("left", False, q, np.eye(3), low, rail, TICK_S)
    assert not relief.feedforward_nm("left", q, np.eye(3)).any()
    assert "left" not in relief.active


def test_the_term_is_bounded(model, aligned):
    q, u, rail = aligned
    relief = GripBendingRelief(model, CAPACITY_NM, max_moment_share=0.5)
    stuck = _closed_chain(model, q, np.r_[0.0, 0.0, 30.0, 20.0 * u])
    for _ in range(2000):  # the currents never change: a saturated arm
        relief.update("left", True, q, np.eye(3), stuck, rail, TICK_S)
    assert float(np.linalg.norm(relief.moment_nm["left"])) == pytest.approx(4.5)


def test_an_onset_below_its_release_is_refused(model):
    with pytest.raises(ValueError):
        GripBendingRelief(model, CAPACITY_NM, onset_share=0.3, release_share=0.45)


def test_the_term_loads_no_stance_leg_joint_near_its_limit(model, aligned):
    """The moment taken off a grip goes to the legs: with the left hip roll above the
    guard, no step of the term raises its torque (∂τ/∂m = b, the joint's angular column
    of the sole's Jacobian), and the term keeps no part along the rail; something is
    still taken off. With no stance leg the whole excess is."""
    q, u, rail = aligned
    hip = JOINT_INDEX["LHR"]
    v = np.cross(rail, u)  # the other direction across the rail
    bent = _closed_chain(model, q, np.r_[0.0, 0.0, 30.0, 5.0 * u + 5.0 * v])
    b = model.stance_moment_gradient(q, np.eye(3), np.array([hip]), "left_foot")[0]
    assert abs(b @ u) > 0.3 and abs(b @ v) > 0.3  # both parts of the bending load it
    relief = GripBendingRelief(model, CAPACITY_NM, onset_share=0.35, release_share=0.23,
                               leg_guard_share=0.85)
    for hip_sign in (1.0, -1.0):
        relief.update("left", False, q, np.eye(3), bent, rail, TICK_S)  # a fresh term
        torque = bent.copy()
        for _ in range(200):
            torque[hip] = hip_sign * 0.9 * relief.limit_nm[hip]
            relief.update("left", True, q, np.eye(3), torque, rail, TICK_S, ("left",))
            torque = bent + relief.feedforward_nm("left", q, np.eye(3))
        term = relief.moment_nm["left"]
        assert abs(term @ rail) < 1e-6
        assert hip_sign * (b @ term) <= 1e-6  # the hot hip roll is not loaded further
        assert np.linalg.norm(term) > 0.5
    relief.update("left", False, q, np.eye(3), bent, rail, TICK_S)
    only_u = _closed_chain(model, q, np.r_[0.0, 0.0, 30.0, 7.0 * u])
    torque = only_u
    for _ in range(400):
        relief.update("left", True, q, np.eye(3), torque, rail, TICK_S, ())
        torque = only_u + relief.feedforward_nm("left", q, np.eye(3))
    assert _bending(model, q, torque, rail)[0] == pytest.approx(0.35 * CAPACITY_NM, rel=0.02)
