"""Gravity compensation of the compliant arms (hubo-motion-rt, thesis §4.3.4).

A PWM arm gives the torque its duty makes; the planner's feed-forward (the sidecar's
`robot.plan_sidecar.ArmFeedforward`) is the torque the arm needs *at the planned
configuration*: its own gravity plus the hold force the torque LP gave it, through the
arm's Jacobian. Where the arm really stands differs (it sagged, the body leans, a grasp
was re-reached), and so does its gravity torque. The compensated feed-forward is

    τ = τ_plan + g(q_sensed, tilt) − g(q_plan, tilt)

the model's gravity torques at the sensed joints and the body IMU's tilt, plus the
planned load share (τ_plan − g(q_plan)). The daemon turns it into duty with the motor
model (`daemon.pwm.feedforward_duty_pct`), as hubo-motion-rt did with its torque–PWM
table.
"""

from __future__ import annotations

import numpy as np

from execute.motion.robot_model import MotionRobotModel
from robot.joints import ARM_JOINTS, joint_indices

__all__ = ["ArmGravityCompensation"]


class ArmGravityCompensation:
    """Corrects the arms' planned feed-forward for where they are (module docstring)."""

    def __init__(self, model: MotionRobotModel):
        self.model = model
        self._arm_cols = np.array(joint_indices(ARM_JOINTS["left"] + ARM_JOINTS["right"]))

    def feedforward_nm(self, planned_nm: np.ndarray, q_plan_rad: np.ndarray,
                       q_sensed_rad: np.ndarray, R_tilt: np.ndarray) -> np.ndarray:
        """The compensated feed-forward [N·m], by column (arm columns changed only).

        Args:
            planned_nm: the player's feed-forward of this tick, shape (40,).
            q_plan_rad: the plan's joints at this tick, shape (40,).
            q_sensed_rad: the encoders, shape (40,).
            R_tilt: the pelvis's tilt from the IMU (3, 3).
        """
        out = np.array(planned_nm, dtype=float)
        cols = self._arm_cols
        g_sensed = self.model.gravity_torques(q_sensed_rad, R_tilt)
        g_plan = self.model.gravity_torques(q_plan_rad, R_tilt)
        out[cols] += g_sensed[cols] - g_plan[cols]
        return out
