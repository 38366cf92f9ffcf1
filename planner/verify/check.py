"""A kinematic verifier of a planned climb, independent of the planner (``check-plan``'s
library; the command line is `planner.verify.cli`).

It trusts only the two files and the robot and ladder descriptions: no search, no IK, no
planner state. For every line it rebuilds the floating base from a foot the sidecar
says is in contact (its sole frame at the hold's position, flat on its tread: the
ladder's orientation on a rung, level on the floor), then checks:

- joint limits (the robot's position limits);
- joint speed between consecutive lines (nominal limits ×1.0 at the file rate);
- held wrists: while a foot is in the air, a hand holding a rail keeps its wrist pitch
  the plan's margin from zero, the wrist's singularity (`check_held_wrists`);
- holds: every limb the sidecar says is in contact has its frame within `HOLD_TOL_M` of
  the recorded hold, and the recorded hold lies within `HOLD_TOL_M` of its rung's tread,
  its rail's axis or the floor;
- collisions (coal, robot and ladder primitives; a limb's end links may touch what it
  holds, and a moving limb what it leaves in the first half of its segment and what it
  reaches in the second);
- static stability with the holds in contact: the CoM inside the support region
  (friction cones, Bretl–Lall) of the holds that may balance it (a lone compliant hand
  may not, `planner.statics.arm_capacity.balance_stance`) and the joint torques within limits
  (LP), an arm whose hand holds a rail limited to what the sidecar's arm strategy lets it
  give;
- contact wrenches: every grip's wrench in the torque LP's load share inside its limits
  (`ladders.contact_model`: radial force, bending, friction along and about the rail),
  the worst hold and limit named; a foot's friction cone and patch are the LP's
  constraints. Where the torque LP finds no share within the joint limits, a second
  LP reports the least use of the grips' capacity any such share needs.

The contacts are the contact model's, whole: the grip's full capacity (the planner keeps
`ladders.contact_model.GRIP_RESERVE` of it), the spec's μ and the sole's whole patch on
its tread (the planner keeps a friction share and a centre-of-pressure margin).

`check_plan` returns, per check, the worst line and whether any line fails.

Size: the checks run in one pass over the lines (`check_plan`), a batch of one segment's
lines at a time (`planner.verify.line_pass`); this module keeps what the pass shares:
the results, the contact rules and models, and `PlanVerifier`, the robot and ladder models
the lines are checked on.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from types import SimpleNamespace
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from ladders.contact_model import hand_limits, sole_patch_x
from planner.holds import WRIST_PITCH_JOINT, foot_patch, half_tread_m, wrist_bound_hands
from planner.statics.arm_capacity import balance_stance, gripping_sides, gripping_torque_limits
from robot.errors import InputError
from robot.plan_sidecar import PlanSidecar, Segment, segment_of_lines
from robot.vocabulary import HoldTarget, HoldTargetKind, Limb

if TYPE_CHECKING:
    from planner.contacts import Hold, Stance
    from planner.statics.com_region import SupportRegion
    from planner.statics.torque_lp import TorqueCheck

__all__ = ["CHECKS", "CLEARANCE_EVERY_LINES", "CheckResult", "ContactLoad", "HOLD_TOL_M",
           "PlanVerifier", "PlannedLoad",
           "allowed_contacts", "check_plan", "contact_hold", "contact_wrench_utilisation",
           "plan_verifier", "planned_loads"]

log = logging.getLogger(__name__)

#: A limb in contact must stay this close to its hold, and a hold to its rung/rail [m].
HOLD_TOL_M = 0.01
#: Slack on joint limits for values written by a float formatter [rad].
LIMIT_TOL_RAD = 1e-9
#: Clearance (a slow distance query) is measured on every this-many-th line, by check-plan
#: and for the plan's own clearance metric (planner.output), so the two compare.
CLEARANCE_EVERY_LINES = 20
#: Values within this of the worst are equal to it (`CheckResult.worst_line`) [the
#: check's unit: m, ratio, share]: rounding, and the LPs' vertices within their tolerance.
WORST_TIE = 1e-9
#: check_plan checks this many lines of a segment at once, and reports its progress after
#: each batch.
BATCH_LINES = 1024
CHECKS = ("joint limits", "velocity", "held wrists", "holds", "collision",
          "stability margin", "torque ratio", "contact wrench")
_FRAME = {"left_hand": "L_palm", "right_hand": "R_palm", "left_foot": "L_sole",
          "right_foot": "R_sole"}


@dataclass
class CheckResult:
    """The outcome of one check over all lines.

    Attributes:
        name: one of `CHECKS`.
        ok: every checked line passed.
        worst_line: 1-based line with the worst value (0: nothing checked): the first
            line whose value is within `WORST_TIE` of the worst, so that lines equal but
            for rounding (a dwell, a grip at its limit) name the first of them.
        value: the worst value, in ``unit``.
        limit: the value it must stay within, in ``unit``.
        unit: unit of ``value`` and ``limit``.
        detail: what the worst line is (segment, joint, limb, pair).
        failing_lines: how many lines fail.
    """

    name: str
    ok: bool = True
    worst_line: int = 0
    value: float = float("nan")
    limit: float = float("nan")
    unit: str = ""
    detail: str = ""
    failing_lines: int = 0
    _worst_key: float = field(default=-math.inf, repr=False)

    def offer(self, line: int, key: float, value: float, detail: str, failed: bool) -> None:
        """Record a line's value; ``key`` orders badness (larger is worse). Lines come
        in order; a later one must be worse by more than `WORST_TIE`."""
        self.failing_lines += int(failed)
        self.ok &= not failed
        if key > self._worst_key + WORST_TIE:
            self._worst_key, self.worst_line, self.value, self.detail = key, line, value, detail


def allowed_contacts(segments: Sequence[Segment], index: int, fraction: float
                     ) -> dict[str, str]:
    """Which environment object each limb may touch at a point of a sidecar segment.

    A held limb touches its hold's target. A moving limb may touch the object it left
    during the first half of the segment and the one it will hold during the second
    (a foot lifting off a rung, a hand closing in on a rail).

    Args:
        segments: the sidecar's segments.
        index: the segment.
        fraction: how far into the segment, 0 (first line) to 1 (last line).

    Returns:
        limb → environment object name (``floor``, ``rung_3``, ``rail_left``...).
    """
    seg = segments[index]
    contacts = {limb: h.target for limb, h in seg.holds.items()}
    for limb in seg.moving_limbs:
        before = next((s.holds[limb].target for s in reversed(segments[:index])
                       if limb in s.holds), None)
        after = next((s.holds[limb].target for s in segments[index + 1:] if limb in s.holds),
                     None)
        choice = (before or after) if fraction < 0.5 else (after or before)
        if choice is not None:
            contacts[limb] = choice
    return contacts


def contact_hold(spec, geom, params, limb: str, record) -> Hold:
    """The contact model of a recorded hold (`ladders.contact_model`, whole): a grip with
    its full capacity on the rail, or the sole's whole patch on its tread (the overlap; a
    line on a round rung) at the spec's μ.

    Args:
        spec, geom: the ladder and its `ladders.geometry.LadderGeometry`.
        params: the robot's `robot.params.RobotParams`.
        limb: the held limb.
        record: the sidecar's `robot.plan_sidecar.HoldRecord`.
    """
    from planner.contacts import Hold

    p = np.asarray(record.position_m, dtype=float)
    mu = spec.friction
    up = np.array([0.0, 0.0, 1.0])
    T = np.eye(4)
    T[:3, 3] = p
    if Limb(limb).is_hand:
        towards = geom.R_world_ladder[:, 0]
        return Hold(limb, record.target, T, np.vstack([p, p]), np.vstack([up, towards]), mu,
                    limits=hand_limits(mu, spec.rail_radius_m, geom.ladder_direction))
    R = np.eye(3) if record.target == "floor" else geom.R_world_ladder
    T[:3, :3] = R
    hl = params.foot_length_m / 2
    x_range = (-hl, hl)
    target = record.hold_target
    if target.kind is HoldTargetKind.RUNG:
        top = geom.rung_top_centres_m[target.rung]
        # Tread centre along the sole's x axis, relative to the sole frame.
        c = float(R[:, 0] @ (top - p))
        x_range = sole_patch_x(spec.rung_shape, half_tread_m(spec), c, params.foot_length_m)
        if x_range is None:  # the sole misses its rung: a line at the nearest sole edge
            c = float(np.clip(c, -hl, hl))
            x_range = (c, c)
    # The whole patch: check-plan verifies the physics, not the planner's margin.
    patch = foot_patch(params, x_range, mu, margin_m=0.0)
    pts = patch.corners() @ R.T + p
    return Hold(limb, record.target, T, pts, np.tile(up, (4, 1)), mu, limits=patch)


class ContactLoad(NamedTuple):
    """check-plan's contact-wrench account of one line.

    Attributes:
        value: the worst use of a contact limit [share of it] (inf: no load share within
            the joint limits keeps the holds within theirs).
        limb: the hold that reaches it ("" if none).
        load: which of its limits.
        detail: one clause for the report.
    """

    value: float
    limb: str
    load: str
    detail: str


def contact_wrench_utilisation(check: TorqueCheck) -> ContactLoad:
    """The most used grip limit of a torque LP's solution
    (`planner.statics.torque_lp.torque_feasibility`). A foot's limits are the LP's own
    constraints (cones at the spec's μ at its patch's corners), which its solution meets
    with equality wherever a vertex lies: an overloaded foot shows as no equilibrium."""
    if not check.equilibrium:
        return ContactLoad(math.inf, "", "", "no load share within the joint limits keeps "
                           "every hold within its contact limits")
    limb, load, use = check.worst_contact(hands_only=True)
    if not limb:
        return ContactLoad(0.0, "", "", "no grip")
    return ContactLoad(use, limb, load, _grip_clause(limb, load, use, *check.wrenches[limb]))


def _grip_clause(limb: str, load: str, use: float, force: np.ndarray, torque: np.ndarray
                 ) -> str:
    """The report's clause on a grip's most used limit: which, its use [share of it], and
    the grip's force [N] and torque [N·m]."""
    return (f"{limb} {load} {use:.2f} of its limit (|F| = {np.linalg.norm(force):.0f} N, "
            f"|T| = {np.linalg.norm(torque):.1f} N·m)")


