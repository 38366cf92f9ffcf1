"""A closed grip's load, from sensors: how near each hand on a rail is to letting go.

The latch in MuJoCo lets a grip go when the rail's radial force or bending torque on the
hand exceeds what the fingers hold (`ladders.contact_model.GripCapacity`, the planner's
and check-plan's limits too). The motion layer cannot read the latch; it estimates the
same wrench from what the robot senses: the arm's joint torques from its motor currents,
its encoders and the IMU's tilt (`MotionRobotModel.hand_wrench`). The wrist's 3-axis F/T
sensor sees only three of the six components, at the wrist rather than the grip.

The estimate is checked against the latch's wrench in `tests/test_grip_load.py`.
"""

from __future__ import annotations

import numpy as np

from execute.motion.robot_model import MotionRobotModel
from ladders.contact_model import RELEASE_LOADS, GripCapacity, default_grip

__all__ = ["GripLoad"]


class GripLoad:
    """Estimated grip loads of the hands on a ladder's rails (module docstring).

    Args:
        model: the motion layer's robot model.
        friction: the ladder's friction coefficient [-].
        rail_radius_m: the rails' radius [m].
    """

    def __init__(self, model: MotionRobotModel, friction: float, rail_radius_m: float):
        self.model = model
        self.capacity = GripCapacity.of(default_grip(), friction, rail_radius_m)

    def release_share(self, side: str, q_rad: np.ndarray, R_tilt: np.ndarray,
                      torque_nm: np.ndarray, rail_axis: np.ndarray) -> tuple[float, str]:
        """The largest of the loads that pry a grip open (radial force, bending torque)
        on ``side``'s hand, as a share of what it holds [-], and that load's name.

        Args:
            side: ``left`` or ``right``.
            q_rad: encoder positions by column [rad].
            R_tilt: the body's attitude (the estimator's).
            torque_nm: joint torques by column, from the motor currents [N·m].
            rail_axis: the rail's unit direction, world frame.
        """
        wrench = self.model.hand_wrench(q_rad, R_tilt, f"{side}_hand", torque_nm)
        parts = self.capacity.utilisation(wrench[:3], wrench[3:], rail_axis)
        what = max(RELEASE_LOADS, key=parts.get)
        return parts[what], what
