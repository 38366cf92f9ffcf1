"""Off-screen frames of a ladder scene, seen from the robot's right and following it.

Both the planner (its planned configurations) and ``validate-plan`` (simulated states)
draw their snapshot strips with this. Rendering needs an OpenGL context: ``MUJOCO_GL=egl``
(Mesa or a GPU driver); without one, `RenderingUnavailable` says how to get it.

The camera looks at the middle of the robot's bounding box and stands back far enough
for the whole box, feet included, to fit the frame with `FRAME_MARGIN_M` to spare (at
least `FOLLOW_DISTANCE_M`). A strip's frames may carry captions (`write_strip`).
"""

from __future__ import annotations

import os
import sys
import textwrap
from pathlib import Path

import numpy as np

from robot.errors import HuboLadderError

__all__ = ["FOLLOW_DISTANCE_M", "FOLLOW_ELEVATION_DEG", "FRAME_MARGIN_M", "SNAPSHOT_SIZE",
           "RenderingUnavailable", "render_states", "write_strip"]

SNAPSHOT_SIZE = (320, 240)  # [px] width, height of one strip frame
#: Following camera: distance from the robot's CoM [m] and elevation [deg]. At MuJoCo's
#: 45° field of view, 2.8 m shows a 2.3 m tall slice: the 1.45 m robot, its holds and
#: the rungs around them.
FOLLOW_DISTANCE_M = 2.8
FOLLOW_ELEVATION_DEG = -10.0
#: Room left around the robot's bounding box in a frame [m].
FRAME_MARGIN_M = 0.15


class RenderingUnavailable(HuboLadderError, RuntimeError):
    """No off-screen OpenGL context could be created (EGL missing). Also a `RuntimeError`,
    as it was before it joined the project's error root."""


def render_states(model, qpos: np.ndarray, size: tuple[int, int]) -> list[np.ndarray]:
    """One RGB frame per row of ``qpos`` (the model's layout), from the robot's right
    (like the scene's ``side`` camera), framing the robot's bounding box (module
    docstring): the fixed camera frames the whole ladder, which leaves the robot small.

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
    robot = np.flatnonzero(model.body_rootid[model.geom_bodyid] == model.body_rootid[pelvis])
    frames = []
    try:
        for row in np.atleast_2d(qpos):
            d.qpos[:] = row
            mujoco.mj_forward(model, d)
            _frame_robot(camera, model, d, robot, size)
            renderer.update_scene(d, camera=camera, scene_option=option)
            frames.append(renderer.render().copy())
    finally:
        renderer.close()
    return frames


def _frame_robot(camera, model, data, geoms: np.ndarray, size: tuple[int, int]) -> None:
    """Aim ``camera`` (azimuth 90°: image x is world x, image up is world z) at the middle
    of the world box around ``geoms`` and back it off until the box fits the frame."""
    # Each geom's box in the world: its local box turned by its orientation.
    half = np.abs(data.geom_xmat[geoms].reshape(-1, 3, 3)) @ model.geom_aabb[geoms, 3:, None]
    centre = data.geom_xpos[geoms] + (data.geom_xmat[geoms].reshape(-1, 3, 3)
                                      @ model.geom_aabb[geoms, :3, None])[..., 0]
    lo, hi = (centre - half[..., 0]).min(axis=0), (centre + half[..., 0]).max(axis=0)
    camera.lookat[:] = (lo + hi) / 2
    tan_half = np.tan(np.radians(model.vis.global_.fovy) / 2)
    # Seen from −y, tilted by the elevation: the box's depth along y adds to its height.
    tilt = np.radians(abs(FOLLOW_ELEVATION_DEG))
    tall = (hi[2] - lo[2]) * np.cos(tilt) + (hi[1] - lo[1]) * np.sin(tilt)
    need_h = (tall / 2 + FRAME_MARGIN_M) / tan_half
    need_w = ((hi[0] - lo[0]) / 2 + FRAME_MARGIN_M) / (tan_half * size[0] / size[1])
    # The near half of the box is closer to the camera and looks larger.
    camera.distance = max(FOLLOW_DISTANCE_M, max(need_h, need_w) + (hi[1] - lo[1]) / 2)


def write_strip(frames: list[np.ndarray], path: str | os.PathLike,
                captions: list[str] | None = None) -> Path:
    """Frames side by side in one PNG, each with its caption underneath if given (the
    frames keep their pixels: one frame pixel is one image pixel)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    strip = np.concatenate(frames, axis=1)
    if captions is None:
        import imageio.v3 as iio

        iio.imwrite(path, strip)
        return path
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if len(captions) != len(frames):
        raise ValueError(f"{len(captions)} captions for {len(frames)} frames")
    dpi, fontsize = 100, 8
    h, w = frames[0].shape[:2]
    # Lines of at most a frame's width: about 0.6 em a character in Matplotlib's font.
    chars = int(w / (0.6 * fontsize * dpi / 72))
    captions = ["\n".join(textwrap.fill(p, chars) for p in c.split("\n")) for c in captions]
    caption_px = 12 + 15 * max(c.count("\n") + 1 for c in captions)
    fig = plt.figure(figsize=(strip.shape[1] / dpi, (h + caption_px) / dpi), dpi=dpi)
    fig.figimage(strip, xo=0, yo=caption_px, origin="upper")
    for i, text in enumerate(captions):
        fig.text((i + 0.5) * w / strip.shape[1], caption_px / 2 / (h + caption_px), text,
                 ha="center", va="center", fontsize=fontsize, linespacing=1.3)
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path
