"""Pictures of a plan: per-stance CoM plots and a snapshot strip.

Stance plots: one PNG per stance (a set of holds in contact), in the order the plan first uses it:
the support region polygon (the CoM positions where gravity can be balanced within the
friction cones), the ground projection of the holds, and the CoM of every configuration
the plan passes through in that stance. Rendered with matplotlib's Agg backend (no
display needed).

Snapshot strip: ``snapshots.png``, planned configurations at evenly spaced lines drawn in
the MuJoCo scene of the ladder (`ladders.render`, headless with ``MUJOCO_GL=egl``), the
same view ``validate-plan`` gives of the simulated climb.
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from planner.search import ClimbPlanner, SearchResult

__all__ = ["plan_qpos", "stance_groups", "write_plan_strip", "write_stance_plots"]


def _stance_key(holds) -> tuple:
    return tuple(sorted((h.limb, h.target, tuple(np.round(h.T_world_frame[:3, 3], 4)))
                        for h in holds))


def stance_groups(result: SearchResult) -> list[tuple[tuple, list[int]]]:
    """Segments grouped by the stance they are in, in order of first use.

    Returns:
        ``[(holds, [segment indices])]`` where ``holds`` is the first segment's tuple.
    """
    order: dict[tuple, int] = {}
    groups: list[tuple[tuple, list[int]]] = []
    for i, seg in enumerate(result.segments):
        key = _stance_key(seg.holds)
        if key not in order:
            order[key] = len(groups)
            groups.append((tuple(seg.holds), []))
        groups[order[key]][1].append(i)
    return groups


def _file_name(k: int, label: str) -> str:
    return f"stance_{k:02d}_{re.sub(r'[^A-Za-z0-9_.-]+', '_', label)}.png"


def write_stance_plots(result: SearchResult, planner: ClimbPlanner,
                       out_dir: str | os.PathLike) -> list[Path]:
    """Write one CoM-vs-support-region plot per stance into ``out_dir``.

    Args:
        result: the search result.
        planner: its planner (kinematics for the CoM, checker for support regions).
        out_dir: directory, created if missing.

    Returns:
        The PNG files written.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from planner.contacts import Stance

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for k, (holds, idx) in enumerate(stance_groups(result)):
        stance = Stance(holds)
        region = planner.checker.region(stance)
        com = np.array([planner.kin.com(q) for i in idx for q in result.segments[i].configs])
        first = result.segments[idx[0]]
        label = f"{first.step.label}_{first.phase}"
        fig, ax = plt.subplots(figsize=(5.5, 5.0))
        if not region.is_empty and len(region.vertices) >= 2:
            v = np.vstack([region.vertices, region.vertices[:1]])
            ax.fill(v[:, 0], v[:, 1], alpha=0.2, color="tab:green",
                    label="support region" + (" (clipped)" if region.clipped else ""))
            ax.plot(v[:, 0], v[:, 1], color="tab:green", lw=1)
        for h in holds:
            pts = np.asarray(h.points_m)
            ax.scatter(pts[:, 0], pts[:, 1], marker="x" if h.is_hand else "s", s=18,
                       color="tab:gray")
            p = h.T_world_frame[:3, 3]
            ax.annotate(f"{h.limb}\n{h.target}", p[:2], fontsize=6, color="tab:gray")
        margins = []
        if len(com):
            ax.plot(com[:, 0], com[:, 1], color="tab:blue", lw=1.2, label="CoM")
            ax.scatter(com[:1, 0], com[:1, 1], color="tab:blue", marker="o", s=20,
                       label="start")
            ax.scatter(com[-1:, 0], com[-1:, 1], color="tab:red", marker="o", s=20,
                       label="end")
            if not region.is_empty:
                margins = list(np.atleast_1d(region.margin(com)))
        worst = f", min margin {min(margins) * 100:.1f} cm" if margins else ""
        ax.set_title(f"{first.step.label} {first.phase}: {len(com)} configurations{worst}",
                     fontsize=8)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, lw=0.3)
        ax.legend(fontsize=7, loc="lower left", framealpha=0.6)
        path = out / _file_name(k, label)
        fig.tight_layout()
        fig.savefig(path, dpi=110)
        plt.close(fig)
        written.append(path)
    return written


def plan_qpos(model, kin, configs: np.ndarray) -> np.ndarray:
    """MuJoCo ``qpos`` rows of the scene ``model`` for planner configurations (pinocchio
    layout: base position, quaternion x y z w, then the joints)."""
    import mujoco

    from robot.mjcf import joint_qpos_addresses

    root = next(j for j in range(model.njnt)
                if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE)
    base = int(model.jnt_qposadr[root])
    joints = [(adr, kin.q_index[name]) for name, adr in joint_qpos_addresses(model).items()
              if name in kin.q_index]
    out = np.tile(model.qpos0, (len(configs), 1))
    for row, q in zip(out, np.atleast_2d(configs), strict=True):
        row[base:base + 3] = q[:3]
        row[base + 3:base + 7] = (q[6], q[3], q[4], q[5])  # MuJoCo: w x y z
        for adr, i in joints:
            row[adr] = q[i]
    return out


def write_plan_strip(configs: np.ndarray, kin, ladder, path: str | os.PathLike,
                     count: int = 6) -> Path:
    """``count`` planned configurations, evenly spaced over the plan's lines, side by
    side in one PNG (raises `ladders.render.RenderingUnavailable` without EGL)."""
    from ladders.render import SNAPSHOT_SIZE, render_states, write_strip
    from ladders.scene import build_scene

    model = build_scene(ladder, kin.params).compile()
    lines = np.linspace(0, len(configs) - 1, count).round().astype(int)
    return write_strip(render_states(model, plan_qpos(model, kin, configs[lines]),
                                     SNAPSHOT_SIZE), path)