class _SegmentStance(NamedTuple):
    """A segment's holds as the checks use them (`PlanVerifier.stance`)."""

    stance: Stance
    region: SupportRegion  # the CoM's, on the holds that may balance it
    torque_limits: dict[str, float]  # [N·m]
    balance_limbs: tuple[str, ...]  # those holds (`planner.statics.arm_capacity.balance_stance`)


class PlanVerifier:
    """The robot and ladder models the checks run on."""

    def __init__(self, spec, robot: str, arm_strategy: str):
        import pinocchio as pin

        from ladders.collision import ladder_collision_objects
        from ladders.geometry import LadderGeometry
        from planner.configuration.collision import CollisionModel
        from planner.statics.torque_lp import torque_limits_by_joint
        from robot.joints import JOINT_NAMES
        from robot.params import robot_params
        from robot.urdf import robot_urdf

        self.pin = pin
        self.params = robot_params(robot)
        self.spec = spec
        self.geom = LadderGeometry(spec)
        self.model = pin.buildModelFromXML(robot_urdf(self.params), pin.JointModelFreeFlyer())
        self.data = self.model.createData()
        self.q_index = np.array([self.model.joints[self.model.getJointId(n)].idx_q
                                 if self.model.existJointName(n) else -1
                                 for n in JOINT_NAMES])
        self.frame_id = {limb: self.model.getFrameId(f) for limb, f in _FRAME.items()}
        robot_view = SimpleNamespace(model=self.model, data=self.data, params=self.params)
        self.collision = CollisionModel(robot_view, ladder_collision_objects(spec))
        self.torque_max = torque_limits_by_joint(self.params.name)
        self.arm_strategy = arm_strategy
        self._stances: dict[int, _SegmentStance] = {}  # by segment index
        self._stances_by_holds: dict[tuple, _SegmentStance] = {}
        self._regions: dict[tuple, SupportRegion] = {}  # by the holds that balance
        self._stance_lines: dict[int, object] = {}  # segment index → its torque LP

    @cached_property
    def kin(self):
        """The robot's kinematics on batches of lines (`BatchKinematics`)."""
        from planner.verify.batch_kinematics import BatchKinematics

        return BatchKinematics(self.model)

    @cached_property
    def collision_lines(self):
        """The collision checks on batches of lines (`CollisionLines`)."""
        from planner.verify.collision_lines import CollisionLines

        return CollisionLines(self.collision)

    def stance_lines(self, seg_index: int, seg: Segment):
        """The torque LP of a segment's stance on batches of lines (`StanceLines`),
        cached: it carries its basis from batch to batch."""
        if seg_index not in self._stance_lines:
            from planner.verify.torque_lines import StanceLines

            held = self.stance(seg_index, seg)
            self._stance_lines[seg_index] = StanceLines(self.kin, held.stance.holds,
                                                        held.torque_limits, self.frame_id)
        return self._stance_lines[seg_index]

    # ---------------------------------------------------------------- configuration
    def sole_rotation(self, target: str) -> np.ndarray:
        return np.eye(3) if target == "floor" else self.geom.R_world_ladder

    def configuration(self, columns: np.ndarray, seg: Segment) -> np.ndarray | None:
        """Full configuration of a line, the base placed from a foot in contact."""
        pin = self.pin
        ref = next((lb for lb in ("left_foot", "right_foot") if lb in seg.holds), None)
        if ref is None:
            return None
        q = pin.neutral(self.model)
        have = self.q_index >= 0
        q[self.q_index[have]] = columns[have]
        pin.framesForwardKinematics(self.model, self.data, q)  # base at the origin
        T_base_sole = self.data.oMf[self.frame_id[ref]].homogeneous
        hold = seg.holds[ref]
        T_world_sole = np.eye(4)
        T_world_sole[:3, :3] = self.sole_rotation(hold.target)
        T_world_sole[:3, 3] = hold.position_m
        T_world_base = T_world_sole @ np.linalg.inv(T_base_sole)
        q[:3] = T_world_base[:3, 3]
        q[3:7] = pin.Quaternion(T_world_base[:3, :3]).coeffs()  # x y z w
        pin.framesForwardKinematics(self.model, self.data, q)
        return q

    def line_poses(self, columns: np.ndarray, seg: Segment):
        """`configuration` on a batch of lines: the joint poses in the world, the base
        placed from a foot in contact, and the lines' pinocchio configurations (built
        on demand); (None, None) when no foot is in contact.

        Args:
            columns: (L, 40) the lines [rad].
            seg: their segment.
        """
        from planner.verify.batch_kinematics import PinConfigurations

        ref = next((lb for lb in ("left_foot", "right_foot") if lb in seg.holds), None)
        if ref is None:
            return None, None
        q = np.zeros((len(columns), self.model.nq))
        have = self.q_index >= 0
        q[:, self.q_index[have]] = columns[:, have]
        frame = self.model.frames[self.frame_id[ref]]
        # The chain from the base to the foot, with the base at the origin, places it.
        rel = self.kin.joint_poses(q, upto=frame.parentJoint)
        R_bs, p_bs = rel.frame(frame.parentJoint, frame.placement.rotation,
                               frame.placement.translation)
        hold = seg.holds[ref]
        R_wb = self.sole_rotation(hold.target) @ R_bs.swapaxes(1, 2)
        p_wb = np.asarray(hold.position_m) - np.einsum("lij,lj->li", R_wb, p_bs)
        return self.kin.joint_poses(q, R_wb, p_wb), PinConfigurations(q, R_wb, p_wb)

    def frame_positions(self, poses, limb: str) -> np.ndarray:
        """(L, 3) world position of a limb's frame on a batch of lines [m]."""
        frame = self.model.frames[self.frame_id[limb]]
        return poses.frame(frame.parentJoint, frame.placement.rotation,
                           frame.placement.translation)[1]

    # ---------------------------------------------------------------- holds
    def target_distance(self, target: str, p: np.ndarray) -> float:
        """How far a recorded hold position lies from its object [m]; raises
        `robot.vocabulary.HoldTargetError` (bad input) for a target that names none."""
        hold = HoldTarget.parse(target)
        if hold.kind is HoldTargetKind.FLOOR:
            return abs(float(p[2]))
        if hold.kind is HoldTargetKind.RAIL:
            return float(np.linalg.norm(p - self.geom.closest_rail_point(hold.side, p)))
        s = self.spec  # a rung
        top = self.geom.to_ladder(self.geom.rung_top_centres_m[hold.rung])
        d = self.geom.to_ladder(p) - top
        # The sole overlaps the tread: its centre within half a foot of the tread.
        half_along = half_tread_m(s) + self.params.foot_length_m / 2
        excess = np.array([max(0.0, abs(d[0]) - half_along),
                           max(0.0, abs(d[1]) - s.rung_width_m / 2), d[2]])
        return float(np.linalg.norm(excess))

    # ---------------------------------------------------------------- stability
    def contact_hold(self, limb: str, record) -> Hold:
        """The contact model of a recorded hold (`contact_hold`)."""
        return contact_hold(self.spec, self.geom, self.params, limb, record)

    def stance(self, seg_index: int, seg: Segment) -> _SegmentStance:
        """The stance of a segment, its support region and its joint torque limits [N·m]
        (arms whose hands hold a rail driven as the plan's arm strategy drives them; the
        planner's capacity model is robot data), cached: by segment, by holds (segments
        that share their holds share it) and the region by the holds that balance."""
        if seg_index not in self._stances:
            key = _holds_key(seg.holds)
            if key not in self._stances_by_holds:
                self._stances_by_holds[key] = self._new_stance(seg)
            self._stances[seg_index] = self._stances_by_holds[key]
        return self._stances[seg_index]

    def _new_stance(self, seg: Segment) -> _SegmentStance:
        from planner.contacts import Stance
        from planner.statics.com_region import support_region

        holds = sorted(seg.holds.items())
        stance = Stance(tuple(self.contact_hold(lb, h) for lb, h in holds))
        limits = gripping_torque_limits(self.torque_max, gripping_sides(seg.holds),
                                        self.arm_strategy)
        balance = balance_stance(stance, self.arm_strategy)
        limbs = tuple(sorted(balance.limbs))
        key = _holds_key({lb: h for lb, h in holds if lb in limbs})
        if key not in self._regions:
            self._regions[key] = support_region(balance, self.params.total_mass_kg)
        return _SegmentStance(stance, self._regions[key], limits, limbs)


