"""The planner's view of the robot: one placo wrapper (whose model is a pinocchio model),
conversions between its configuration vector and the 40 file columns, frame poses, CoM.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
import placo

from robot.joints import ARM_JOINTS, JOINT_NAMES
from robot.params import RobotParams, robot_params
from robot.urdf import robot_urdf

#: The planner keeps the arm joints this far inside their limits [rad]: a compliant arm
#: pressed on its mechanical stop is rigid in that direction, and the stop, not the
#: planned torques, then decides what its hand carries.
ARM_LIMIT_MARGIN_RAD = 0.05


@dataclass
class HuboKinematics:
    """placo/pinocchio model of one robot, plus the column ↔ configuration mapping.

    A configuration ``q`` is pinocchio's: base position (3), base quaternion x y z w (4),
    then the revolute joints in model order.
    """

    params: RobotParams
    wrapper: placo.RobotWrapper
    model: pin.Model
    data: pin.Data
    q_index_of_column: np.ndarray  # (40,) index into q, or -1 for a column with no joint
    q_index: dict[str, int]  # revolute joint name → its index in q

    @classmethod
    def load(cls, robot: str = "drc-hubo") -> HuboKinematics:
        params = robot_params(robot)
        wrapper = placo.RobotWrapper("", placo.Flags.ignore_collisions, robot_urdf(params))
        model = wrapper.model
        for name in (n for side in ARM_JOINTS.values() for n in side):
            if model.existJointName(name):
                idx = model.joints[model.getJointId(name)].idx_q
                wrapper.set_joint_limits(name, model.lowerPositionLimit[idx] + ARM_LIMIT_MARGIN_RAD,
                                         model.upperPositionLimit[idx] - ARM_LIMIT_MARGIN_RAD)
        q_index = {model.names[j]: model.joints[j].idx_q for j in range(2, model.njoints)}
        index = np.array([q_index.get(name, -1) for name in JOINT_NAMES])
        return cls(params, wrapper, model, model.createData(), index, q_index)

    @property
    def q(self) -> np.ndarray:
        return np.array(self.wrapper.state.q)

    def set_q(self, q: np.ndarray) -> None:
        self.wrapper.state.q = np.asarray(q, dtype=float).copy()
        self.wrapper.update_kinematics()

    def columns(self, q: np.ndarray) -> np.ndarray:
        """The 40 file columns [rad] of configuration ``q``."""
        out = np.zeros(len(JOINT_NAMES))
        have = self.q_index_of_column >= 0
        out[have] = q[self.q_index_of_column[have]]
        return out

    def posture(self, q: np.ndarray) -> dict[str, float]:
        """Every revolute joint's angle in ``q`` [rad], by name."""
        return {name: float(q[i]) for name, i in self.q_index.items()}

    def actuated(self, q: np.ndarray) -> np.ndarray:
        """The revolute part of ``q`` (model order)."""
        return np.asarray(q)[7:]

    def frame_pose(self, q: np.ndarray, frame: str) -> np.ndarray:
        """T_world_frame (4, 4) at configuration ``q``."""
        fid = self.model.getFrameId(frame)
        pin.framesForwardKinematics(self.model, self.data, q)
        return self.data.oMf[fid].homogeneous.copy()

    def com(self, q: np.ndarray) -> np.ndarray:
        return pin.centerOfMass(self.model, self.data, q).copy()

    def joint_distance(self, qa: np.ndarray, qb: np.ndarray) -> float:
        """Largest joint-angle difference [rad] (the base is implied by the contacts)."""
        return float(np.max(np.abs(qa[7:] - qb[7:])))

    def interpolate(self, qa: np.ndarray, qb: np.ndarray, s: float) -> np.ndarray:
        return pin.interpolate(self.model, qa, qb, s)
