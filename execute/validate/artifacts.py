"""Things people look at after a run: tracking-error plots, a snapshot strip, an MP4.

- ``tracking_<arm>.png``: per arm joint, ``pos − ref`` [rad] against time, PWM stretches
  shaded (like thesis Figs. 4.3–4.4). Matplotlib with the Agg backend (no display).
- ``plan_vs_sim.png``: for the joints whose torque departed most from the plan by the
  run's end (`execute.validate.plan_compare`), MuJoCo's torque against the plan's torque LP
  along the run, with the joint's limit: when the two parted.
- ``snapshots.png``: a strip of frames from the robot's right, following its CoM,
  rendered off-screen by ``mujoco.Renderer`` with ``MUJOCO_GL=egl``.
- ``*.mp4``: the same camera at 30 fps through imageio-ffmpeg.

Rendering needs an OpenGL context. If EGL is not available (no GPU driver, no Mesa EGL),
`RenderingUnavailable` says so and the plots are still written.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ladders.render import SNAPSHOT_SIZE, RenderingUnavailable, render_states, write_strip
from robot.joints import ARM_JOINTS, joint_indices

__all__ = ["RenderingUnavailable", "render_frames", "write_plan_comparison_plot",
           "write_snapshot_strip", "write_tracking_plots", "write_video"]

VIDEO_SIZE = (640, 480)  # [px]
VIDEO_FPS = 30


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


def write_plan_comparison_plot(run, comparison, trajectory_rad: np.ndarray, ladder,
                               path: str | os.PathLike, joints: int = 4) -> Path:
    """``plan_vs_sim.png``: simulated against planned torque [N·m] vs time for the
    ``joints`` joints that departed most from the plan (`execute.validate.plan_compare`)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from execute.validate.plan_compare import planned_torque_history

    names = [j.joint for j in comparison.joints[:joints]]
    limits = {j.joint: j.limit_nm for j in comparison.joints}
    times, planned = planned_torque_history(run, trajectory_rad, ladder, names)
    lg = run.log
    fig, axes = plt.subplots(len(names), 1, sharex=True, figsize=(8, 2.2 * len(names)),
                             squeeze=False)
    for ax, name, col in zip(axes[:, 0], names, planned.T, strict=True):
        ax.plot(lg.time_s, lg.torque_nm[:, joint_indices([name])[0]], lw=0.8,
                label="MuJoCo")
        ax.plot(times, col, lw=1.2, ls="--", label="plan (torque LP)")
        for sign in (1, -1):
            ax.axhline(sign * limits[name], color="red", lw=0.6, alpha=0.6)
        ax.set_ylabel(f"{name}\n[N·m]", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=7, loc="upper left")
    axes[0, 0].set_title(f"joint torque, MuJoCo against the plan\n{comparison.summary()}",
                         fontsize=8)
    axes[-1, 0].set_xlabel("time [s]")
    fig.tight_layout()
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=90)
    plt.close(fig)
    return out


def render_frames(run, times_s, size: tuple[int, int]) -> list[np.ndarray]:
    """RGB frames of the run at the given simulated times (`ladders.render`)."""
    lg = run.log
    if lg.qpos is None or not len(lg.qpos):
        raise ValueError("the run kept no qpos (record_qpos=False)")
    rows = [int(np.clip(np.searchsorted(lg.time_s, t), 0, len(lg.time_s) - 1))
            for t in times_s]
    return render_states(run.board.model, lg.qpos[rows], size)


def write_snapshot_strip(run, path: str | os.PathLike, count: int = 6) -> Path:
    """``count`` evenly spaced frames side by side in one PNG."""
    t_end = float(run.log.time_s[-1])
    return write_strip(render_frames(run, np.linspace(0.0, t_end, count), SNAPSHOT_SIZE),
                       path)


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