def _holds_key(holds: dict) -> tuple:
    """A hashable key of a segment's holds (limb, target, position)."""
    return tuple(sorted((lb, h.target, tuple(h.position_m)) for lb, h in holds.items()))


@dataclass(frozen=True, eq=False)
class PlannedLoad:
    """The plan's account of one line: where the body is and how it carries its weight.

    Attributes:
        line: the line (1-based).
        base_pose: (4, 4) world pose of the robot's root link, placed from a held foot.
        torque: the torque LP on the line's holds (check-plan's limits and contacts):
            joint torques and the contact forces on each held limb; None when the line
            has no foot in contact to place the body from.
    """

    line: int
    base_pose: np.ndarray | None
    torque: TorqueCheck | None


def plan_verifier(sidecar: PlanSidecar, spec, robot: str | None = None) -> PlanVerifier:
    """The verifier of a plan: its robot and ladder, its gripping arms driven as the plan's
    arm strategy drives them (rigid for a sidecar from before it was recorded)."""
    return PlanVerifier(spec, robot or sidecar.robot,
                        sidecar.metrics.get("arm_strategy", "position"))


def planned_loads(traj_rad: np.ndarray, sidecar: PlanSidecar, spec, lines: Sequence[int],
                  robot: str | None = None, verifier: PlanVerifier | None = None
                  ) -> list[PlannedLoad]:
    """The configuration and the torque LP of each of ``lines`` (1-based), as check-plan
    computes them: what a simulation of the plan is compared against.

    ``verifier`` (`plan_verifier`) keeps the stances it has built; callers that ask about
    the same plan several times pass one, so that each stance's support region is
    computed once.
    """
    from planner.statics.torque_lp import torque_feasibility

    seg_of = segment_of_lines(sidecar, "plan")
    v = verifier or plan_verifier(sidecar, spec, robot)
    out = []
    for line in lines:
        si = int(seg_of[line - 1])
        seg = sidecar.segments[si]
        q = v.configuration(traj_rad[line - 1], seg)
        if q is None:
            out.append(PlannedLoad(line, None, None))
            continue
        held = v.stance(si, seg)
        torque = torque_feasibility(v.model, v.data, q, held.stance, held.torque_limits,
                                    v.frame_id)
        base = np.eye(4)
        base[:3, :3] = v.pin.Quaternion(q[6], q[3], q[4], q[5]).toRotationMatrix()
        base[:3, 3] = q[:3]
        out.append(PlannedLoad(line, base, torque))
    return out


