"""Writing a planned climb: the 40-column trajectory and its ``.plan.json`` sidecar.

`write_plan` times the search result's dense segments (`planner.timing`), writes
``OUT.traj`` (deterministic: the same result gives the same bytes) and the sidecar:
per segment the primitive, phase, rung, lines, holds in contact and moving limbs; per
arm a run-length position/PWM schedule; the final holds; planner metrics, seed, timings
and version.

The arms' position/PWM schedule is `planner.arm_schedule`'s.
"""

from __future__ import annotations

import importlib.metadata
import logging
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from planner.arm_schedule import PWM_RAIL_DISTANCE_M, arm_schedule
from planner.statics.arm_capacity import DEFAULT_ARM_STRATEGY
from planner.verify.check import CLEARANCE_EVERY_LINES  # the verifier's sampling
from robot.constants import DAEMON_RATE_HZ
from robot.joints import ARM_JOINTS
from robot.plan_sidecar import (
    ArmFeedforward,
    HoldRecord,
    PlanSidecar,
    Segment,
    feedforward_rows,
    sidecar_path,
    write_sidecar,
)
from robot.trajectory_file import write_trajectory
from robot.vocabulary import SIDES, SegmentPhase

if TYPE_CHECKING:
    from planner.contacts import Hold
    from planner.search import ClimbPlanner, PathSegment, SearchResult
    from planner.timing import SegmentPath, TimedPlan

log = logging.getLogger(__name__)

#: ``progress(phase, done, total)``: how far `write_plan` is.
OutputProgress = Callable[[str, int, int], None]

__all__ = ["FEEDFORWARD_EVERY_LINES", "PlanOutput", "arm_feedforward", "planner_version",
           "segment_paths", "step_groups", "write_plan"]

#: The arms' feed-forward torques are sampled every this-many lines (0.1 s at 200 Hz:
#: a quasi-static climb's load shifts over seconds).
FEEDFORWARD_EVERY_LINES = 20
ARMS = SIDES


@dataclass
class PlanOutput:
    """What `write_plan` wrote.

    Attributes:
        traj_path, sidecar_path: the two files.
        sidecar: the sidecar as written.
        timed: the sampled trajectory with each line's segment and configuration.
        segment_paths: the timed inputs, one per search segment.
    """

    traj_path: Path
    sidecar_path: Path
    sidecar: PlanSidecar = field(repr=False)
    timed: TimedPlan = field(repr=False)
    segment_paths: list[SegmentPath] = field(repr=False)

    def __repr__(self) -> str:
        return (f"PlanOutput({self.traj_path}, {self.sidecar.line_count} lines, "
                f"{len(self.sidecar.segments)} segments)")


def planner_version() -> str:
    """The installed hubo-ladder version, or ``"unknown"`` from a bare checkout."""
    try:
        return importlib.metadata.version("hubo-ladder")
    except importlib.metadata.PackageNotFoundError:
        return "unknown"


def step_groups(segments: Sequence[PathSegment]) -> list[list[int]]:
    """Indices of the segments of each step, in order (consecutive segments that share
    their `Step`)."""
    groups: list[list[int]] = []
    for i, seg in enumerate(segments):
        if groups and segments[groups[-1][-1]].step is seg.step:
            groups[-1].append(i)
        else:
            groups.append([i])
    return groups


