"""A plan's layers in a recording: the robot, its segments in words, its holds, its CoM
and support region, and its planned hold forces.

The same layers serve a plan on its own (time = line / rate) and a plan as the ghost of a
simulated run (time = the simulated time at which the player played that line): the
caller gives the lines to draw, their times, and the time at which any line was first
played.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import rerun as rr

from execute.view.plan_poses import PlanKinematics
from execute.view.plan_statics import (
    FORCE_EVERY_S,
    MAX_FORCE_LINES,
    force_rows,
    hold_forces,
    support_polygon,
)
from execute.view.recording import (
    TIMELINE,
    log_event,
    log_robot,
    log_scalars,
    log_track,
    robot_bodies,
)
from execute.view.scene_meshes import body_meshes
from robot.vocabulary import Limb

__all__ = ["DISPLAY_EVERY_S", "LIMB_RGB", "PlanLayers", "log_plan", "segment_text"]

#: The robot is drawn every this long [s] (20 frames a second); the data is not thinned.
DISPLAY_EVERY_S = 0.05
#: Hold forces are drawn this long per newton [m/N] (a 50 kg robot's weight: 0.5 m).
ARROW_M_PER_N = 0.001
LIMB_RGB = {Limb.LEFT_HAND: (40, 170, 60), Limb.RIGHT_HAND: (220, 50, 50),
            Limb.LEFT_FOOT: (40, 110, 220), Limb.RIGHT_FOOT: (230, 150, 20)}
COM_RGB = (200, 30, 200)
REGION_RGB = (200, 30, 200)


@dataclass(frozen=True)
class PlanLayers:
    """What to draw of a plan, and how densely.

    Attributes:
        display_every_s: robot poses every this long of plan time [s].
        statics: the CoM's support regions, stability margin and hold forces.
        force_every_s: hold forces every this long [s] ...
        max_force_lines: ... on at most this many lines.
    """

    display_every_s: float = DISPLAY_EVERY_S
    statics: bool = True
    force_every_s: float = FORCE_EVERY_S
    max_force_lines: int = MAX_FORCE_LINES


def segment_text(kin: PlanKinematics, si: int) -> str:
    """One line on a segment: its index, lines, primitive and phase in words, the holds
    kept and the limbs in the air."""
    from planner.plots import step_in_words

    sc = kin.sidecar
    seg = sc.segments[si]
    holds = ", ".join(f"{limb.replace('_', ' ')} on {h.target}"
                      for limb, h in sorted(seg.holds.items()))
    moving = ", ".join(m.replace("_", " ") for m in seg.moving_limbs) or "none"
    return (f"segment {si + 1}/{len(sc.segments)}, lines {seg.first_line:,}–"
            f"{seg.last_line:,}: {seg.primitive} ({seg.phase}) — "
            f"{step_in_words(seg.primitive, seg.phase, seg.rung)}. Holds: {holds or 'none'}; "
            f"moving: {moving}")


def log_plan(rec: rr.RecordingStream, kin: PlanKinematics, rows: np.ndarray,
             times_s: np.ndarray, time_of_row: Callable[[int], float | None],
             layers: PlanLayers, root: str = "world/plan",
             tint_rgba: tuple[int, int, int, int] | None = None) -> None:
    """Log the plan's layers.

    Args:
        kin: the plan placed in the world.
        rows, times_s: (K,) the 0-based lines whose robot is drawn, and when.
        time_of_row: when a line was first played [s] (None: never).
        layers: what to draw.
        root: the 3D entity under which the plan goes.
        tint_rgba: one colour for the robot (a ghost), else the geoms' colours.
    """
    poses = kin.poses(rows, statics=layers.statics)
    log_robot(rec, f"{root}/robot", robot_bodies(kin.model, body_meshes(kin.model)), times_s,
              poses.body_pos_m, poses.body_quat_xyzw, tint_rgba)
    log_track(rec, f"{root}/com", times_s, poses.com_m, COM_RGB)
    if layers.statics:
        log_scalars(rec, "plan/stability_margin_cm", times_s, 100 * poses.margin_m,
                    "CoM inside its support region [cm]")
    for si, seg in enumerate(kin.sidecar.segments):
        t = time_of_row(seg.first_line - 1)
        if t is None:
            continue
        log_event(rec, "events/segment", t, segment_text(kin, si))
        limbs = sorted(seg.holds)
        rec.log(f"{root}/holds", rr.Points3D(
            [seg.holds[limb].position_m for limb in limbs], radii=0.03,
            colors=[LIMB_RGB[Limb(limb)] for limb in limbs],
            labels=[f"{limb.replace('_', ' ')}: {seg.holds[limb].target}" for limb in limbs]))
        if layers.statics:
            poly = support_polygon(kin, si)
            rec.log(f"{root}/support_region", rr.LineStrips3D(
                [poly.vertices_m], colors=[REGION_RGB], radii=0.004,
                labels=[f"support region of {', '.join(poly.limbs)}"]))
    if layers.statics:
        _log_hold_forces(rec, kin, root, time_of_row, layers)


def _log_hold_forces(rec: rr.RecordingStream, kin: PlanKinematics, root: str,
                     time_of_row: Callable[[int], float | None], layers: PlanLayers) -> None:
    """The torque LP's hold forces as arrows, and its worst torque ratio as a series."""
    rows = force_rows(kin.sidecar.line_count, kin.sidecar.rate_hz, layers.force_every_s,
                      layers.max_force_lines)
    times, ratios = [], []
    for f in hold_forces(kin, [row for row in rows if time_of_row(int(row)) is not None]):
        t = time_of_row(f.row)
        times.append(t)
        ratios.append(f.max_ratio if np.isfinite(f.max_ratio) else np.nan)
        rec.set_time(TIMELINE, duration=t)
        rec.log(f"{root}/hold_forces", rr.Arrows3D(
            origins=f.origins_m, vectors=ARROW_M_PER_N * f.forces_n,
            colors=[LIMB_RGB[Limb(limb)] for limb in f.limbs], radii=0.006,
            labels=[f"{np.linalg.norm(v):.0f} N" for v in f.forces_n]))
    log_scalars(rec, "plan/torque_ratio", np.array(times), np.array(ratios),
                "planned worst |τ|/τmax (torque LP)")
