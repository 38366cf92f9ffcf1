"""Pictures of a plan: per-stance CoM plots and a snapshot strip.

Stance plots: one PNG per stance (a set of holds in contact), in the order the plan first
uses it, seen from above: the support region polygon (the CoM positions where gravity can
be balanced within the friction cones), each hold's contact points (a foot's sole
corners, a hand's grip), and the CoM of every configuration the plan passes through in
that stance. Every mark has a legend entry; the title says in words what the stance's
first segment does ("right foot moves to rung 4, seen from above") and what the robot
holds, wrapped to the figure's width (`wrap_to_width`). Rendered with matplotlib's Agg
backend (no display needed).

Snapshot strip: ``snapshots.png``, planned configurations at evenly spaced lines drawn in
the MuJoCo scene of the ladder (`ladders.render`, headless with ``MUJOCO_GL=egl``), the
same view ``validate-plan`` gives of the simulated climb, each captioned "plan", its time
and line and what its segment does (`frame_caption`).
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from robot.words import limb_words, target_words

if TYPE_CHECKING:
    from planner.search import ClimbPlanner, SearchResult

__all__ = ["hold_in_words", "plan_qpos", "stance_groups", "step_in_words", "wrap_to_width",
           "frame_caption", "stance_figure", "write_plan_strip", "write_stance_plots"]

#: Marker and colour of each limb's holds in the stance plots.
_LIMB_MARK = {"left_foot": ("s", "tab:olive"), "right_foot": ("s", "tab:purple"),
              "left_hand": ("X", "tab:orange"), "right_hand": ("X", "tab:cyan")}


def hold_in_words(limb: str, target: str) -> str:
    """``left_foot``, ``rung_3`` → "left foot on rung 3"; ``rail_right`` → "on the right
    rail"."""
    return f"{limb_words(limb)} on {target_words(target)}"


def step_in_words(primitive: str, phase: str, rung: int) -> str:
    """What a segment of a plan does, in words.

    Args:
        primitive: the thesis primitive (``placeRFoot``, ``moveLHand``, ``straighten``...).
        phase: the segment's phase (`robot.vocabulary.SegmentPhase`'s values).
        rung: the rung the feet stand on or step to.

    Returns:
        For example "right foot moves to rung 4", "left hand lets go of the left rail",
        "standing still after: both hands close on the rails".
    """
    m = re.fullmatch(r"(place|move)([LR])(Hand|Foot)", primitive)
    if m:
        side = "left" if m[2] == "L" else "right"
        limb = f"{side} {m[3].lower()}"
        if m[3] == "Foot":
            move = (f"{limb} steps onto rung {rung}" if m[1] == "place"
                    else f"{limb} moves to rung {rung}")
        else:
            move = f"{limb} moves up the {side} rail"
        phrases = {"limb": move, "body": f"the body shifts before the {limb} moves",
                   "release": f"{limb} lets go of the {side} rail",
                   "grasp": f"{limb} closes on the {side} rail"}
    elif primitive == "placeHands":
        phrases = {"limb": "both hands reach for the rails",
                   "grasp": "both hands close on the rails",
                   "body": "the body shifts before the hands reach for the rails",
                   "release": "both hands let go of the rails"}
    elif primitive == "straighten":
        phrases = {"body": f"the body straightens up on rung {rung}"}
    else:
        phrases = {}
    if phase == "dwell":
        main = next((phrases[p] for p in ("limb", "grasp", "body") if p in phrases), "")
        return f"standing still after: {main}" if main else "standing still"
    return phrases.get(phase, f"{primitive} ({phase}) at rung {rung}")


