"""What a gripping arm may carry per strategy, and that the planner and check-plan use it."""

import numpy as np
import pytest

from ladders.loader import load_ladder
from planner.configuration.kinematics import ARM_LIMIT_MARGIN_RAD, HuboKinematics
from planner.search import ClimbPlanner, PlannerConfig, StepStats
from planner.statics.arm_capacity import (
    BACK_EMF_SHARE,
    balance_stance,
    compliant_speed_rad_s,
    compliant_torque_nm,
    gripping_torque_limits,
    gripping_velocity_limits,
)
from planner.statics.com_region import support_region
from planner.statics.torque_lp import torque_feasibility, torque_limits_by_joint
from primitives.library import climb_sequence
from robot.joints import ARM_JOINTS, JOINT_INDEX
from robot.limits import joint_limits
from robot.motors import DEFAULT_BATTERY_V, motor_table
from robot.pwm_gains import climbing_gain_table, safe_default_gain_table


def _stall_nm(kt, r_ohm, gear, duty_pct, volts=48.0, eta=0.7):
    return eta * gear * kt * (volts * duty_pct / 100.0) / r_ohm


def test_compliant_capacity_is_the_stall_torque_at_the_pwm_clamp():
    cap = compliant_torque_nm()
    # Hand-computed from the motor table (RE35: 0.060 N·m/A, 2.8 Ω; RE25: 0.047, 9.3 Ω)
    # and the safe default clamps (shoulder 7.9 %, left elbow 4 %, right elbow 5 %,
    # wrist pitch 4 %).
    assert cap["LSP"] == pytest.approx(_stall_nm(0.060, 2.8, 250, 7.9), rel=1e-9)
    assert cap["LSP"] == pytest.approx(14.22, abs=0.01)
    assert cap["LEB"] == pytest.approx(_stall_nm(0.060, 2.8, 200, 4.0), rel=1e-9)
    assert cap["REB"] == pytest.approx(_stall_nm(0.060, 2.8, 200, 5.0), rel=1e-9)
    assert cap["LWP"] == pytest.approx(_stall_nm(0.047, 9.3, 200, 4.0), rel=1e-9)
    assert cap["LWP"] == pytest.approx(1.36, abs=0.01)
    # The wrist roll has no PWM gains (it shares the finger board): not compliant.
    assert "LWR" not in cap and "RWR" not in cap
    # A lower battery gives proportionally less.
    assert compliant_torque_nm(24.0)["LSP"] == pytest.approx(cap["LSP"] / 2)


def test_only_the_gripping_arm_is_limited_and_only_under_mixed():
    rigid = torque_limits_by_joint("drc-hubo")
    cap = compliant_torque_nm()
    mixed = gripping_torque_limits(rigid, {"left"}, "mixed")
    for name in ARM_JOINTS["left"]:
        assert mixed[name] == (min(rigid[name], cap[name]) if name in cap else rigid[name])
    for name in ARM_JOINTS["right"] + ("LKN", "RHR", "WST"):
        assert mixed[name] == rigid[name]
    assert mixed["LWP"] < rigid["LWP"] / 6  # 1.4 against 8.9 N·m
    assert gripping_torque_limits(rigid, {"left", "right"}, "position") == rigid
    with pytest.raises(ValueError, match="arm strategy"):
        gripping_torque_limits(rigid, {"left"}, "limp")


def test_position_share_reserves_torque_of_position_joints_only():
    rigid = torque_limits_by_joint("drc-hubo")
    cap = compliant_torque_nm()
    mixed = gripping_torque_limits(rigid, {"left"}, "mixed", position_share=0.9)
    for name in ("LKN", "RHR", "WST", "LWR") + ARM_JOINTS["right"]:  # position mode
        assert mixed[name] == pytest.approx(0.9 * rigid[name])
    for name in ("LSP", "LEB", "LWP"):  # PWM: the clamp is the ceiling, not shared
        assert mixed[name] == min(rigid[name], cap[name])
    rigid_arms = gripping_torque_limits(rigid, {"left", "right"}, "position",
                                        position_share=0.9)
    assert rigid_arms == pytest.approx({n: 0.9 * t for n, t in rigid.items()})


