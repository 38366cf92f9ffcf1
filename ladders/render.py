"""Off-screen frames of a ladder scene, seen from the robot's right and following it.

Both the planner (its planned configurations) and ``validate-plan`` (simulated states)
draw their snapshot strips with this. Rendering needs an OpenGL context: ``MUJOCO_GL=egl``
(Mesa or a GPU driver); without one, `RenderingUnavailable` says how to get it.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np

from robot.errors import HuboLadderError

__all__ = ["FOLLOW_DISTANCE_M", "FOLLOW_ELEVATION_DEG", "SNAPSHOT_SIZE",
           "RenderingUnavailable", "render_states", "write_strip"]

SNAPSHOT_SIZE = (320, 240)  # [px] width, height of one strip frame
#: Following camera: distance from the robot's CoM [m] and elevation [deg]. At MuJoCo's
#: 45° field of view, 2.8 m shows a 2.3 m tall slice: the 1.45 m robot, its holds and
#: the rungs around them.
FOLLOW_DISTANCE_M = 2.8
FOLLOW_ELEVATION_DEG = -10.0


class RenderingUnavailable(HuboLadderError, RuntimeError):
    """No off-screen OpenGL context could be created (EGL missing). Also a `RuntimeError`,
    as it was before it joined the project's error root."""


def render_states(model, qpos: np.ndarray, size: tuple[int, int]) -> list[np.ndarray]:
    """One RGB frame per row of ``qpos`` (the model's layout), from the robot's right
    (like the scene's ``side`` camera) at `FOLLOW_DISTANCE_M` from the robot's CoM: the
    fixed camera frames the whole ladder, which leaves the robot small.

    Raises:
        RenderingUnavailable: no EGL context (message says how to get one).
    """
    if "mujoco" not in sys.modules:
        os.environ.setdefault("MUJOCO_GL", "egl")
    import mujoco

    d = mujoco.MjData(model)
    try:
        renderer = mujoco.Renderer(model, height=size[1], width=size[0])
    except Exception as exc:  # mujoco raises plain RuntimeError/FatalError types
        gl = os.environ.get("MUJOCO_GL")
        hint = ("set MUJOCO_GL=egl before mujoco is first imported" if gl != "egl" else
                "install Mesa EGL (libegl1, libgl1-mesa-dri) or use a GPU driver")
        raise RenderingUnavailable(f"cannot create an off-screen OpenGL context with "
                                   f"MUJOCO_GL={gl!r} ({exc}); {hint}") from None
    option = mujoco.MjvOption()
    option.geomgroup[:] = 1  # the robot's geoms are in group 3 (collision class)
    camera = mujoco.MjvCamera()
    camera.type = mujoco.mjtCamera.mjCAMERA_FREE
    camera.azimuth, camera.elevation = 90.0, FOLLOW_ELEVATION_DEG  # from −y, looking +y
    camera.distance = FOLLOW_DISTANCE_M
    pelvis = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "pelvis")
    frames = []
    try:
        for row in np.atleast_2d(qpos):
            d.qpos[:] = row
            mujoco.mj_forward(model, d)
            camera.lookat[:] = d.subtree_com[pelvis]
            renderer.update_scene(d, camera=camera, scene_option=option)
            frames.append(renderer.render().copy())
    finally:
        renderer.close()
    return frames


def write_strip(frames: list[np.ndarray], path: str | os.PathLike) -> Path:
    """Frames side by side in one PNG."""
    import imageio.v3 as iio

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    iio.imwrite(path, np.concatenate(frames, axis=1))
    return path
