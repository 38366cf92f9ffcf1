"""Per-joint limits in trajectory-file column order, read off the robot description."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import numpy as np

from robot.joints import JOINT_NAMES
from robot.kinematic_tree import build_tree
from robot.params import RobotParams, robot_params

#: How far beyond a joint limit a value still counts as on it [rad]: the rounding of a
#: trajectory file's values to a microradian (`robot.trajectory_file.DECIMALS`). The
#: trajectory reader accepts such values and the daemon clamps them; anything farther is
#: refused (reader) or rejected (daemon).
LIMIT_TOLERANCE_RAD = 1e-6
#: How far past a joint limit the daemon still clamps a commanded reference onto it [rad];
#: farther, it rejects the reference (the joint holds its previous one). Writers that
#: compute references (the motion layer's corrections) land up to about 2e-6 rad past a
#: limit the plan sits on (a straight elbow at 0); 1e-3 rad is far below anything that
#: moves the robot and far above that noise.
REF_CLAMP_TOLERANCE_RAD = 1e-3


@dataclass(frozen=True)
class JointLimits:
    """Arrays of shape (40,), indexed like the trajectory file's columns."""

    robot: str
    lower_rad: np.ndarray
    upper_rad: np.ndarray
    velocity_max_rad_s: np.ndarray  # hardware maximum: the trajectory reader's bound
    velocity_nominal_rad_s: np.ndarray  # planning speed
    accel_nominal_rad_s2: np.ndarray
    torque_max_nm: np.ndarray


@cache
def joint_limits(robot: str | RobotParams = "drc-hubo") -> JointLimits:
    """Limits of every column for a robot (by name or parameter table)."""
    p = robot_params(robot) if isinstance(robot, str) else robot
    by_joint = build_tree(p).joint_links
    lower, upper, vmax, vnom, torque = (np.zeros(40) for _ in range(5))
    for i, name in enumerate(JOINT_NAMES):
        link = by_joint.get(name)
        if link is None:  # a column with no joint on this robot (Hubo2+ wrist roll)
            lower[i] = upper[i] = 0.0
            vmax[i], torque[i] = p.speed_max_rad_s["arm"], 0.0
        else:
            lower[i], upper[i] = link.lower_rad, link.upper_rad
            vmax[i], torque[i] = link.velocity_rad_s, link.effort_nm
        suffix = name[1:]
        if suffix == "KN":
            vnom[i] = p.speed_nominal_rad_s["knee"]
        elif name[0] in "RL" and suffix in ("HY", "HR", "HP", "AP", "AR"):
            vnom[i] = p.speed_nominal_rad_s["leg"]
        elif name[0] in "RL" and suffix.startswith("F"):
            vnom[i] = p.speed_nominal_rad_s["finger"]
        else:
            vnom[i] = p.speed_nominal_rad_s["arm"]
    accel = np.full(40, p.accel_nominal_rad_s2)
    for arr in (lower, upper, vmax, vnom, accel, torque):
        arr.setflags(write=False)
    return JointLimits(p.name, lower, upper, vmax, vnom, accel, torque)
