"""Joint relief: rigid joints that a closed chain loads to their limits give way, from
their motor currents only, within a bound."""

import numpy as np
import pytest

from execute.motion.joint_relief import LEG_RELIEF, WRIST_RELIEF, JointRelief, leg_columns
from robot.joints import JOINT_INDEX, NUM_JOINTS
from robot.limits import joint_limits
from robot.motors import motor_table

DT = 0.005


def _current_for(joint: int, torque_nm: float) -> np.ndarray:
    m = motor_table()
    cur = np.zeros(NUM_JOINTS)
    cur[joint] = torque_nm / (m.efficiency[joint] * m.gear[joint] * m.kt_nm_per_a[joint])
    return cur


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_a_standing_hip_roll_at_its_limit_gives_way_against_its_torque_within_the_bound(
        sign):
    relief = JointRelief()
    lhr = JOINT_INDEX["LHR"]
    limit = joint_limits("drc-hubo").torque_max_nm[lhr]
    cur = _current_for(lhr, sign * 0.97 * limit)
    assert relief.torque_nm(lhr, cur) == pytest.approx(sign * 0.97 * limit)
    off = relief.update(lhr, LEG_RELIEF, True, cur, DT)
    assert off == pytest.approx(-sign * LEG_RELIEF.speed_rad_s * DT)
    for _ in range(int(2.0 / DT)):  # 2 s at the limit: 0.1 rad asked, 0.04 allowed
        off = relief.update(lhr, LEG_RELIEF, True, cur, DT)
    assert off == pytest.approx(-sign * LEG_RELIEF.max_offset_rad)


def test_a_load_the_plan_allows_moves_nothing_and_a_swinging_leg_unwinds():
    relief = JointRelief()
    lkn = JOINT_INDEX["LKN"]
    limit = joint_limits("drc-hubo").torque_max_nm[lkn]
    planned = _current_for(lkn, 0.9 * limit)  # the planner's own ceiling
    assert relief.update(lkn, LEG_RELIEF, True, planned, DT) == 0.0
    over = _current_for(lkn, -limit)
    for _ in range(100):
        off = relief.update(lkn, LEG_RELIEF, True, over, DT)
    assert off == pytest.approx(100 * LEG_RELIEF.speed_rad_s * DT)
    # the foot lifts: the offset unwinds at the same speed, to zero and no further
    for _ in range(99):
        off = relief.update(lkn, LEG_RELIEF, False, over, DT)
    assert off == pytest.approx(LEG_RELIEF.speed_rad_s * DT)
    assert relief.update(lkn, LEG_RELIEF, False, over, DT) == 0.0
    assert relief.update(lkn, LEG_RELIEF, False, over, DT) == 0.0


def test_the_leg_rule_starts_above_the_planners_share_and_the_wrist_at_half():
    from planner.statics.arm_capacity import DEFAULT_POSITION_TORQUE_SHARE

    assert DEFAULT_POSITION_TORQUE_SHARE < LEG_RELIEF.torque_share < 0.99  # trip at 0.99
    assert WRIST_RELIEF.torque_share == 0.5
    assert [JOINT_INDEX[n] for n in ("RHY", "RHR", "RHP", "RKN", "RAP", "RAR")] == \
        leg_columns("right")