def check_plan(traj_rad: np.ndarray, sidecar: PlanSidecar, spec, robot: str | None = None,
               rate_hz: float | None = None, every: int = 1, where: str = "plan",
               progress: Callable[[int, int], None] | None = None) -> list[CheckResult]:
    """Run every check on a trajectory and its sidecar.

    Args:
        traj_rad: (N, 40) trajectory lines [rad] (not necessarily within limits).
        sidecar: its sidecar.
        spec: the `LadderSpec` the plan climbs.
        robot: robot name; the sidecar's if None.
        rate_hz: playback rate [Hz]; the sidecar's if None.
        every: check collisions and stability on every n-th line only (and on the
            first and last line of every segment); limits and holds are always checked
            on every line.
        where: the plan's name, for messages.
        progress: called as ``progress(lines_done, lines)`` at the start and after every
            batch (at most `BATCH_LINES` lines).

    Returns:
        One result per check, in `CHECKS` order.

    Raises:
        InputError: the sidecar and the trajectory disagree (line count, coverage).
    """
    from robot.limits import joint_limits

    robot = robot or sidecar.robot
    rate_hz = float(rate_hz or sidecar.rate_hz)
    # The torque a gripping arm may carry depends on how it will be driven; a sidecar from
    # before the strategy was recorded was planned with rigid arms.
    arm_strategy = sidecar.metrics.get("arm_strategy", "position")
    n = len(traj_rad)
    if n != sidecar.line_count:
        raise InputError(f"{where}: the trajectory has {n} lines, its sidecar's field "
                         f"'line_count' says {sidecar.line_count}")
    seg_of = segment_of_lines(sidecar, where)
    segs = sidecar.segments
    v = PlanVerifier(spec, robot, arm_strategy)
    res = _new_results()
    _check_limits_and_speed(res, traj_rad, joint_limits(robot), rate_hz)
    check_held_wrists(res["held wrists"], traj_rad, segs,
                      float(sidecar.metrics.get("held_wrist_margin_rad", 0.0)))

    # Per batch of lines of one segment: base from a foot, holds, collisions, stability.
    from planner.verify.line_pass import check_lines

    if progress is not None:
        progress(0, n)
    cuts = np.flatnonzero(np.diff(seg_of)) + 1
    for lo, hi in zip(np.r_[0, cuts], np.r_[cuts, n], strict=True):
        for a in range(int(lo), int(hi), BATCH_LINES):
            b = min(int(hi), a + BATCH_LINES)
            check_lines(res, v, traj_rad, segs, int(seg_of[a]), np.arange(a, b), every)
            if progress is not None:
                progress(b, n)
    return [res[c] for c in CHECKS]


