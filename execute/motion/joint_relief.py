"""Relief of rigid joints that a closed chain loads towards their limits, from their motor
currents.

Two kinds of joints of a climbing Hubo stay rigid (position mode) inside a closed
kinematic chain:

- the **wrist roll** of a gripping compliant arm, the one joint of the arm that cannot
  comply (it shares a 3-channel board with the fingers, hubo-facts §2): a twist of the
  grip loads its position loop, and when its board trips the fingers let go;
- the **legs of standing feet**: soles held by friction on a floor or rungs, with the hands
  on the rails, close loops through stiff position servos. A few millimetres between where
  the plan put a foot and where it stands make internal forces that the servos fight; a
  hip roll or an ankle pitch then holds its limit until its board trips. The planner plans
  these joints within `planner.statics.arm_capacity.DEFAULT_POSITION_TORQUE_SHARE` (0.9)
  of their limits, so relief starts above that.

The motor current says how hard a joint pushes (``τ = η·gear·Kt·I``, `robot.motors`).
While that torque is above a share of the joint's limit, its reference walks towards
where the chain holds the joint, at a bounded speed, within a bounded offset: the
stiff chain's internal force falls away within millimetres, while a load the joint
really carries is shared out by a bounded sag. The offset is kept while the limb holds,
and unwound while it moves in the air.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from robot.joints import JOINT_INDEX, LEG_JOINTS
from robot.limits import joint_limits
from robot.motors import MotorTable, motor_table

__all__ = ["LEG_RELIEF", "WRIST_RELIEF", "WRIST_ROLL", "JointRelief", "ReliefRule",
           "leg_columns"]

WRIST_ROLL = {"left": JOINT_INDEX["LWR"], "right": JOINT_INDEX["RWR"]}


def leg_columns(side: str) -> list[int]:
    """Trajectory columns of the ``side`` leg's joints."""
    return [JOINT_INDEX[n] for n in LEG_JOINTS[side]]


@dataclass(frozen=True)
class ReliefRule:
    """When and how far a joint's reference gives way.

    Attributes:
        torque_share: share of the joint's torque limit above which it gives way [-].
        speed_rad_s: how fast the reference gives way, and unwinds [rad/s].
        max_offset_rad: largest offset from the reference [rad].
    """

    torque_share: float
    speed_rad_s: float
    max_offset_rad: float


#: The gripping wrist roll: above half its 4.8 N·m, 0.3 rad/s, within ±0.6 rad
#: (docs/decisions/motion-layer.md).
WRIST_RELIEF = ReliefRule(torque_share=0.5, speed_rad_s=0.3, max_offset_rad=0.6)
#: A standing leg's joints: above 0.93 of the limit (the plan asks at most 0.9, the board
#: trips at 0.99 held 0.5 s), 0.05 rad/s, within ±0.04 rad (about 3 cm at the foot of a
#: 0.8 m leg) (docs/decisions/joint-relief.md).
LEG_RELIEF = ReliefRule(torque_share=0.93, speed_rad_s=0.05, max_offset_rad=0.04)


class JointRelief:
    """Offsets of rigid joints from their sensed motor currents (module docstring).

    Args:
        robot: robot name (torque limits).
        motors: the motor table (default: `robot.motors.motor_table`).
    """

    def __init__(self, robot: str = "drc-hubo", motors: MotorTable | None = None):
        self.limit_nm = joint_limits(robot).torque_max_nm
        self.motors = motors or motor_table()
        self.offset_rad: dict[int, float] = {}

    def torque_nm(self, joint: int, cur_a: np.ndarray) -> float:
        """The torque column ``joint``'s motor current says it gives [N·m]."""
        m = self.motors
        return float(cur_a[joint] * m.efficiency[joint] * m.gear[joint]
                     * m.kt_nm_per_a[joint])

    def update(self, joint: int, rule: ReliefRule, holding: bool, cur_a: np.ndarray,
               dt_s: float) -> float:
        """The offset of column ``joint`` after one tick [rad]."""
        off = self.offset_rad.get(joint, 0.0)
        step = rule.speed_rad_s * dt_s
        if holding:
            torque = self.torque_nm(joint, cur_a)
            if abs(torque) > rule.torque_share * self.limit_nm[joint]:
                # the loop pushes with +τ towards a reference above the joint: give way
                off -= np.sign(torque) * step
        else:
            off -= np.sign(off) * min(abs(off), step)
        off = float(np.clip(off, -rule.max_offset_rad, rule.max_offset_rad))
        self.offset_rad[joint] = off
        return off
