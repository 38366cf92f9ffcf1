"""The snapshot camera frames the whole robot, feet included, whatever its pose: every
corner of every robot geom's box projects inside the frame (computed the way MuJoCo
places its free camera, so no OpenGL is needed)."""

from __future__ import annotations

import sys
from pathlib import Path

import mujoco
import numpy as np

sys.path.insert(0, str(Path(__file__).parent))

from synthetic_plan import synthetic_plan  # noqa: E402

from ladders.loader import load_ladder  # noqa: E402
from ladders.render import FOLLOW_ELEVATION_DEG, SNAPSHOT_SIZE, _frame_robot  # noqa: E402
from ladders.scene import build_scene  # noqa: E402
from planner.plots import plan_qpos  # noqa: E402


def _in_frame(model, data, camera, geoms, size) -> float:
    """The largest |image coordinate| of the robot's geom box corners, 1 at the edge."""
    az, el = np.radians(camera.azimuth), np.radians(camera.elevation)
    forward = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    up = np.array([-np.sin(el) * np.cos(az), -np.sin(el) * np.sin(az), np.cos(el)])
    right = np.cross(forward, up)
    eye = camera.lookat - camera.distance * forward
    tan_half = np.tan(np.radians(model.vis.global_.fovy) / 2)
    worst = 0.0
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
    for g in geoms:
        R = data.geom_xmat[g].reshape(3, 3)
        centre = data.geom_xpos[g] + R @ model.geom_aabb[g, :3]
        corners = centre + (signs * model.geom_aabb[g, 3:]) @ R.T
        rel = corners - eye
        depth = rel @ forward
        worst = max(worst, np.max(np.abs(rel @ up) / depth / tan_half),
                    np.max(np.abs(rel @ right) / depth / (tan_half * size[0] / size[1])))
    return worst


def test_the_camera_frames_every_part_of_the_robot():
    planner, result, _ = synthetic_plan()
    model = build_scene(load_ladder("drc"), planner.kin.params).compile()
    data = mujoco.MjData(model)
    pelvis = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "pelvis")
    geoms = np.flatnonzero(model.body_rootid[model.geom_bodyid] == model.body_rootid[pelvis])
    configs = np.array([q for seg in result.segments for q in seg.configs[::40]])
    lifted = configs[-1].copy()
    lifted[2] += 1.5  # high on the ladder: the camera follows
    reach = configs[0].copy()  # arms straight up: 2.2 m tall, the CoM off its middle (a
    for joint, value in (("LSP", -3.1), ("RSP", -3.1), ("LEB", 0.0), ("REB", 0.0)):
        reach[planner.kin.q_index[joint]] = value  # camera on the CoM cut the hands off)
    camera = mujoco.MjvCamera()
    camera.azimuth, camera.elevation = 90.0, FOLLOW_ELEVATION_DEG
    for row in plan_qpos(model, planner.kin, np.vstack([configs, lifted, reach])):
        data.qpos[:] = row
        mujoco.mj_forward(model, data)
        _frame_robot(camera, model, data, geoms, SNAPSHOT_SIZE)
        assert _in_frame(model, data, camera, geoms, SNAPSHOT_SIZE) < 0.95