def _new_results() -> dict[str, CheckResult]:
    """An empty result per check, with its limit and unit."""
    res = {c: CheckResult(c) for c in CHECKS}
    res["joint limits"].limit, res["joint limits"].unit = 0.0, "rad past limit"
    res["velocity"].limit, res["velocity"].unit = 1.0, "× nominal"
    res["held wrists"].unit = "rad from zero"
    res["holds"].limit, res["holds"].unit = HOLD_TOL_M, "m"
    res["collision"].limit, res["collision"].unit = 0.0, "m clearance"
    res["stability margin"].limit, res["stability margin"].unit = 0.0, "m"
    res["torque ratio"].limit, res["torque ratio"].unit = 1.0, "× limit"
    res["contact wrench"].limit, res["contact wrench"].unit = 1.0, "× limit"
    return res


def check_held_wrists(result: CheckResult, traj_rad: np.ndarray, segments: Sequence[Segment],
                      margin_rad: float) -> None:
    """While a foot is in the air, a hand on its hold keeps its wrist pitch at least
    ``margin_rad`` from zero, its singularity (the margin the plan was made with,
    `plan-ladder --held-wrist-margin`, and the planner's rule,
    `planner.holds.wrist_bound_hands`; a plan made without a margin has nothing to
    meet). The value is the smallest |pitch| on such a line."""
    from robot.joints import JOINT_INDEX

    result.limit = margin_rad
    worst = None
    bound_segments = [(seg, wrist_bound_hands(seg.holds)) for seg in segments]
    for limb, joint in WRIST_PITCH_JOINT.items():
        bound = np.zeros(len(traj_rad), dtype=bool)
        for seg, hands in bound_segments:
            if limb in hands:
                bound[seg.first_line - 1:seg.last_line] = True
        if not bound.any():
            continue
        pitch_rad = np.where(bound, np.abs(traj_rad[:, JOINT_INDEX[joint]]), np.inf)
        k = int(np.argmin(pitch_rad))
        failing = int(np.count_nonzero(pitch_rad < margin_rad - LIMIT_TOL_RAD))
        if worst is None or pitch_rad[k] < worst[0]:
            worst = (float(pitch_rad[k]), k, joint)
        result.failing_lines += failing
        result.ok &= failing == 0
    if worst is not None:
        value, k, joint = worst
        result.worst_line, result.value = k + 1, value
        bound = (f"at least {margin_rad:g} rad from zero" if margin_rad > 0
                 else "planned without a margin")
        result.detail = (f"{joint} = {traj_rad[k, JOINT_INDEX[joint]]:+.4f} rad while its hand "
                         f"holds and a foot is in the air ({bound})")


