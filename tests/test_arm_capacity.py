"""What a gripping arm may carry per strategy, and that the planner and check-plan use it."""

import numpy as np
import pytest

from ladders.loader import load_ladder
from planner.arm_capacity import compliant_torque_nm, gripping_torque_limits
from planner.search import ClimbPlanner, PlannerConfig, StepStats
from planner.stability import torque_feasibility, torque_limits_by_joint
from primitives.library import climb_sequence
from robot.joints import ARM_JOINTS


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
    assert rigid.checker.torque_limits(stance)["LSP"] == torque_limits_by_joint()["LSP"]


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