def wrap_to_width(fig, text: str, fontsize: float, share: float = 0.96) -> str:
    """``text`` broken into lines (at spaces, and at existing newlines) that each fit in
    ``share`` of the figure's width at ``fontsize``, measured by its renderer."""
    from matplotlib.font_manager import FontProperties

    renderer = fig.canvas.get_renderer()
    font = FontProperties(size=fontsize)
    room = share * fig.bbox.width

    def width(s: str) -> float:
        return renderer.get_text_width_height_descent(s, font, ismath=False)[0]

    out = []
    for paragraph in text.split("\n"):
        line = ""
        for word in paragraph.split(" "):
            trial = f"{line} {word}" if line else word
            if line and width(trial) > room:
                out.append(line)
                line = word
            else:
                line = trial
        out.append(line)
    return "\n".join(out)


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
    """Write one CoM-vs-support-region plot per stance into ``out_dir`` (`stance_figure`).

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

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for k, (holds, idx) in enumerate(stance_groups(result)):
        fig = stance_figure(result, planner, holds, idx)
        first = result.segments[idx[0]]
        path = out / _file_name(k, f"{first.step.label}_{first.phase}")
        fig.savefig(path, dpi=110)
        plt.close(fig)
        written.append(path)
    return written


def stance_figure(result: SearchResult, planner: ClimbPlanner, holds, idx: list[int]):
    """One stance seen from above (a `stance_groups` entry): the support region, each
    hold's contact points and the CoM of every configuration of its segments, every mark
    in the legend, titled in words (what its first segment does, what the robot holds)
    and wrapped to the figure's width."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from planner.contacts import Stance

    region = planner.checker.region(Stance(holds))
    com = np.array([planner.kin.com(q) for i in idx for q in result.segments[i].configs])
    first = result.segments[idx[0]]
    fig, ax = plt.subplots(figsize=(8.0, 5.5), layout="constrained")
    _draw_stance(ax, region, holds, com)
    margins = list(np.atleast_1d(region.margin(com))) if len(com) and \
        not region.is_empty else []
    worst = f", smallest CoM margin {min(margins) * 100:.1f} cm" if margins else ""
    what = step_in_words(first.step.primitive.name, first.phase, first.step.rung)
    held = "; ".join(hold_in_words(h.limb, h.target) for h in holds)
    title = (f"{what[0].upper()}{what[1:]}, seen from above\nHolding: {held}\n"
             f"{len(com)} configurations{worst}")
    fig.suptitle(wrap_to_width(fig, title, 10), fontsize=10)
    return fig


def _draw_stance(ax, region, holds, com: np.ndarray) -> None:
    """The support region, each hold's contact points and the CoM path, every mark in the
    legend (outside the axes, right)."""
    if not region.is_empty and len(region.vertices) >= 2:
        v = np.vstack([region.vertices, region.vertices[:1]])
        ax.fill(v[:, 0], v[:, 1], alpha=0.2, color="tab:green",
                label="support region: where the CoM can be balanced"
                      + (" (clipped)" if region.clipped else ""))
        ax.plot(v[:, 0], v[:, 1], color="tab:green", lw=1)
    for h in holds:
        marker, colour = _LIMB_MARK.get(h.limb, ("o", "tab:gray"))
        pts = np.asarray(h.points_m)
        what = "its grip" if h.is_hand else "its sole's corners"
        ax.scatter(pts[:, 0], pts[:, 1], marker=marker, s=28, color=colour,
                   label=f"{hold_in_words(h.limb, h.target)} ({what})")
    if len(com):
        ax.plot(com[:, 0], com[:, 1], color="tab:blue", lw=1.2,
                label="CoM path (its ground projection)")
        ax.scatter(com[:1, 0], com[:1, 1], color="tab:blue", marker="o", s=24,
                   label="CoM at the start", zorder=3)
        ax.scatter(com[-1:, 0], com[-1:, 1], color="tab:red", marker="o", s=24,
                   label="CoM at the end", zorder=3)
    ax.set_xlabel("x, towards the ladder [m]")
    ax.set_ylabel("y, to the robot's left [m]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.margins(0.08)
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0), framealpha=0.8)


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
                     count: int = 6, sidecar=None) -> Path:
    """``count`` planned configurations, evenly spaced over the plan's lines, side by
    side in one PNG, each captioned "plan", its time and line, and (with the plan's
    `robot.plan_sidecar.PlanSidecar`) what its segment does (raises
    `ladders.render.RenderingUnavailable` without EGL)."""
    from ladders.render import SNAPSHOT_SIZE, render_states, write_strip
    from ladders.scene import build_scene

    model = build_scene(ladder, kin.params).compile()
    lines = np.linspace(0, len(configs) - 1, count).round().astype(int)
    captions = None
    if sidecar is not None:
        captions = [frame_caption("plan", line / sidecar.rate_hz, line + 1, sidecar)
                    for line in lines]
    return write_strip(render_states(model, plan_qpos(model, kin, configs[lines]),
                                     SNAPSHOT_SIZE), path, captions)


def frame_caption(source: str, time_s: float, line: int, sidecar) -> str:
    """A snapshot's caption: "plan" or "simulation", its time and line, and what the
    segment of that line does."""
    seg = next((s for s in sidecar.segments if s.first_line <= line <= s.last_line), None)
    what = step_in_words(seg.primitive, seg.phase, seg.rung) if seg else "after the plan"
    return f"{source}, t = {time_s:.1f} s, line {line:,}\n{what}"