def test_compliant_speed_leaves_the_load_three_quarters_of_the_clamp():
    # Back-EMF damping b = η·gear²·Kt²/R (Ke = Kt in SI): a shoulder RE35 on a 250:1 gear.
    b_shoulder = 0.7 * 250**2 * 0.060**2 / 2.8
    speed = compliant_speed_rad_s()
    assert speed["LSP"] == pytest.approx(BACK_EMF_SHARE * compliant_torque_nm()["LSP"]
                                         / b_shoulder, rel=1e-9)
    assert speed["LSP"] == pytest.approx(0.063, abs=1e-3)  # rad/s, against 1 nominal
    assert "LWR" not in speed  # the wrist roll is never compliant


def test_an_elbow_and_a_wrist_follow_the_body_at_their_climbing_clamp():
    """The motion layer climbs with the elbows' and wrists' clamps at 7.9 % (4–5 % by
    default): they may follow the body that much faster, and the load the planner gives
    them (the default clamp's torque) still fits beside the back-EMF."""
    speed, load = compliant_speed_rad_s(), compliant_torque_nm()
    climbing, default = climbing_gain_table(), safe_default_gain_table()
    per_duty = np.abs(motor_table().torque_per_duty(DEFAULT_BATTERY_V))
    damping = motor_table().back_emf_damping
    for name in ("LEB", "REB", "LWP", "RWY"):
        j = JOINT_INDEX[name]
        assert climbing[name][2] == pytest.approx(7.9) and default[name][2] <= 5.0
        assert speed[name] == pytest.approx(BACK_EMF_SHARE * per_duty[j] * 7.9 / damping[j])
        back_emf_nm = damping[j] * speed[name]
        assert load[name] + back_emf_nm <= per_duty[j] * climbing[name][2] + 1e-9


def test_velocity_limits_cap_only_the_compliant_joints_of_holding_arms():
    nominal = joint_limits("drc-hubo").velocity_nominal_rad_s
    capped = gripping_velocity_limits(nominal, {"right"}, "mixed")
    speed = compliant_speed_rad_s()
    for name in ARM_JOINTS["right"]:
        j = JOINT_INDEX[name]
        assert capped[j] == (min(nominal[j], speed[name]) if name in speed else nominal[j])
    untouched = [JOINT_INDEX[n] for n in ARM_JOINTS["left"] + ("RKN", "WST")]
    np.testing.assert_array_equal(capped[untouched], nominal[untouched])
    assert gripping_velocity_limits(nominal, {"left", "right"}, "position") is None
    assert gripping_velocity_limits(nominal, set(), "mixed") is None


def test_the_planner_keeps_the_arms_off_their_stops():
    kin = HuboKinematics.load()
    limits = joint_limits("drc-hubo")
    for name in ARM_JOINTS["left"] + ARM_JOINTS["right"]:
        i, j = kin.q_index[name], JOINT_INDEX[name]
        assert kin.model.lowerPositionLimit[i] == pytest.approx(
            limits.lower_rad[j] + ARM_LIMIT_MARGIN_RAD)
        assert kin.model.upperPositionLimit[i] == pytest.approx(
            limits.upper_rad[j] - ARM_LIMIT_MARGIN_RAD)
    knee = kin.q_index["LKN"]
    assert kin.model.lowerPositionLimit[knee] == pytest.approx(
        limits.lower_rad[JOINT_INDEX["LKN"]])


@pytest.fixture(scope="module")
def hands_on_rails():
    """Both hands placed on the DRC rails by the planner (mixed), and its planner."""
    p = ClimbPlanner(load_ladder("drc"), seed=1)
    q, stance = p.start_configuration()
    _, q_end, new_stance = p.try_step(climb_sequence(0)[0], q, stance, 0.0, StepStats("x"))
    return p, q_end, new_stance


def test_the_planner_loads_a_gripping_arm_only_up_to_its_compliant_capacity(hands_on_rails):
    p, q, stance = hands_on_rails
    limits = p.checker.torque_limits(stance)
    assert limits["LSP"] == pytest.approx(compliant_torque_nm()["LSP"])
    tq = torque_feasibility(p.kin.model, p.kin.data, q, stance, limits)
    assert tq.feasible
    cap = compliant_torque_nm()
    for name in cap:
        assert abs(tq.torque(name)) <= cap[name] * (1 + 1e-6)
    # A rigid-arm planner would not be bound by those capacities.
    rigid = ClimbPlanner(load_ladder("drc"), seed=1,
                         config=PlannerConfig(arm_strategy="position"))
    share = rigid.config.position_torque_share  # a rigid arm is in position mode
    assert rigid.checker.torque_limits(stance)["LSP"] == pytest.approx(
        share * torque_limits_by_joint()["LSP"])


