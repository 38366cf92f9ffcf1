"""Things people look at after a run: tracking-error plots, a snapshot strip, an MP4.

- ``tracking_<arm>.png``: per arm joint, ``pos − ref`` [rad] against time, PWM stretches
  shaded (like thesis Figs. 4.3–4.4). Matplotlib with the Agg backend (no display).
- ``snapshots.png``: a strip of frames from the robot's right, following its CoM,
  rendered off-screen by ``mujoco.Renderer`` with ``MUJOCO_GL=egl``.
- ``*.mp4``: the same camera at 30 fps through imageio-ffmpeg.

Rendering needs an OpenGL context. If EGL is not available (no GPU driver, no Mesa EGL),
`RenderingUnavailable` says so and the plots are still written.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path

import numpy as np

from robot.joints import ARM_JOINTS, joint_indices

__all__ = ["RenderingUnavailable", "render_frames", "write_snapshot_strip",
           "write_tracking_plots", "write_video"]

log = logging.getLogger(__name__)

SNAPSHOT_SIZE = (320, 240)  # [px] width, height of one strip frame
VIDEO_SIZE = (640, 480)  # [px]
VIDEO_FPS = 30
#: Following camera: distance from the robot's CoM [m] and elevation [deg]. At MuJoCo's
#: 45° field of view, 2.8 m shows a 2.3 m tall slice: the 1.45 m robot, its holds and
#: the rungs around them.
FOLLOW_DISTANCE_M = 2.8
FOLLOW_ELEVATION_DEG = -10.0


class RenderingUnavailable(RuntimeError):
    """No off-screen OpenGL context could be created (EGL missing)."""


def write_tracking_plots(run, out_dir: str | os.PathLike) -> list[Path]:
    """One PNG per arm: ``pos − ref`` per joint vs time, PWM stretches shaded."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    lg = run.log
    paths = []
    for arm, names in ARM_JOINTS.items():
        idx = joint_indices(names)
        fig, axes = plt.subplots(len(idx), 1, sharex=True, figsize=(8, 10))
        for ax, name, j in zip(axes, names, idx, strict=True):
            err = lg.pos_rad[:, j] - lg.ref_rad[:, j]
            ax.plot(lg.time_s, err, lw=0.8)
            pwm = lg.pwm[:, j]
            if pwm.any():
                ax.fill_between(lg.time_s, 0, 1, where=pwm, color="orange", alpha=0.2,
                                transform=ax.get_xaxis_transform(), label="PWM mode")
            ax.set_ylabel(f"{name}\n[rad]", fontsize=8)
            ax.tick_params(labelsize=7)
            ax.grid(alpha=0.3)
        axes[0].set_title(f"{arm} arm tracking error pos − ref, strategy "
                          f"{run.options.strategy} ("
                          f"{run.verdict.failure.cause if run.verdict.failure else 'climbed'})")
        axes[-1].set_xlabel("time [s]")
        fig.tight_layout()
        path = out / f"tracking_{arm}.png"
        fig.savefig(path, dpi=90)
        plt.close(fig)
        paths.append(path)
    return paths


def render_frames(run, times_s, size: tuple[int, int]) -> list[np.ndarray]:
    """RGB frames at the given simulated times, seen from the robot's right like the
    scene's ``side`` camera but following the robot at `FOLLOW_DISTANCE_M` from its CoM
    (the fixed camera frames the whole ladder, which leaves the robot small).

    Raises:
        RenderingUnavailable: no EGL context (message says how to get one).
    """
    import sys

    if "mujoco" not in sys.modules:
        os.environ.setdefault("MUJOCO_GL", "egl")
    import mujoco

    lg = run.log
    if lg.qpos is None or not len(lg.qpos):
        raise ValueError("the run kept no qpos (record_qpos=False)")
    m = run.board.model
    d = mujoco.MjData(m)
    try:
        renderer = mujoco.Renderer(m, height=size[1], width=size[0])
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
    pelvis = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "pelvis")
    frames = []
    try:
        for t in times_s:
            k = int(np.clip(np.searchsorted(lg.time_s, t), 0, len(lg.time_s) - 1))
            d.qpos[:] = lg.qpos[k]
            mujoco.mj_forward(m, d)
            camera.lookat[:] = d.subtree_com[pelvis]
            renderer.update_scene(d, camera=camera, scene_option=option)
            frames.append(renderer.render().copy())
    finally:
        renderer.close()
    return frames


def write_snapshot_strip(run, path: str | os.PathLike, count: int = 6) -> Path:
    """``count`` evenly spaced frames side by side in one PNG."""
    import imageio.v3 as iio

    t_end = float(run.log.time_s[-1])
    frames = render_frames(run, np.linspace(0.0, t_end, count), SNAPSHOT_SIZE)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    iio.imwrite(path, np.concatenate(frames, axis=1))
    return path


def write_video(run, path: str | os.PathLike, fps: int = VIDEO_FPS) -> Path:
    """An MP4 of the run from the ``side`` camera (H.264 via imageio-ffmpeg)."""
    import imageio.v2 as imageio

    t_end = float(run.log.time_s[-1])
    frames = render_frames(run, np.arange(0.0, t_end, 1.0 / fps), VIDEO_SIZE)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with imageio.get_writer(path, fps=fps, codec="libx264", macro_block_size=8) as w:
        for f in frames:
            w.append_data(f)
    return path