def segment_paths(result: SearchResult, kin, q_start: np.ndarray | None = None,
                  arm_strategy: str = DEFAULT_ARM_STRATEGY) -> list[SegmentPath]:
    """The search segments as timing inputs: each path starts where the previous ended.

    Args:
        result: the search result (segments exclude their start configuration).
        kin: `HuboKinematics` (columns of a configuration).
        q_start: the configuration the plan starts from; the first segment's first
            configuration if None.
        arm_strategy: how gripping arms are driven; under ``mixed`` a segment in which
            a hand holds its rail, closes on it or opens, moves that arm no faster than
            its compliant joints can follow (`planner.statics.arm_capacity`).

    Returns:
        One `SegmentPath` per segment; the last segment of each step dwells after it.
    """
    from planner.statics.arm_capacity import gripping_sides, gripping_velocity_limits
    from planner.timing import SegmentPath
    from robot.limits import joint_limits

    nominal = joint_limits(kin.params.name).velocity_nominal_rad_s

    last_of_step = {g[-1] for g in step_groups(result.segments)}
    out: list[SegmentPath] = []
    prev = None if q_start is None else np.asarray(q_start, dtype=float)
    for i, seg in enumerate(result.segments):
        configs = [np.asarray(q, dtype=float) for q in seg.configs]
        if prev is not None:
            configs = [prev] + configs
        prev = configs[-1] if configs else prev
        q = np.array(configs)
        on_rail = [h.limb for h in seg.holds]
        if seg.phase in (SegmentPhase.GRASP, SegmentPhase.RELEASE):
            on_rail += list(seg.moving_limbs)
        out.append(SegmentPath(f"{seg.step.label}/{seg.phase}",
                               np.array([kin.columns(c) for c in q]), q,
                               dwell_after=i in last_of_step,
                               velocity_max_rad_s=gripping_velocity_limits(
                                   nominal, gripping_sides(on_rail), arm_strategy)))
    return out


def _record(hold: Hold) -> HoldRecord:
    return HoldRecord(hold.target, tuple(float(v) for v in hold.T_world_frame[:3, 3]))


def _holds_after_steps(result: SearchResult, kin) -> list[dict[str, Hold]]:
    """The stance after each step, limb → hold.

    The step's last segment has every hold it keeps; a limb placed by the step (a foot,
    whose last segment is the swing) is read from the next step's segments where it
    supports, from the final stance after the last step, or else from the limb frame's
    pose at the end of the step (target from the step's seed hold).
    """
    from planner.contacts import LIMB_FRAME, Hold

    segs = result.segments
    groups = step_groups(segs)
    out = []
    for g, idx in enumerate(groups):
        last = segs[idx[-1]]
        holds = {h.limb: h for h in last.holds}
        moved = {limb for i in idx for limb in segs[i].moving_limbs}
        for limb in sorted(moved - set(holds)):
            found = None
            if g + 1 < len(groups):
                nxt = groups[g + 1]
                still = {lb for i in nxt for lb in segs[i].moving_limbs}
                if limb not in still:
                    found = next((h for i in nxt for h in segs[i].holds if h.limb == limb),
                                 None)
            else:
                found = result.final_stance.hold(limb)
            if found is None:
                seed = next((s for s in last.step.new_holds if s.limb == limb), None)
                if seed is None:
                    continue
                q = last.configs[-1]
                T = kin.frame_pose(q, LIMB_FRAME[limb])
                found = Hold(limb, seed.target, T, T[:3, 3][None, :], np.array([[0, 0, 1.0]]))
            holds[limb] = found
        out.append(holds)
    return out


def _sidecar_segments(result: SearchResult, timed: TimedPlan,
                      after: list[dict[str, Hold]]) -> list[Segment]:
    step_of_segment = {i: g for g, idx in enumerate(step_groups(result.segments)) for i in idx}
    out: list[Segment] = []
    key = np.stack([timed.segment_of_line, timed.dwell.astype(int)], axis=1)
    change = np.flatnonzero(np.any(key[1:] != key[:-1], axis=1)) + 1
    starts = np.concatenate([[0], change])
    ends = np.concatenate([change, [timed.line_count]])
    for a, b in zip(starts, ends, strict=True):
        seg = result.segments[int(timed.segment_of_line[a])]
        if timed.dwell[a]:
            holds = after[step_of_segment[int(timed.segment_of_line[a])]]
            phase, moving = SegmentPhase.DWELL, ()
        else:
            holds = {h.limb: h for h in seg.holds}
            phase, moving = seg.phase, tuple(seg.moving_limbs)
        out.append(Segment(seg.step.primitive.name, phase, int(seg.step.rung), int(a) + 1,
                           int(b), {limb: _record(h) for limb, h in sorted(holds.items())},
                           moving))
    return out


