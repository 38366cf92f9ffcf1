"""Things people look at after a run: tracking-error plots, a snapshot strip, an MP4.

- ``tracking_<arm>.png``: per arm joint, ``pos − ref`` [rad] against time, PWM stretches
  shaded (like thesis Figs. 4.3–4.4). Matplotlib with the Agg backend (no display).
- ``plan_vs_sim.png``: for the joints whose torque departed most from the plan by the
  run's end (`execute.validate.plan_compare`), MuJoCo's torque against the plan's torque LP
  along the run, with the joint's limit: when the two parted.
- ``snapshots.png``: a strip of frames from the robot's right, framing the whole robot,
  rendered off-screen by ``mujoco.Renderer`` with ``MUJOCO_GL=egl``; each frame captioned
  "simulation", its time and plan line, and what that line's segment does.

Every mark has a legend entry, and titles are wrapped to the figure's width
(`planner.plots.wrap_to_width`).
- ``*.mp4``: the same camera at 30 fps through imageio-ffmpeg.

Rendering needs an OpenGL context. If EGL is not available (no GPU driver, no Mesa EGL),
`RenderingUnavailable` says so and the plots are still written.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ladders.render import SNAPSHOT_SIZE, RenderingUnavailable, render_states, write_strip
from planner.plots import frame_caption, wrap_to_width
from robot.joints import ARM_JOINTS, joint_indices

__all__ = ["RenderingUnavailable", "plan_comparison_figure", "render_frames",
           "snapshot_captions", "tracking_figure", "write_plan_comparison_plot",
           "write_snapshot_strip", "write_tracking_plots", "write_video"]

VIDEO_SIZE = (640, 480)  # [px]
VIDEO_FPS = 30


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def tracking_figure(run, arm: str):
    """One arm's figure: ``pos − ref`` [rad] per joint vs time, PWM stretches shaded."""
    plt = _pyplot()
    lg = run.log
    names = ARM_JOINTS[arm]
    idx = joint_indices(names)
    fig, axes = plt.subplots(len(idx), 1, sharex=True, figsize=(8, 10), layout="constrained")
    for ax, name, j in zip(axes, names, idx, strict=True):
        ax.plot(lg.time_s, lg.pos_rad[:, j] - lg.ref_rad[:, j], lw=0.8,
                label="pos − ref (tracking error)")
        pwm = lg.pwm[:, j]
        if pwm.any():
            ax.fill_between(lg.time_s, 0, 1, where=pwm, color="orange", alpha=0.2,
                            transform=ax.get_xaxis_transform(),
                            label="shaded: joint in PWM mode")
        ax.set_ylabel(f"{name}\n[rad]", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(alpha=0.3)
    _legend_of_all(fig, axes)
    outcome = run.verdict.failure.cause if run.verdict.failure else "climbed"
    fig.suptitle(wrap_to_width(fig, f"{arm} arm: tracking error pos − ref per joint, "
                                    f"strategy {run.options.strategy} ({outcome})", 11),
                 fontsize=11)
    axes[-1].set_xlabel("time [s]")
    return fig


def write_tracking_plots(run, out_dir: str | os.PathLike) -> list[Path]:
    """One PNG per arm, ``tracking_<arm>.png`` (`tracking_figure`)."""
    plt = _pyplot()
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for arm in ARM_JOINTS:
        fig = tracking_figure(run, arm)
        path = out / f"tracking_{arm}.png"
        fig.savefig(path, dpi=90)
        plt.close(fig)
        paths.append(path)
    return paths


def plan_comparison_figure(run, comparison, trajectory_rad: np.ndarray, ladder,
                           joints: int = 4, verifier=None):
    """Simulated against planned torque [N·m] vs time for the ``joints`` joints that
    departed most from the plan (`execute.validate.plan_compare`), with their limits.
    ``verifier``: the plan's verifier, if the caller has one (its stances are reused)."""
    from execute.validate.plan_compare import planned_torque_history

    plt = _pyplot()
    names = [j.joint for j in comparison.joints[:joints]]
    limits = {j.joint: j.limit_nm for j in comparison.joints}
    times, planned = planned_torque_history(run, trajectory_rad, ladder, names,
                                            verifier=verifier)
    lg = run.log
    fig, axes = plt.subplots(len(names), 1, sharex=True, figsize=(8, 2.2 * len(names) + 0.8),
                             squeeze=False, layout="constrained")
    for ax, name, col in zip(axes[:, 0], names, planned.T, strict=True):
        ax.plot(lg.time_s, lg.torque_nm[:, joint_indices([name])[0]], lw=0.8,
                label="MuJoCo")
        ax.plot(times, col, lw=1.2, ls="--", label="plan (torque LP)")
        for sign in (1, -1):
            ax.axhline(sign * limits[name], color="red", lw=0.6, alpha=0.6,
                       label="torque limit (±)" if sign > 0 else None)
        ax.set_ylabel(f"{name}\n[N·m]", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.grid(alpha=0.3)
    _legend_of_all(fig, axes[:, 0])
    summary = comparison.summary()
    fig.suptitle(wrap_to_width(fig, f"Joint torque in MuJoCo and in the plan, the "
                                    f"{len(names)} joints furthest apart\n"
                                    f"{summary[0].upper()}{summary[1:]}", 9), fontsize=9)
    axes[-1, 0].set_xlabel("time [s]")
    return fig


def write_plan_comparison_plot(run, comparison, trajectory_rad: np.ndarray, ladder,
                               path: str | os.PathLike, joints: int = 4,
                               verifier=None) -> Path:
    """``plan_vs_sim.png`` (`plan_comparison_figure`)."""
    plt = _pyplot()
    fig = plan_comparison_figure(run, comparison, trajectory_rad, ladder, joints, verifier)
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=90)
    plt.close(fig)
    return out


def _legend_of_all(fig, axes) -> None:
    """One legend for the figure, below the plots, with every labelled mark of any of
    ``axes`` once."""
    entries: dict[str, object] = {}
    for ax in axes:
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            entries.setdefault(label, handle)
    fig.legend(list(entries.values()), list(entries), loc="outside lower center",
               ncols=min(3, len(entries)), fontsize=8)


def _rows(run, times_s) -> list[int]:
    lg = run.log
    return [int(np.clip(np.searchsorted(lg.time_s, t), 0, len(lg.time_s) - 1))
            for t in times_s]


def render_frames(run, times_s, size: tuple[int, int]) -> list[np.ndarray]:
    """RGB frames of the run at the given simulated times (`ladders.render`)."""
    lg = run.log
    if lg.qpos is None or not len(lg.qpos):
        raise ValueError("the run kept no qpos (record_qpos=False)")
    return render_states(run.board.model, lg.qpos[_rows(run, times_s)], size)


def snapshot_captions(run, times_s) -> list[str]:
    """Each snapshot's caption: "simulation", its time, the plan line playing and what
    that line's segment does (`planner.plots.frame_caption`)."""
    lg = run.log
    return [frame_caption("simulation", float(lg.time_s[r]), int(lg.line_index[r]) + 1,
                          run.sidecar) for r in _rows(run, times_s)]


def write_snapshot_strip(run, path: str | os.PathLike, count: int = 6) -> Path:
    """``count`` evenly spaced frames side by side in one PNG, captioned."""
    times = np.linspace(0.0, float(run.log.time_s[-1]), count)
    return write_strip(render_frames(run, times, SNAPSHOT_SIZE), path,
                       snapshot_captions(run, times))


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
