"""The robot description: joint order, parameter tables, limits, URDF/MJCF, trajectory files.

Kept light: importing ``robot`` pulls in numpy only; ``robot.mjcf`` imports mujoco.
"""

from robot.errors import (
    HuboLadderError,
    InputError,
    LadderSpecError,
    RobotModelError,
    TrajectoryFileError,
)
from robot.joints import JOINT_INDEX, JOINT_NAMES, NUM_JOINTS
from robot.limits import JointLimits, joint_limits
from robot.params import DRC_HUBO, HUBO2PLUS, ROBOTS, RobotParams, robot_params
from robot.trajectory_file import read_trajectory, write_trajectory
from robot.urdf import robot_urdf

__all__ = [
    "DRC_HUBO", "HUBO2PLUS", "JOINT_INDEX", "JOINT_NAMES", "NUM_JOINTS", "ROBOTS",
    "HuboLadderError", "InputError", "JointLimits", "LadderSpecError", "RobotModelError",
    "RobotParams", "TrajectoryFileError", "joint_limits", "read_trajectory", "robot_params",
    "robot_urdf", "write_trajectory",
]