def arm_feedforward(result: SearchResult, timed: TimedPlan, after: list[dict[str, Hold]],
                    checker, every_lines: int = FEEDFORWARD_EVERY_LINES) -> ArmFeedforward:
    """The arm joint torques of the torque LP along the timed plan, every ``every_lines``.

    Each sampled line is held on the stance the search checked it against (its segment's
    holds; a step's holds after it for the dwell lines), with the limits of
    ``checker.torque_limits`` (a gripping arm gets what the plan's arm strategy lets it
    give). An arm whose hand holds nothing gets its own gravity torques: a compliant arm
    closing on a rail must not sag onto a lower point of it. A line whose LP has no
    solution (none should: every planned configuration passed it) keeps the previous
    sample's torques.
    """
    from planner.contacts import Stance

    step_of_segment = {i: g for g, idx in enumerate(step_groups(result.segments)) for i in idx}
    joints = tuple(n for side in ARMS for n in ARM_JOINTS[side])
    rows = feedforward_rows(timed.line_count, every_lines)
    torque = np.zeros((rows, len(joints)))
    stances: dict[tuple[int, bool], Stance] = {}
    for k in range(rows):
        i = min(k * every_lines, timed.line_count - 1)
        key = (int(timed.segment_of_line[i]), bool(timed.dwell[i]))
        if key not in stances:
            holds = (after[step_of_segment[key[0]]].values() if key[1]
                     else result.segments[key[0]].holds)
            stances[key] = Stance(tuple(holds))
        check = checker.holding_torques(timed.configs[i], stances[key])
        if check.equilibrium:
            torque[k] = [check.torque(n) for n in joints]
        elif k:
            torque[k] = torque[k - 1]
    torque.setflags(write=False)
    return ArmFeedforward(every_lines, joints, torque)


def _finite(x: float) -> float | None:
    return float(x) if np.isfinite(x) else None


def _metrics(result: SearchResult, planner: ClimbPlanner, timed: TimedPlan,
             segments: list[Segment], clearance_every: int,
             progress: OutputProgress | None = None) -> dict[str, Any]:
    from planner.verify.check import allowed_contacts  # the verifier's rule, shared

    stats = result.step_stats
    per_primitive: dict[str, dict[str, float]] = {}
    for st in stats:
        name = st.label.split("@")[0]
        agg = per_primitive.setdefault(name, {"time_s": 0.0, "samples": 0, "backtracks": 0})
        agg["time_s"] += st.seconds
        agg["samples"] += st.samples
        agg["backtracks"] += st.backtracks
    clearance, worst_line = np.inf, 0
    if timed.configs is not None and clearance_every > 0:
        bounds = np.array([s.first_line for s in segments])
        for line in range(1, timed.line_count + 1, clearance_every):
            if progress is not None and (line - 1) % (50 * clearance_every) == 0:
                progress("clearance", line - 1, timed.line_count)
            k = int(np.searchsorted(bounds, line, side="right") - 1)
            s = segments[k]
            frac = (line - s.first_line) / max(1, s.last_line - s.first_line)
            d = planner.checker.clearance(timed.configs[line - 1],
                                          allowed_contacts(segments, k, frac))
            if d < clearance:
                clearance, worst_line = d, line
    margins = [st.min_margin_m for st in stats if np.isfinite(st.min_margin_m)]
    return {
        "min_stability_margin_m": _finite(min(margins)) if margins else None,
        "max_torque_ratio": max((st.max_torque_ratio for st in stats), default=0.0),
        "min_clearance_m": _finite(clearance),
        "min_clearance_line": worst_line,
        "clearance_every_lines": clearance_every,
        "leg_clearance_m": planner.config.leg_clearance_m,
        "arm_clearance_m": planner.config.arm_clearance_m,
        "steps_at_min_leg_clearance": sum(st.leg_clearance_m < planner.config.leg_clearance_m
                                          for st in stats),
        "duration_s": timed.duration_s,
        "search_s": result.total_s,
        "steps": [{"label": st.label, "time_s": st.seconds, "samples": st.samples,
                   "backtracks": st.backtracks, "limb_detours": st.limb_detours,
                   "min_margin_m": _finite(st.min_margin_m),
                   "max_torque_ratio": st.max_torque_ratio, "failures": dict(st.failures),
                   "leg_clearance_m": _finite(st.leg_clearance_m),
                   "position_torque_share": _finite(st.position_torque_share)}
                  for st in stats],
        "primitives": per_primitive,
    }


