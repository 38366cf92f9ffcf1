"""Leg relief: the gripping arms lift more while a stance leg's joint nears its limit."""

from __future__ import annotations

import numpy as np
import pytest

from execute.motion.leg_relief import LegRelief
from execute.motion.robot_model import MotionRobotModel
from robot.joints import ARM_JOINTS, JOINT_INDEX, LEG_JOINTS, NUM_JOINTS
from robot.limits import joint_limits
from robot.motors import motor_table

TICK_S = 0.005


@pytest.fixture(scope="module")
def model():
    return MotionRobotModel()


def _torque_for(joint: str, share: float) -> np.ndarray:
    """Sensed joint torques [N·m] (from motor currents) with ``joint`` pushing at
    ``share`` of its torque limit."""
    m, c = motor_table(), JOINT_INDEX[joint]
    cur = np.zeros(NUM_JOINTS)
    cur[c] = m.current_a(share * joint_limits().torque_max_nm)[c]
    return m.torque_nm(cur)


def _climbing_arms() -> np.ndarray:
    q = np.zeros(NUM_JOINTS)
    for side, sign in (("left", 1.0), ("right", -1.0)):
        s = side[0].upper()
        q[JOINT_INDEX[f"{s}SP"]], q[JOINT_INDEX[f"{s}SR"]] = -1.2, 0.2 * sign
        q[JOINT_INDEX[f"{s}EB"]] = -0.8
    return q


def test_wrench_torques_are_the_palms_virtual_work(model):
    """Jᵀw·dq equals f·dp + m·dθ for a small arm motion (the Jacobian, its frame and its
    sign), for a force alone and for a force and a moment."""
    import pinocchio as pin

    q = _climbing_arms()
    f, m = np.array([10.0, -20.0, 50.0]), np.array([3.0, -1.0, 2.0])
    rng = np.random.default_rng(3)
    dq = np.zeros(NUM_JOINTS)
    cols = [JOINT_INDEX[n] for n in ARM_JOINTS["left"]]
    dq[cols] = rng.normal(scale=1e-4, size=len(cols))
    T0 = model.frame_in_pelvis(q, "L_palm")
    T1 = model.frame_in_pelvis(q + dq, "L_palm")
    dp, dtheta = T1[:3, 3] - T0[:3, 3], pin.log3(T1[:3, :3] @ T0[:3, :3].T)
    tau = model.wrench_torques(q, np.eye(3), "left_hand", f)
    assert tau @ dq == pytest.approx(f @ dp, rel=1e-3)
    tau_m = model.wrench_torques(q, np.eye(3), "left_hand", f, m)
    assert tau_m @ dq == pytest.approx(f @ dp + m @ dtheta, rel=1e-3)
    assert abs(m @ dtheta) > 0.1 * abs(f @ dp)  # the moment's share is not lost in rel
    legs = [JOINT_INDEX[n] for n in LEG_JOINTS["left"] + LEG_JOINTS["right"]]
    assert not tau_m[legs].any()  # a wrench at the palm loads the arm's joints only


def test_the_lift_grows_above_onset_holds_between_and_shrinks_below_release(model):
    relief = LegRelief(model, onset_fraction=0.85, release_fraction=0.75,
                       rate_n_per_s=40.0, max_lift_n=30.0)
    hot, warm, cool = (_torque_for("LKN", s) for s in (0.92, 0.8, 0.5))
    for _ in range(100):  # 0.5 s at 40 N/s
        relief.update(["left"], True, hot, TICK_S)
    assert relief.lift_n == pytest.approx(20.0)
    for _ in range(200):
        relief.update(["left"], True, hot, TICK_S)
    assert relief.lift_n == pytest.approx(30.0)  # bounded
    assert relief.peak_joint == "LKN"
    for _ in range(100):
        relief.update(["left"], True, warm, TICK_S)
    assert relief.lift_n == pytest.approx(30.0)  # hysteresis: neither grows nor shrinks
    for _ in range(100):
        relief.update(["left"], True, cool, TICK_S)
    assert relief.lift_n == pytest.approx(10.0)


