"""A MuJoCo scene: floor, ladder, the robot at its start pose and a side camera."""

from __future__ import annotations

import math

import mujoco
import numpy as np

from ladders.geometry import LadderGeometry
from ladders.mjcf import add_ladder
from ladders.spec import LadderSpec
from robot.kinematic_tree import build_tree
from robot.mjcf import add_floor, add_robot, new_spec
from robot.params import RobotParams, robot_params

#: Vertical field of view of the side camera [deg] (MuJoCo's default).
SIDE_CAMERA_FOVY_DEG = 45.0
#: Margin around robot + ladder in the side camera's view [-].
SIDE_CAMERA_MARGIN = 1.15
#: Floor friction (not the ladder's; feet on a shop floor) [-].
FLOOR_FRICTION = 1.0


def side_camera_pose(geometry: LadderGeometry, robot_height_m: float
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Position [m] and orientation (3×3, columns = camera x, y, z) of a camera on the
    robot's right (−y) that looks along +y and frames the robot at the origin and the
    ladder; image right = world +x, image up = world +z.
    """
    lo, hi = geometry.bounds_m()
    x_lo, x_hi = min(lo[0], -0.3), max(hi[0], 0.3)
    z_hi = max(hi[2], robot_height_m)
    centre = np.array([(x_lo + x_hi) / 2, (lo[1] + hi[1]) / 2, z_hi / 2])
    half_fov = math.radians(SIDE_CAMERA_FOVY_DEG) / 2
    # Fit the taller of the two spans (a 4:3 image is wider than it is tall).
    half_span = SIDE_CAMERA_MARGIN * max(z_hi / 2, (x_hi - x_lo) / 2 * 3 / 4)
    distance = half_span / math.tan(half_fov) + max(-lo[1], 0.0)
    pos = centre - np.array([0.0, distance, 0.0])
    R = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])  # x, y=z_w, z=-y_w
    return pos, R


def build_scene(ladder: LadderSpec, robot: str | RobotParams = "drc-hubo",
                floor_friction: float = FLOOR_FRICTION) -> mujoco.MjSpec:
    """Floor + ladder + robot standing at the world origin facing +x + side camera.

    The robot's ``home`` keyframe (key 0) is the standing start pose with zero joint
    angles; position actuators with ``ctrl = 0`` hold it.

    Args:
        ladder: The ladder and its placement.
        robot: Robot name (``"drc-hubo"``, ``"hubo2plus"``) or parameter table.
        floor_friction: Coulomb friction of the floor [-].

    Returns:
        An uncompiled spec; camera ``side``; ladder body ``ladder``.
    """
    params = robot_params(robot) if isinstance(robot, str) else robot
    geometry = LadderGeometry(ladder)
    spec = new_spec()
    spec.modelname = f"{params.name}_{ladder.name}"
    add_floor(spec, floor_friction)
    add_ladder(spec, geometry)
    add_robot(spec, build_tree(params), base_pos_m=(0.0, 0.0, None), base_yaw_rad=0.0)
    pos, R = side_camera_pose(geometry, params.pelvis_height_m + params.neck_above_torso_m)
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, R.ravel())
    spec.worldbody.add_camera(name="side", pos=pos.tolist(), quat=quat.tolist(),
                              fovy=SIDE_CAMERA_FOVY_DEG)
    return spec


__all__ = ["build_scene", "side_camera_pose"]