def _arm_metrics(planner: ClimbPlanner, turn: dict[str, np.ndarray]) -> dict:
    """The sidecar metrics of the arms' schedule and the planner's arm and foot
    settings."""
    return {
        "palm_rail_pwm_distance_m": PWM_RAIL_DISTANCE_M,
        "max_held_palm_turn_rad": {side: float(turn[side].max()) for side in ARMS},
        "max_held_palm_turn_line": {side: int(np.argmax(turn[side])) + 1 for side in ARMS},
        "arm_strategy": planner.config.arm_strategy,
        "position_torque_share": planner.config.position_torque_share,
        "reserve_torque_share": planner.config.torque_share(0),
        "foot_cop_margin_m": planner.config.foot_cop_margin_m,
        "foot_friction_share": planner.config.foot_friction_share,
        "held_wrist_margin_rad": planner.config.held_wrist_margin_rad,
    }


def write_plan(result: SearchResult, planner: ClimbPlanner, out_traj: str | os.PathLike,
               rate_hz: float = DAEMON_RATE_HZ, timings: dict[str, float] | None = None, *,
               dwell_s: float = 0.5, q_start: np.ndarray | None = None,
               clearance_every: int = CLEARANCE_EVERY_LINES,
               progress: OutputProgress | None = None) -> PlanOutput:
    """Time the plan, write ``OUT.traj`` and ``OUT.plan.json``.

    Args:
        result: the search result.
        planner: the planner that produced it (kinematics, ladder geometry, checker,
            spec, seed).
        out_traj: path of the trajectory file; the sidecar goes next to it.
        rate_hz: file rate [Hz].
        timings: wall times to record in the sidecar [s] (e.g. ``{"search_s": ...}``);
            the timing and writing times are added.
        dwell_s: quasi-static hold after each step [s].
        q_start: configuration before the first segment; the planner's start
            configuration if None.
        clearance_every: measure the clearance metric on every n-th line (0: never).
        progress: called as ``progress(phase, done, total)`` as the output goes: timing
            (segments), palm poses (lines), clearance (lines), writing (0 of 1, 1 of 1).

    Returns:
        What was written.

    Raises:
        TimingError: a segment could not be timed within the joint limits.
    """
    from ladders.loader import ladder_to_mapping
    from planner.timing import TimingConfig, time_parameterize
    from robot.limits import joint_limits

    def phase(name: str, done: int, total: int) -> None:
        if progress is not None:
            progress(name, done, total)

    t0 = time.perf_counter()
    kin = planner.kin
    phase("timing", 0, len(result.segments))
    if q_start is None:
        q_start = planner.start_configuration()[0]
    paths = segment_paths(result, kin, q_start, planner.config.arm_strategy)
    timed = time_parameterize(paths, joint_limits(kin.params.name),
                              TimingConfig(rate_hz=rate_hz, dwell_s=dwell_s),
                              kin.q_index_of_column)
    t_timed = time.perf_counter()
    after = _holds_after_steps(result, kin)
    segments = _sidecar_segments(result, timed, after)
    phase("palm poses", 0, timed.line_count)
    arm_modes, turn = arm_schedule(planner, segments, timed)
    feedforward = arm_feedforward(result, timed, after, planner.checker)
    metrics = _metrics(result, planner, timed, segments, clearance_every, progress)
    phase("writing", 0, 1)
    metrics.update(_arm_metrics(planner, turn))
    out_traj = Path(out_traj)
    write_trajectory(out_traj, timed.columns_rad)
    all_timings = dict(timings or {})
    all_timings["timing_s"] = t_timed - t0
    all_timings["output_s"] = time.perf_counter() - t_timed
    sidecar = PlanSidecar(
        robot=kin.params.name, ladder=ladder_to_mapping(planner.spec),
        rate_hz=float(rate_hz), line_count=timed.line_count, segments=tuple(segments),
        arm_modes=arm_modes,
        final_holds={h.limb: _record(h) for h in sorted(result.final_stance.holds,
                                                         key=lambda h: h.limb)},
        seed=int(planner.seed), metrics=metrics, timings_s=all_timings,
        planner_version=planner_version(), arm_feedforward=feedforward)
    side_path = sidecar_path(out_traj)
    write_sidecar(side_path, sidecar)
    phase("writing", 1, 1)
    log.info("wrote %s (%d lines, %.1f s) and %s", out_traj, timed.line_count,
             timed.duration_s, side_path)
    return PlanOutput(out_traj, side_path, sidecar, timed, paths)