def test_a_grip_near_what_it_holds_stops_the_lift_and_takes_it_back(model):
    """Above ``grip_fraction`` of what a grip holds the lift shrinks, and it grows again
    only once the grip is below ``grip_release_fraction`` (hysteresis)."""
    relief = LegRelief(model, rate_n_per_s=40.0, max_lift_n=80.0, grip_fraction=0.5,
                       grip_release_fraction=0.4)
    hot = _torque_for("LKN", 0.92)
    for _ in range(200):  # 1 s: 40 N
        relief.update(["left"], True, hot, TICK_S, grip_share=0.3)
    assert relief.lift_n == pytest.approx(40.0)
    for _ in range(100):  # the grip passes its bound: 0.5 s shrinks 20 N
        relief.update(["left"], True, hot, TICK_S, grip_share=0.55)
    assert relief.grip_bound and relief.lift_n == pytest.approx(20.0)
    for _ in range(100):  # back between the two fractions: still bound, still shrinking
        relief.update(["left"], True, hot, TICK_S, grip_share=0.45)
    assert relief.grip_bound and relief.lift_n == pytest.approx(0.0)
    for _ in range(100):  # below the release fraction it grows again
        relief.update(["left"], True, hot, TICK_S, grip_share=0.35)
    assert not relief.grip_bound and relief.lift_n == pytest.approx(20.0)


def test_the_grips_load_is_needed_only_while_a_lift_is_on_or_due(model):
    """The layer estimates the grips' load (an arm Jacobian and a least-squares solve
    per grip) only when the relief could use it."""
    relief = LegRelief(model, onset_fraction=0.85, release_fraction=0.75)
    hot, warm = _torque_for("LKN", 0.9), _torque_for("LKN", 0.8)
    assert not relief.needs_grip_share(["left"], warm)
    assert not relief.needs_grip_share(["right"], hot)  # the hot knee is not in stance
    assert relief.needs_grip_share(["left"], hot)
    relief.update(["left"], True, hot, TICK_S)
    assert relief.lift_n > 0.0 and relief.needs_grip_share(["left"], warm)  # lift on


def test_no_lift_without_a_gripping_arm_or_from_a_swing_leg(model):
    relief = LegRelief(model)
    hot = _torque_for("LKN", 0.95)
    for _ in range(100):
        relief.update(["left"], False, hot, TICK_S)  # no compliant hand on a rail
        relief.update(["right"], True, hot, TICK_S)  # the loaded knee is not in stance
    assert relief.lift_n == 0.0


def _static_knee_torque(model, q, hand_force):
    """LKN's torque [N·m] holding ``q`` on the left sole alone, with ``hand_force`` (world)
    of the environment on the left palm: the sole's wrench from the free flyer's rows."""
    import pinocchio as pin

    pq = model.configuration(q)
    m, d = model.model, model.data
    pin.computeJointJacobians(m, d, pq)
    pin.updateFramePlacements(m, d)
    g = pin.computeGeneralizedGravity(m, d, pq)
    J_sole = pin.getFrameJacobian(m, d, m.getFrameId("L_sole"), pin.LOCAL_WORLD_ALIGNED)
    J_palm = pin.getFrameJacobian(m, d, m.getFrameId("L_palm"), pin.LOCAL_WORLD_ALIGNED)
    hand = J_palm[:3].T @ hand_force
    w_sole = np.linalg.solve(J_sole[:, :6].T, g[:6] - hand[:6])
    tau = g - J_sole.T @ w_sole - hand
    return float(tau[m.joints[m.getJointId("LKN")].idx_v])


def test_the_stance_torque_gradient_is_the_statics_of_one_foot(model):
    """∂τ/∂f from the sole's Jacobian equals a static solve's difference quotient."""
    q = _climbing_arms()
    q[JOINT_INDEX["LHP"]], q[JOINT_INDEX["LKN"]], q[JOINT_INDEX["LAP"]] = -0.5, 1.0, -0.5
    grad = model.stance_torque_gradient(q, np.eye(3), JOINT_INDEX["LKN"], "left_foot",
                                        "left_hand")
    base = _static_knee_torque(model, q, np.zeros(3))
    for axis in np.eye(3):
        assert _static_knee_torque(model, q, 10.0 * axis) - base == \
            pytest.approx(10.0 * grad @ axis, abs=1e-6)