def _check_limits_and_speed(res: dict[str, CheckResult], traj_rad: np.ndarray, lim,
                            rate_hz: float) -> None:
    """Joint limits and joint speeds between lines: whole-array checks."""
    from robot.joints import JOINT_NAMES

    n = len(traj_rad)
    beyond = np.maximum(lim.lower_rad - traj_rad, traj_rad - lim.upper_rad)
    # The worst line, then every failing line, each once (the worst is usually among them).
    for k in dict.fromkeys(np.argsort(-beyond.max(axis=1))[:1].tolist()
                           + np.flatnonzero(beyond.max(axis=1) > LIMIT_TOL_RAD).tolist()):
        j = int(np.argmax(beyond[k]))
        res["joint limits"].offer(k + 1, beyond[k, j], float(beyond[k, j]),
                                  f"{JOINT_NAMES[j]} = {traj_rad[k, j]:.4f} rad, limits "
                                  f"[{lim.lower_rad[j]:.4g}, {lim.upper_rad[j]:.4g}]",
                                  bool(beyond[k, j] > LIMIT_TOL_RAD))
    if n > 1:
        ratio = np.abs(np.diff(traj_rad, axis=0)) * rate_hz / lim.velocity_nominal_rad_s
        worst = ratio.max(axis=1)
        for k in dict.fromkeys([int(np.argmax(worst))]
                               + np.flatnonzero(worst > 1.0 + 1e-9).tolist()):
            j = int(np.argmax(ratio[k]))
            vnom = lim.velocity_nominal_rad_s[j]
            res["velocity"].offer(k + 2, ratio[k, j], float(ratio[k, j]),
                                  f"{JOINT_NAMES[j]} at {ratio[k, j] * vnom:.3g} rad/s "
                                  f"(nominal {vnom:.3g})",
                                  bool(ratio[k, j] > 1.0 + 1e-9))
    else:
        res["velocity"].value = 0.0
