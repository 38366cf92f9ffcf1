"""Figures of merit of a simulated run (`execute.validate.simulate.SimulationRun`).

- **Tracking error per arm** (thesis §4.3.4): for each of the arm's 7 joints, the sum
  over trajectory lines of ``|pos − ref|`` [rad], sampled once per line (the last tick
  the line is the reference), then the Euclidean norm over the joints. ``ref`` is what
  hubo-state reports: the reference the board ran on after the daemon's filter. The
  thesis measured 0.0036 (position) and 0.2372 (PWM) over a climb.
- **Peak torque ratio**: ``max |τ| / τ_max`` over joints and ticks, and which joint.
- **Minimum CoM margin**: the smallest distance of the CoM's ground projection inside
  the convex hull of the robot's contact points, over the ticks where every contact is
  on a horizontal surface (floor or rung treads) and no hand is latched, sampled every
  10 ticks. Then the hull is the exact static support polygon. Ticks with a hand on a
  rail have a 3-D support region (the planner's LP, `planner.statics.com_region`, which the
  executor does not import); they are left out, so the figure is ``None`` when no tick
  qualifies.
- **Hold slip**: the largest drift of a sole from where it stood at the start of a
  segment that keeps that foot on a hold [m]; per hand, the largest net turn about its
  rail [deg] and slide along it [m] of one grasp, from its latch to its release
  (`daemon.sim.grasp_latch`: beyond the grip's friction a closed hand slips on its rail;
  letting go is a verdict failure).
- **Simulated seconds per rung**: simulated time / rungs climbed (`rungs_climbed`: the
  highest rung a foot stood on in a segment the run played to its end, +1), ``None``
  when the run climbed no rung.
- **Real-time factor**: simulated time / wall time of the loop.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import mujoco
import numpy as np

from robot.joints import ARM_JOINTS, JOINT_NAMES, joint_indices
from robot.vocabulary import HoldTargetKind, Limb

__all__ = ["RunMetrics", "compute_metrics", "line_samples", "rungs_climbed",
           "tracking_error_by_arm"]

_CONTACT_SAMPLE_TICKS = 10


@dataclass(frozen=True)
class RunMetrics:
    """See the module docstring. Units in the names."""

    tracking_error_rad: dict[str, float]  # arm → norm over joints of per-joint sums
    tracking_error_by_joint_rad: dict[str, float]  # joint → sum over lines
    peak_torque_ratio: float
    peak_torque_joint: str
    min_com_margin_m: float | None
    min_com_margin_time_s: float | None  # when that minimum was
    min_com_margin_line: int | None  # the trajectory line then (1-based)
    max_foot_slip_m: float
    max_hand_turn_per_grasp_deg: dict[str, float]  # hand → largest net turn of one grasp
    max_hand_slide_per_grasp_m: dict[str, float]  # hand → largest net slide of one grasp
    simulated_s: float
    rungs_climbed: int
    simulated_s_per_rung: float | None
    real_time_factor: float
    lines_played: int

    def to_json(self) -> dict:
        return asdict(self)


def line_samples(line_index: np.ndarray) -> np.ndarray:
    """Tick indices of the last tick of each line played (ascending)."""
    change = np.flatnonzero(np.diff(line_index) != 0)
    return np.concatenate([change, [len(line_index) - 1]]) if len(line_index) else change


def tracking_error_by_arm(pos_rad: np.ndarray, ref_rad: np.ndarray, line_index: np.ndarray
                          ) -> tuple[dict[str, float], dict[str, float]]:
    """(arm → thesis tracking error [rad], joint → sum over lines of |pos − ref| [rad])."""
    ticks = line_samples(line_index)
    per_joint = np.abs(pos_rad[ticks] - ref_rad[ticks]).sum(axis=0)
    by_arm, by_joint = {}, {}
    for arm, names in ARM_JOINTS.items():
        idx = joint_indices(names)
        by_arm[arm] = float(np.linalg.norm(per_joint[idx]))
        by_joint.update({n: float(per_joint[i]) for n, i in zip(names, idx, strict=True)})
    return by_arm, by_joint


def _com_margin(model, data, qpos_rows, com_rows, latched_rows, env_geoms
                ) -> tuple[float | None, int | None]:
    """(smallest margin [m], its row) over the rows that qualify (module docstring)."""
    from scipy.spatial import ConvexHull, QhullError

    best, where = None, None
    pts = []
    for row, (q, com, lat) in enumerate(zip(qpos_rows, com_rows, latched_rows, strict=True)):
        if lat.any():
            continue
        data.qpos[:] = q
        mujoco.mj_fwdPosition(model, data)
        pts.clear()
        ok = True
        for c in data.contact[:data.ncon]:
            if not ({int(c.geom1), int(c.geom2)} & env_geoms):
                continue
            if abs(c.frame[2]) < 0.99:  # contact normal not vertical: not a flat support
                ok = False
                break
            pts.append(c.pos[:2].copy())
        if not ok or len(pts) < 3:
            continue
        P = np.array(pts)
        try:
            hull = ConvexHull(P)
        except QhullError:
            continue
        # hull.equations: n·x + b <= 0 inside; margin = min over edges of −(n·c + b)
        margin = float(np.min(-(hull.equations[:, :2] @ com[:2] + hull.equations[:, 2])))
        if best is None or margin < best:
            best, where = margin, row
    return best, where


def compute_metrics(run) -> RunMetrics:
    """The metrics of a finished `execute.validate.simulate.SimulationRun`."""
    lg = run.log
    by_arm, by_joint = tracking_error_by_arm(lg.pos_rad, lg.ref_rad, lg.line_index)
    lim = run.board.limits.torque_max_nm
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(lim > 0, np.abs(lg.torque_nm) / lim, 0.0)
    if ratio.size:
        k, j = np.unravel_index(int(np.argmax(ratio)), ratio.shape)
        peak, peak_joint = float(ratio[k, j]), JOINT_NAMES[j]
    else:
        peak, peak_joint = 0.0, ""
    margin = margin_tick = None
    if lg.qpos is not None and len(lg.qpos):
        m = run.board.model
        d = mujoco.MjData(m)
        ladder = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "ladder")
        env = {g for g in range(m.ngeom) if m.geom_bodyid[g] in (0, ladder)}
        sel = slice(0, None, _CONTACT_SAMPLE_TICKS)
        margin, row = _com_margin(m, d, lg.qpos[sel], lg.com_m[sel], lg.latched[sel], env)
        margin_tick = None if row is None else row * _CONTACT_SAMPLE_TICKS
    slip = 0.0
    for seg in run.sidecar.segments:
        ticks = np.flatnonzero((lg.line_index >= seg.first_line - 1) &
                               (lg.line_index <= seg.last_line - 1))
        if len(ticks) == 0:
            continue
        for s, limb in enumerate(("left_foot", "right_foot")):
            if limb in seg.holds:
                drift = np.linalg.norm(lg.sole_m[ticks, s] - lg.sole_m[ticks[0], s], axis=1)
                slip = max(slip, float(drift.max()))
    lines_played = int(lg.line_index.max()) + 1 if len(lg.line_index) else 0
    climbed = rungs_climbed(run.sidecar.segments, lines_played)
    sim_s = float(run.simulated_s)
    latches = run.board.latches.items()
    return RunMetrics(
        tracking_error_rad=by_arm, tracking_error_by_joint_rad=by_joint,
        peak_torque_ratio=peak, peak_torque_joint=peak_joint, min_com_margin_m=margin,
        min_com_margin_time_s=None if margin_tick is None else float(lg.time_s[margin_tick]),
        min_com_margin_line=None if margin_tick is None else int(lg.line_index[margin_tick]) + 1,
        max_foot_slip_m=slip,
        max_hand_turn_per_grasp_deg={h: math.degrees(latch.max_grasp_turn_rad)
                                     for h, latch in latches},
        max_hand_slide_per_grasp_m={h: latch.max_grasp_slide_m for h, latch in latches},
        simulated_s=sim_s, rungs_climbed=climbed,
        simulated_s_per_rung=sim_s / climbed if climbed else None,
        real_time_factor=float(run.real_time_factor) if math.isfinite(
            run.real_time_factor) else 0.0,
        lines_played=lines_played)


def rungs_climbed(segments, lines_played: int) -> int:
    """Rungs a run climbed: the highest rung a foot stood on in a segment played to its
    end, plus 1; 0 when no such segment (a run that stopped before its first rung)."""
    rungs = [h.hold_target.rung for seg in segments if seg.last_line <= lines_played
             for limb, h in seg.holds.items()
             if Limb(limb).is_foot and h.hold_target.kind is HoldTargetKind.RUNG]
    return max(rungs) + 1 if rungs else 0
