"""``hubo-view PLAN.traj``: a plan's recording.

The plan's time is line / rate. The robot is drawn every `DISPLAY_EVERY_S`; the segments,
holds and support regions change at their segments' first lines; the planned hold forces
are on a decimated set of lines (`execute.view.plan_statics`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import rerun as rr

from execute.view.layout import AFTER_FAILURE_S, blueprint
from execute.view.plan_layers import PlanLayers, log_plan
from execute.view.plan_poses import PlanKinematics
from execute.view.recording import log_static_bodies
from execute.view.scene_meshes import body_meshes
from ladders.spec import LadderSpec
from robot.errors import InputError
from robot.plan_sidecar import PlanSidecar

__all__ = ["PLAN_SERIES", "Plan", "display_rows", "read_plan", "record_plan"]

#: The plots of a plan's recording: (entity, title).
PLAN_SERIES = (("/plan/stability_margin_cm", "CoM margin in its support region [cm]"),
               ("/plan/torque_ratio", "planned worst joint torque / limit"))


@dataclass(frozen=True, eq=False)
class Plan:
    """A plan read from its two files."""

    path: Path
    trajectory_rad: np.ndarray
    sidecar: PlanSidecar
    ladder: LadderSpec


def read_plan(path: str | Path) -> Plan:
    """Read ``PLAN.traj[.gz]`` and its sidecar ``PLAN.plan.json``; the ladder is the
    sidecar's.

    Raises:
        InputError: a missing file, a malformed sidecar or trajectory, or the two
            disagreeing on the line count; the message names the file.
    """
    from ladders.loader import sidecar_ladder
    from robot.plan_sidecar import check_line_count, read_sidecar, sidecar_path
    from robot.trajectory_file import read_trajectory

    plan = Path(path)
    if not plan.is_file():
        raise InputError(f"{plan}: no such file")
    side = sidecar_path(plan)
    if not side.is_file():
        raise InputError(f"{side}: no plan sidecar next to {plan}; hubo-view needs the "
                         "segments and holds that plan-ladder writes beside the trajectory")
    sidecar = read_sidecar(side)
    traj = read_trajectory(plan, sidecar.rate_hz, sidecar.robot, check_speed=False)
    check_line_count(plan, len(traj), sidecar)
    return Plan(plan, traj, sidecar, sidecar_ladder(sidecar, str(side)))


def display_rows(line_count: int, step: int) -> np.ndarray:
    """Every ``step``-th line (0-based) and the last one."""
    rows = np.arange(0, line_count, max(1, step))
    return rows if rows[-1] == line_count - 1 else np.append(rows, line_count - 1)


def record_plan(rec: rr.RecordingStream, plan: Plan, layers: PlanLayers,
                failure_s: float | None = None) -> None:
    """Log a plan: the scene, the robot and the plan's layers, and the layout.

    With ``failure_s`` [s of plan time], the plan is drawn up to `AFTER_FAILURE_S` past
    it, so that the recording opens at the failure (`execute.view.layout`)."""
    rate = plan.sidecar.rate_hz
    kin = PlanKinematics(plan.trajectory_rad, plan.sidecar, plan.ladder, str(plan.path))
    log_static_bodies(rec, "world", kin.model, body_meshes(kin.model))
    rows = display_rows(plan.sidecar.line_count, round(layers.display_every_s * rate))
    last = plan.sidecar.line_count - 1
    if failure_s is not None:
        last = min(last, int((failure_s + AFTER_FAILURE_S) * rate))
        rows = np.append(rows[rows < last], last)
    log_plan(rec, kin, rows, rows / rate, lambda row: row / rate if row <= last else None,
             layers)
    rec.send_blueprint(blueprint(PLAN_SERIES if layers.statics else (), failure_s))