def test_the_lift_pulls_each_gripping_hand_the_way_that_unloads_the_joint(model):
    """The relief's feed-forward is −Jᵀf on the gripping arms' columns alone; f never
    points down, and it lowers the loaded knee's |τ|."""
    q = _climbing_arms()
    q[JOINT_INDEX["LHP"]], q[JOINT_INDEX["LKN"]], q[JOINT_INDEX["LAP"]] = -0.5, 1.0, -0.5
    relief = LegRelief(model, max_lift_n=40.0)
    hot = _torque_for("LKN", -0.95)  # the knee holds the bent leg: negative torque
    for _ in range(400):
        relief.update(["left"], True, hot, TICK_S)
    assert relief.lift_n == pytest.approx(40.0)
    ff = relief.feedforward_nm(["left", "right"], q, np.eye(3), hot)
    for side in ("left", "right"):
        d = relief.direction(q, np.eye(3), "left_foot", f"{side}_hand", hot)
        assert d[2] >= 0.0 and np.linalg.norm(d) == pytest.approx(1.0)
        grad = model.stance_torque_gradient(q, np.eye(3), JOINT_INDEX["LKN"], "left_foot",
                                            f"{side}_hand")
        assert grad @ d > 0.0  # the negative knee torque moves towards zero
        cols = list(model.chains[f"{side}_hand"].columns)
        push = model.wrench_torques(q, np.eye(3), f"{side}_hand", 20.0 * d)
        np.testing.assert_allclose(ff[cols], -push[cols])
    ff_left = relief.feedforward_nm(["left"], q, np.eye(3), hot)
    right = [JOINT_INDEX[n] for n in ARM_JOINTS["right"]]
    assert not ff_left[right].any()


def test_the_lift_does_not_load_another_loaded_joint_of_the_leg(model):
    """A hip yaw already near its limit is not loaded further by the knee's relief: the
    push is the fastest one projected onto those that leave it be (a DRC mount's left hip
    yaw went from 0.05 to 0.99 of its limit under an 80 N knee relief); a joint under
    the guard's share does not bend it."""
    q = _climbing_arms()
    q[JOINT_INDEX["LHP"]], q[JOINT_INDEX["LKN"]], q[JOINT_INDEX["LAP"]] = -0.5, 1.0, -0.5
    q[JOINT_INDEX["LHY"]] = 0.3
    relief = LegRelief(model, max_lift_n=40.0)
    hot = _torque_for("LKN", -0.95)
    for _ in range(400):
        relief.update(["left"], True, hot, TICK_S)
    hy, kn = JOINT_INDEX["LHY"], JOINT_INDEX["LKN"]
    for side in ("left", "right"):
        hand = f"{side}_hand"
        fastest = relief.direction(q, np.eye(3), "left_foot", hand, hot)
        g_hy = model.stance_torque_gradient(q, np.eye(3), hy, "left_foot", hand)
        assert abs(g_hy @ fastest) > 1e-3  # the fastest push does move the hip yaw
        both = model.stance_torque_gradient(q, np.eye(3), np.array([hy, kn]), "left_foot",
                                            hand)
        np.testing.assert_array_equal(both[0], g_hy)
        loaded = hot.copy()
        loaded[hy] = 0.9 * relief.limit_nm[hy] * np.sign(g_hy @ fastest)  # ... the wrong way
        d = relief.direction(q, np.eye(3), "left_foot", hand, loaded)
        assert np.sign(loaded[hy]) * (g_hy @ d) <= 1e-9
        assert d[2] >= -1e-12
        if np.linalg.norm(d) > 0:  # what is left of the push still unloads the knee
            assert np.linalg.norm(d) == pytest.approx(1.0)
            g_kn = model.stance_torque_gradient(q, np.eye(3), kn, "left_foot", hand)
            assert g_kn @ d >= 0.0
        below = hot.copy()
        below[hy] = 0.5 * loaded[hy] / 0.9  # half its limit: not guarded
        np.testing.assert_array_equal(
            relief.direction(q, np.eye(3), "left_foot", hand, below), fastest)