def test_a_stance_that_needs_the_arms_is_refused_when_they_are_compliant(hands_on_rails):
    p, q, stance = hands_on_rails
    # Stand on the left foot only, hands on the rails: the rigid arms can prop the body
    # up, compliant ones cannot give the same torques.
    one_foot = type(stance)(tuple(h for h in stance.holds if h.limb != "right_foot"))
    rigid = torque_feasibility(p.kin.model, p.kin.data, q, one_foot,
                               torque_limits_by_joint())
    mixed = torque_feasibility(p.kin.model, p.kin.data, q, one_foot,
                               p.checker.torque_limits(one_foot))
    assert mixed.max_ratio > rigid.max_ratio
    assert np.isfinite(rigid.max_ratio)


def test_a_lone_compliant_hand_does_not_hold_the_balance(hands_on_rails):
    p, _, stance = hands_on_rails
    mass = p.kin.params.total_mass_kg
    one_hand = type(stance)(tuple(h for h in stance.holds if h.limb != "left_hand"))
    feet = type(stance)(tuple(h for h in stance.holds if not h.is_hand))
    assert balance_stance(one_hand, "mixed") == feet
    assert balance_stance(one_hand, "position") == one_hand  # a rigid arm holds it
    assert balance_stance(stance, "mixed") == stance  # two compliant arms hold it
    # The pulling hand extends the region behind the feet; the planner's region for a
    # lone compliant hand is the feet's, and a CoM that only the hand could hold fails.
    with_hand, feet_only = support_region(one_hand, mass), support_region(feet, mass)
    behind = np.array([feet_only.vertices[:, 0].min() - 0.03, feet_only.vertices[:, 1].mean()])
    assert feet_only.margin(behind) < 0 < with_hand.margin(behind)
    assert p.checker.region(one_hand).margin(behind) < 0
    rigid = ClimbPlanner(load_ladder("drc"), seed=1,
                         config=PlannerConfig(arm_strategy="position"))
    assert rigid.checker.region(one_hand).margin(behind) > 0


def test_the_checker_plans_position_joints_to_the_share_it_is_set_to(hands_on_rails):
    p, _, stance = hands_on_rails
    rigid, cap = torque_limits_by_joint(), compliant_torque_nm()
    try:
        p.checker.set_position_torque_share(0.8)
        limits = p.checker.torque_limits(stance)
        assert limits["LKN"] == pytest.approx(0.8 * rigid["LKN"])
        assert limits["LSP"] == pytest.approx(cap["LSP"])  # a PWM joint keeps its clamp
    finally:
        p.checker.set_position_torque_share(p.config.position_torque_share)
    assert p.checker.torque_limits(stance)["LKN"] == pytest.approx(
        p.config.position_torque_share * rigid["LKN"])


def test_a_step_is_tried_at_the_reserve_share_first_then_at_the_position_share(monkeypatch):
    """The search plans each step's first ``reserve_samples`` samples with position-mode
    joints at ``reserve_torque_share``, the rest at ``position_torque_share``, and records
    which share each step was found with."""
    from planner.search import _StepRejected
    from robot.vocabulary import StepFailure

    p = ClimbPlanner(load_ladder("drc"), seed=1, config=PlannerConfig(
        position_torque_share=0.9, reserve_torque_share=0.8, reserve_samples=3))
    tried: list[tuple[str, float]] = []

    def try_step(step, q, stance, radius_m, stats, attempt=0):
        tried.append((step.label, p.checker.position_torque_share))
        if step.label == "placeRFoot@rung0" and attempt < 5:  # five samples fail
            raise _StepRejected(StepFailure.NO_LIFT_OFF, "no lift-off pose", "lift-off")
        return [], q, stance

    monkeypatch.setattr(p, "try_step", try_step)
    result = p.plan(top_rung=0)
    shares = [share for label, share in tried if label == "placeRFoot@rung0"]
    assert shares == [0.8, 0.8, 0.8, 0.9, 0.9, 0.9]
    by_step = {st.label: st.position_torque_share for st in result.step_stats}
    assert by_step["placeRFoot@rung0"] == 0.9
    assert by_step["placeLFoot@rung0"] == 0.8
