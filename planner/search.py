"""Algorithm 5 of the thesis: randomized sequential descent over the primitive sequence.

Each step samples a hold near the primitive's seed hold (radius 0 at first, growing with
failures), a configuration feasible at both the old and the new stance, and a path. A
step that fails ``samples_per_step`` times backtracks: the previous step is re-sampled.

Size: one class, `ClimbPlanner`, whose methods share the search's state (the
kinematic model, the feasibility checker, the random generator, hints from earlier
samples); `try_step` reads as the step's phases (lift off, open hands, carry, place,
close hands).
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from ladders.geometry import LadderGeometry
from ladders.spec import LadderSpec
from planner.configuration.collision import CollisionModel
from planner.configuration.feasible import FeasibleSearchStats, SearchTarget, find_feasible
from planner.configuration.ik import IKConfig, solve_ik
from planner.configuration.kinematics import HuboKinematics
from planner.configuration.validity import FeasibilityChecker, Verdict
from planner.contacts import Hold, Stance
from planner.failure_report import SampleFailure, explain_no_plan
from planner.holds import (
    FOOT_COP_MARGIN_M,
    FOOT_FRICTION_SHARE,
    GRIP_STYLES,
    HELD_WRIST_MARGIN_RAD,
    WRIST_PITCH_JOINT,
    make_hold,
    wrist_bound_hands,
)
from planner.paths.interpolation import (
    InterpolationError,
    InterpolationStats,
    contact_space_interpolate,
)
from planner.paths.limb_path import foot_waypoints, hand_waypoints
from planner.paths.limb_rrt import plan_limb_path
from planner.reachability import check_reach
from planner.statics.arm_capacity import DEFAULT_ARM_STRATEGY, DEFAULT_POSITION_TORQUE_SHARE
from planner.time_limit import TimeLimitExceeded
from primitives.hold_seeds import FloorSeed, RailSeed
from primitives.library import climb_sequence
from primitives.primitive import Step
from robot.errors import HuboLadderError, InputError
from robot.joints import ARM_JOINTS, FINGER_JOINTS, LEG_JOINTS
from robot.kinematic_tree import FINGER_CLOSED_RAD
from robot.vocabulary import (
    InterpolationFailure,
    Limb,
    RejectCause,
    SegmentPhase,
    StepFailure,
)

log = logging.getLogger(__name__)

#: Largest joint correction [rad] when a placed limb is snapped exactly onto its hold.
POLISH_MAX_RAD = 0.1
#: Clearance between an inboard forearm's elbow end and the chest for the facing grip [m].
FOREARM_CLEARANCE_M = 0.05
#: Weight of the seed pelvis position in IK (soft, against hard holds).
PELVIS_WEIGHT = 1.0
#: The planner keeps each wrist pitch this far short of the bend at which a closed hand's
#: fingers touch its forearm [rad].
WRIST_FOLD_MARGIN_RAD = 0.05
#: Step of the scan for that bend [rad].
WRIST_FOLD_SCAN_STEP_RAD = 0.01
#: Start posture [rad], per side (roll signs mirrored): knees a little bent (a straight
#: knee is an IK singularity), arms in a ready pose forward and out, elbows bent.
#: Standing start postures [rad] (left side; roll joints mirrored), in order of preference:
#: forearms forward, ready to reach; then arms hanging, for a steep ladder whose rungs
#: come within a forearm of the chest, or rails that pass beside the elbows. The first
#: that touches nothing is the start.
START_POSTURES = (
    {"HP": -0.2, "KN": 0.4, "AP": -0.2, "SP": -0.5, "SR": 0.3, "EB": -1.2},
    {"HP": -0.2, "KN": 0.4, "AP": -0.2, "SP": 0.0, "SR": 0.15, "EB": -0.3},
)


#: How much further from zero than the checker's band the IK bounds a held wrist's pitch
#: [rad] (`ClimbPlanner._wrist_bounds`).
WRIST_BOUND_SLACK_RAD = 0.05


@dataclass(frozen=True)
class PlannerConfig:
    """Tunables of the search (defaults from the thesis where it gives them)."""

    samples_per_step: int = 50
    resolution_rad: float = 0.01
    hold_radius_step_m: float = 0.01  # perturbation radius growth per failed sample
    hold_radius_max_m: float = 0.05
    feasible_attempts: int = 3
    max_backtracks: int = 30
    time_limit_s: float = 600.0
    min_margin_m: float = 0.0
    # Thighs and shins keep this far from the ladder [m]: what playback leaves between a
    # stance leg and the plan, a foot up to 1.5 cm forward on its rung and a loaded leg
    # sagging at its position loops' torque limit (docs/decisions/leg-clearance.md).
    leg_clearance_m: float = 0.025
    # A step whose first `leg_clearance_samples` samples all fail tries the rest at
    # `min_leg_clearance_m`, the sag alone: a ladder with short rung spacing (ship,
    # 0.254 m) has little room for the legs, and the margin then costs minutes of search.
    min_leg_clearance_m: float = 0.01
    leg_clearance_samples: int = 10
    # Upper arms and forearms keep this far from the ladder [m]. Planned at none, the
    # right upper arm passed 0.2–1.5 cm from the DRC's right stringer in the mount of 9
    # of 10 plans, and one simulated climb hit it at 113 N (docs/decisions/arm-clearance.md).
    arm_clearance_m: float = 0.02
    arm_strategy: str = DEFAULT_ARM_STRATEGY  # how gripping arms are driven (arm_capacity)
    # Largest planned joint torque / limit, compliant arm joints included (their limit is
    # their PWM clamp). The reserve the legs need is `position_torque_share`'s.
    max_torque_ratio: float = 1.0
    # Share of its torque limit a joint in position mode is planned to (arm_capacity's
    # DEFAULT_POSITION_TORQUE_SHARE says why 0.9).
    position_torque_share: float = DEFAULT_POSITION_TORQUE_SHARE
    # A step's first `reserve_samples` samples are planned with position-mode joints at
    # `reserve_torque_share` of their limits, the rest at `position_torque_share`: the
    # standing leg on the higher rung in a foot's swing is where playback overloads it
    # (docs/decisions/position-torque-share.md), and the mount plans only at the latter.
    # None: no reserve (the position share throughout).
    reserve_torque_share: float | None = None
    reserve_samples: int = 10
    # The feet's centre of pressure stays this far inside each sole's support [m]
    # (planner.holds.FOOT_COP_MARGIN_M says why 2 cm).
    foot_cop_margin_m: float = FOOT_COP_MARGIN_M
    # Share of the ladder's μ a foot is planned to (planner.holds.FOOT_FRICTION_SHARE).
    foot_friction_share: float = FOOT_FRICTION_SHARE
    # The OMPL fallback (planner.paths.limb_rrt): RRTConnect's budget in collision checks
    # (≈ 0.1 ms each; an arm through a steep ladder's rungs takes tens of thousands),
    # tried on at most this many samples of a step, as a failed search costs the whole
    # budget, and only in the last samples before the step gives up: a pose whose arc
    # collides sits near an obstacle, and later steps from there are harder
    # (docs/decisions/ompl-fallback.md).
    limb_rrt_max_checks: int = 30000
    limb_rrt_tries_per_step: int = 4
    limb_rrt_after_failures: int = 40
    # While a foot is in the air, a hand on its hold keeps its wrist pitch at least this
    # far from zero [rad], where the wrist's yaw and roll axes line up and the grip, not
    # the arm, takes any turn across the rail (planner.holds.HELD_WRIST_MARGIN_RAD). 0:
    # no bound, the default.
    held_wrist_margin_rad: float = HELD_WRIST_MARGIN_RAD

    def torque_share(self, failed_samples: int) -> float:
        """The share of their torque limits position-mode joints are planned to in a
        step's sample after ``failed_samples`` failed ones."""
        if self.reserve_torque_share is None or failed_samples >= self.reserve_samples:
            return self.position_torque_share
        return self.reserve_torque_share


class PlanningFailed(HuboLadderError):
    """No plan was found; names the primitive and rung where the search stopped.

    Attributes:
        step: the step where the search stopped.
        reason: why, with the last sample's solver figures (for logs and batch records).
        stop: why the search stopped, in a user's words (`explain_no_plan`).
        progress: how far the search got, with every step's failed samples.
    """

    def __init__(self, step: Step, reason: str, stop: str = "",
                 progress: SearchProgress | None = None):
        super().__init__(f"no feasible {step.primitive.name} at rung {step.rung}: {reason}")
        self.step = step
        self.reason = reason
        self.stop = stop or reason
        self.progress = progress


@dataclass
class PathSegment:
    """Dense configurations of one phase of one step."""

    step: Step
    phase: str  # body | release | limb | grasp
    holds: tuple[Hold, ...]  # holds in contact during the phase
    moving_limbs: tuple[str, ...]
    configs: list[np.ndarray] = field(repr=False)


@dataclass
class StepStats:
    label: str
    seconds: float = 0.0
    samples: int = 0
    backtracks: int = 0
    min_margin_m: float = np.inf
    max_torque_ratio: float = 0.0
    failures: dict[str, int] = field(default_factory=dict)
    limb_detours: int = 0  # limb paths found by RRTConnect where the arc collided
    limb_detour_tries: int = 0
    leg_clearance_m: float = np.nan  # the legs' clearance the step was found with [m]
    position_torque_share: float = np.nan  # the share the step was found with
    # Every failed sample, over all visits of the step: what a no-plan message explains.
    rejected: list[SampleFailure] = field(default_factory=list, repr=False)


@dataclass
class SearchProgress:
    """How far a search has got, kept up to date while it runs, so that a search stopped
    from outside (the CLI's hard time limit) can still be explained.

    Attributes:
        steps: the climb's steps; stats: their statistics, index for index.
        current: index of the step being searched.
        deepest: index of the furthest step the search has reached.
        backtracks: backtracks so far.
    """

    steps: list[Step]
    stats: list[StepStats]
    current: int = 0
    deepest: int = 0
    backtracks: int = 0

    def explain(self, spec: LadderSpec, stop: str) -> str:
        """The user's ``no plan:`` message (`explain_no_plan`) for a search stopped, for
        the reason ``stop`` in words, at `current`."""
        return explain_no_plan(self.steps[self.deepest], self.stats[self.deepest].rejected,
                               spec, stop, stopped_at=self.steps[self.current])


@dataclass
class SearchResult:
    segments: list[PathSegment]
    final_stance: Stance
    step_stats: list[StepStats]
    total_s: float


def preferred_grip_style(geom: LadderGeometry, params) -> str:
    """``facing`` when a forearm lying inboard of the rail, level with it, ends clear of
    the chest; ``shoulder`` otherwise (narrow rails, e.g. the ship ladder)."""
    from robot.kinematic_tree import ROOT_LINK, build_tree

    torso_half_width = max(g.half[1] for lk in build_tree(params).links
                           if lk.name in ("torso", ROOT_LINK) for g in lk.geoms if g.kind == "box")
    elbow_y = geom.spec.rail_spacing_m / 2 - params.wrist_to_palm_m - params.forearm_m
    return "facing" if elbow_y >= torso_half_width + FOREARM_CLEARANCE_M else "shoulder"


def closed_hand_wrist_pitch_range_rad(kin: HuboKinematics, collision: CollisionModel,
                                      side: str) -> tuple[float, float]:
    """The wrist pitch range [rad] over which the closed fingers of hand ``side`` (``L`` or
    ``R``) clear its forearm at every wrist roll, within the joint's limits.

    Closed fingers curl back towards the wrist; bent further, the forearm folds onto them.
    Holding a rail, the hand's roll about it is free, and the IK, bounded by this range,
    rolls it to keep the wrist clear instead of bending it onto the fingers.
    """
    pitch, roll = kin.q_index[f"{side}WP"], kin.q_index.get(f"{side}WR")
    q = pin.neutral(kin.model)
    for f in FINGER_JOINTS["left" if side == "L" else "right"]:
        if f in kin.q_index:
            q[kin.q_index[f]] = FINGER_CLOSED_RAD
    rolls_rad = [0.0] if roll is None else np.linspace(
        kin.model.lowerPositionLimit[roll], kin.model.upperPositionLimit[roll], 9)
    geom, gdata, link_of = collision.geom, collision.gdata, collision.robot_link_of
    pairs = [k for k, (a, b) in enumerate(collision.self_pairs)  # self pairs come first
             if f"{side}_forearm" in (link_of[a], link_of[b])
             and f"{side}_finger" in link_of[a] + link_of[b]]

    def folded(q_pitch_rad: float) -> bool:
        q[pitch] = q_pitch_rad
        for q_roll_rad in rolls_rad:
            if roll is not None:
                q[roll] = q_roll_rad
            pin.updateGeometryPlacements(kin.model, kin.data, geom, gdata, q)
            if any(pin.computeCollision(geom, gdata, k) for k in pairs):
                return True
        return False

    out = []
    for limit_rad in (kin.model.lowerPositionLimit[pitch], kin.model.upperPositionLimit[pitch]):
        step_rad = np.copysign(WRIST_FOLD_SCAN_STEP_RAD, limit_rad)
        bound_rad = limit_rad
        for angle_rad in np.arange(step_rad, limit_rad, step_rad):
            if folded(angle_rad):
                bound_rad = angle_rad - np.copysign(WRIST_FOLD_MARGIN_RAD, limit_rad)
                break
        out.append(float(bound_rad))
    return out[0], out[1]


class ClimbPlanner:
    """Plans a climb of one ladder for one robot.

    Raises:
        LadderOutOfReach: on construction, when the reach pre-check rules the ladder out
            for this robot (`planner.reachability`).
    """

    def __init__(self, spec: LadderSpec, robot: str = "drc-hubo",
                 config: PlannerConfig = PlannerConfig(), seed: int = 1):
        from ladders.collision import ladder_collision_objects

        check_reach(spec, robot)  # before the models load: out of reach is refused at once
        self.spec = spec
        self.geom = LadderGeometry(spec)
        self.kin = HuboKinematics.load(robot)
        self.collision = CollisionModel(self.kin, ladder_collision_objects(spec),
                                        config.leg_clearance_m, config.arm_clearance_m)
        for side in "LR":  # the IK and the checker both keep the wrists inside this range
            self.kin.wrapper.set_joint_limits(
                f"{side}WP", *closed_hand_wrist_pitch_range_rad(self.kin, self.collision, side))
        self.checker = FeasibilityChecker(self.kin, self.collision, config.min_margin_m,
                                          config.arm_strategy, config.max_torque_ratio,
                                          config.position_torque_share,
                                          config.held_wrist_margin_rad)
        self.config = config
        self.seed = seed
        self.rng = np.random.default_rng(seed)
        self.torso_R = self.geom.R_world_ladder.copy()
        self.away = -self.geom.R_world_ladder[:, 0]
        self.preferred_grip = preferred_grip_style(self.geom, self.kin.params)
        self.ik_config = IKConfig()
        # Rungs repeat: a configuration found for a primitive's stage on one rung, moved
        # by the rung-to-rung offset, is the first guess for the same stage on the next.
        self._rung_step_m = self.geom.rung_top_point(1) - self.geom.rung_top_point(0) \
            if spec.num_rungs > 1 else np.zeros(3)
        self._found: dict[tuple[str, int], tuple[int, np.ndarray]] = {}
        self._standing_pelvis_z_m = self.kin.params.pelvis_height_m  # set when standing
        self.progress: SearchProgress | None = None  # the running or last search's
        self.ik_waypoint_config = IKConfig(
            moving_tol_m=self.ik_config.waypoint_tol_m,
            moving_angle_tol_rad=self.ik_config.waypoint_angle_tol_rad)

    def no_plan_message(self, exc: PlanningFailed | TimeLimitExceeded,
                        time_limit_s: float) -> str:
        """The user's ``no plan:`` message for a search that stopped with ``exc``
        (`planner.failure_report`): the deepest step reached and its reasons in user
        terms; the search's own text, with the solver's figures, is only logged."""
        log.info("search stopped: %s", exc)
        if isinstance(exc, PlanningFailed):
            if exc.progress is None:
                return f"no plan: {exc.step.primitive.name} at rung {exc.step.rung}: {exc.stop}"
            return exc.progress.explain(self.spec, exc.stop)
        stop = f"time limit of {time_limit_s:g} s reached"
        if self.progress is None:
            return f"no plan: {stop} before the search began"
        return self.progress.explain(self.spec, stop)

    # ----------------------------------------------------------------------------------
    def start_configuration(self) -> tuple[np.ndarray, Stance]:
        """Standing on the floor at the world origin, limbs slightly bent, hands open, in
        the first of `START_POSTURES` clear of the ladder.

        Raises:
            InputError: every start posture touches the ladder (the spec's placement puts
                the ladder where the robot stands).
        """
        hits = []
        for posture in START_POSTURES:
            q, stance = self._standing(posture)
            verdict = self.checker.check(q, stance, self._contacts(stance.holds))
            if verdict.ok or verdict.cause is not RejectCause.COLLISION:
                self._standing_pelvis_z_m = float(q[2])
                return q, stance
            hits.append("–".join(verdict.colliding[0]) if verdict.colliding else "collision")
        raise InputError(
            f"ladder '{self.spec.name}': placement_x_m = {self.spec.placement_x_m:g} m "
            f"leaves the robot no room to stand in front of it (every start posture touches "
            f"the ladder: {', '.join(hits)}); place the ladder farther away")

    def _standing(self, posture: dict[str, float]) -> tuple[np.ndarray, Stance]:
        """The robot standing at the world origin in ``posture`` (left side; roll joints
        mirrored), its feet flat on the floor where they fall."""
        kin = self.kin
        q = pin.neutral(kin.model)
        q[2] = kin.params.pelvis_height_m
        for side, sign in (("L", 1.0), ("R", -1.0)):
            for joint, v in posture.items():
                if side + joint in kin.q_index:
                    q[kin.q_index[side + joint]] = sign * v if joint == "SR" else v
        floor = {}
        for limb, frame in (("left_foot", "L_sole"), ("right_foot", "R_sole")):
            T = np.eye(4)
            T[:3, 3] = kin.frame_pose(q, frame)[:3, 3] * [1, 1, 0]
            floor[limb] = T
        holds = tuple(self._make_hold(FloorSeed(limb), floor_pose=floor) for limb in floor)
        return self._project(q, holds), Stance(holds)

    def _project(self, q: np.ndarray, holds: tuple[Hold, ...]) -> np.ndarray:
        r = solve_ik(self.kin, q, holds, torso_R=self.torso_R)
        if not r.converged:
            raise HuboLadderError(f"cannot stand at the start pose: {r!r}")
        return r.q

    def top_rung(self) -> int:
        """Highest rung whose next rail point (where the hands hold while the feet step up)
        still lies on the rails, a hand's width from their end."""
        p0, p1 = self.geom.rail_axis("left")
        rail_len = float(np.linalg.norm(p1 - p0))
        best = 0
        for k in range(self.spec.num_rungs):
            s = self.spec.rung_height_m(k) / np.sin(self.spec.slope_rad)
            if s + 0.05 <= rail_len:
                best = k
        return best

    # ----------------------------------------------------------------------------------
    def _contacts(self, holds) -> dict[str, str]:
        return {h.limb: h.target for h in holds}

    def _finger_path(self, q: np.ndarray, side: str, value: float) -> list[np.ndarray]:
        """Open or close a hand in steps no larger than the resolution."""
        idx = [self.kin.q_index[n] for n in FINGER_JOINTS[side] if n in self.kin.q_index]
        start = q[idx].copy()
        n = max(1, int(np.ceil(np.max(np.abs(value - start)) / self.config.resolution_rad)))
        out = []
        for i in range(1, n + 1):
            qi = q.copy()
            qi[idx] = start + (value - start) * i / n
            out.append(qi)
        return out

    def _sample_hold(self, seed, radius_m: float, q: np.ndarray, attempt: int) -> Hold:
        """A hold near the seed: offsets within ``radius_m``; rail holds alternate the grip
        style between attempts (ladder-facing first)."""
        if radius_m > 0:
            along = self.rng.uniform(-radius_m, radius_m)
            lateral = 0.0 if isinstance(seed, RailSeed) else self.rng.uniform(-radius_m,
                                                                              radius_m) / 2
        else:
            along = lateral = 0.0
        shoulder = None
        if isinstance(seed, RailSeed):
            frame = ("L" if seed.limb == "left_hand" else "R") + "_shoulder_pitch"
            shoulder = self.kin.frame_pose(q, frame)[:3, 3]
        first = GRIP_STYLES.index(self.preferred_grip)
        style = GRIP_STYLES[(first + attempt) % len(GRIP_STYLES)]
        return self._make_hold(seed, offset_m=(along, lateral), shoulder_m=shoulder,
                               grip_style=style)

    def _make_hold(self, seed, **kwargs) -> Hold:
        """`make_hold` with this planner's ladder, robot and foot model (the centre of
        pressure margin and the friction share)."""
        return make_hold(seed, self.geom, self.kin.params, **kwargs,
                         cop_margin_m=self.config.foot_cop_margin_m,
                         friction_share=self.config.foot_friction_share)

    def _pelvis_target(self, step: Step, support) -> np.ndarray:
        """Seed pelvis position: the primitive's offset from the supporting feet."""
        feet = [h.T_world_frame[:3, 3] for h in support if not h.is_hand]
        offset = self.geom.R_world_ladder @ np.array(step.primitive.pelvis_offset_m)
        target = np.mean(feet, axis=0) + offset
        if step.primitive.pelvis_below_standing_m is not None:
            target[2] = self._standing_pelvis_z_m - step.primitive.pelvis_below_standing_m
        return target

    def _posture(self, step: Step, q: np.ndarray, support,
                 wrist_bounds: dict[str, tuple[float, float]]) -> dict[str, float]:
        """Seed posture: the primitive's, except that an arm holding a rail prefers where
        it is. A 7-joint arm on a fixed hand can fold two ways; jumping between them has
        no continuous path on the hold. A wrist the IK bounds away from its singularity
        (``wrist_bounds``, `_wrist_bounds`) prefers its pitch at twice the margin, on the
        side it is on, when it is nearer zero: the primitive's straight wrist is where
        the band is."""
        posture = dict(step.primitive.posture_rad)
        for h in support:
            if h.is_hand:
                for name in ARM_JOINTS[Limb(h.limb).side]:
                    if name in self.kin.q_index:
                        posture[name] = float(q[self.kin.q_index[name]])
        preferred_rad = 2 * self.config.held_wrist_margin_rad
        for joint in wrist_bounds:
            pitch_rad = float(q[self.kin.q_index[joint]])
            if abs(pitch_rad) < preferred_rad:
                posture[joint] = math.copysign(preferred_rad, pitch_rad)
        return posture

    def _wrist_bounds(self, q: np.ndarray, stability: Stance) -> dict[str, tuple[float, float]]:
        """The IK's bound on the wrists the checker keeps out of their singularity
        (`planner.holds.wrist_bound_hands`): each on the side of zero it is on, at least
        the margin from it, so that no sample flips a wrist through zero."""
        margin_rad = self.config.held_wrist_margin_rad
        if margin_rad <= 0:
            return {}
        # the IK's bound stands WRIST_BOUND_SLACK_RAD further out than the checker's, so
        # that the interpolated poses between two solutions stay out of its band
        bound_rad = margin_rad + WRIST_BOUND_SLACK_RAD
        bounds = {}
        for limb in wrist_bound_hands(h.limb for h in stability.holds):
            joint = WRIST_PITCH_JOINT[limb]
            bounds[joint] = ((bound_rad, np.inf) if q[self.kin.q_index[joint]] >= 0
                             else (-np.inf, -bound_rad))
        return bounds

    def _target(self, step: Step, support, moving, stability: Stance, contacts,
                pelvis=None, weight=PELVIS_WEIGHT, q=None) -> SearchTarget:
        if q is None:
            posture, bounds = step.primitive.posture_rad, None
        else:
            bounds = self._wrist_bounds(q, stability)
            posture = self._posture(step, q, support, bounds)
        return SearchTarget(support=tuple(support), moving=tuple(moving),
                            stability_stance=stability, contacts=contacts,
                            posture_rad=posture, pelvis_target_m=pelvis,
                            pelvis_weight=weight, torso_R=self.torso_R,
                            retreat_direction=self.away, joint_bounds_rad=bounds)

    def _hint(self, step: Step, stage: int, attempt: int) -> np.ndarray | None:
        """The configuration found for ``step``'s primitive at ``stage`` on an earlier rung,
        moved to this rung; only for a step's first sample (later ones explore)."""
        found = self._found.get((step.primitive.name, stage))
        if attempt > 0 or found is None or found[0] == step.rung:
            return None
        q = found[1].copy()
        q[:3] += (step.rung - found[0]) * self._rung_step_m
        return q

    def _remember(self, step: Step, stage: int, q: np.ndarray) -> None:
        self._found[(step.primitive.name, stage)] = (step.rung, q.copy())

    def _interp(self, qa, qb, support, stability, contacts, stats: StepStats, moving=()):
        istats = InterpolationStats()
        path = contact_space_interpolate(self.kin, self.checker, qa, qb, tuple(support),
                                         stability, contacts, moving=moving,
                                         resolution_rad=self.config.resolution_rad,
                                         stats=istats)
        stats.min_margin_m = min(stats.min_margin_m, istats.min_margin_m)
        stats.max_torque_ratio = max(stats.max_torque_ratio, istats.max_torque_ratio)
        return path

    def _limb_detour(self, qa, qb, limbs, support, stability, contacts, stats: StepStats,
                     exc: InterpolationError, attempt: int) -> list[np.ndarray]:
        """The OMPL fallback (`planner.paths.limb_rrt`) where the arc between two way-point
        configurations collides, in a step's last samples (`PlannerConfig`): the body
        moves to ``qb``'s with the moving limbs' joints held (contact-space
        interpolation), then RRTConnect moves one limb at a time with everything else held
        (a 7- or 6-joint space each, not all moving limbs at once). Re-raises ``exc`` when
        the fallback is not due or finds nothing."""
        cfg = self.config
        if (attempt < cfg.limb_rrt_after_failures
                or stats.limb_detour_tries >= cfg.limb_rrt_tries_per_step
                or exc.cause is not InterpolationFailure.MIDPOINT_INFEASIBLE
                or exc.verdict_cause is not RejectCause.COLLISION):
            raise exc
        stats.limb_detour_tries += 1
        joints = [(names, [self.kin.q_index[n] for n in names])
                  for names in map(self._limb_joints, limbs)]
        q_cur = qb.copy()
        for _, idx in joints:
            q_cur[idx] = qa[idx]
        if not self.checker.check(q_cur, stability, contacts).ok:
            raise exc
        path = (self._interp(qa, q_cur, support, stability, contacts, stats)
                if self.kin.joint_distance(qa, q_cur) > 0 else [])
        for names, idx in joints:
            q_next = q_cur.copy()
            q_next[idx] = qb[idx]
            if self.kin.joint_distance(q_cur, q_next) == 0:
                continue
            part = plan_limb_path(self.kin, self.checker, q_cur, q_next, names, stability,
                                  contacts, resolution_rad=cfg.resolution_rad,
                                  max_checks=cfg.limb_rrt_max_checks)
            if part is None:
                raise exc
            path += part
            q_cur = q_next
        stats.limb_detours += 1
        return path

    def _limb_joints(self, limb: str) -> list[str]:
        table = ARM_JOINTS if Limb(limb).is_hand else LEG_JOINTS
        return [n for n in table[Limb(limb).side] if n in self.kin.q_index]

    # ----------------------------------------------------------------------------------
    def try_step(self, step: Step, q: np.ndarray, stance: Stance, radius_m: float,
                 stats: StepStats, attempt: int = 0
                 ) -> tuple[list[PathSegment], np.ndarray, Stance]:
        """One sample of a step; raises `InterpolationError`/`_StepRejected` on failure.

        A step lifts off (every hold kept, the body made stable without the moving limbs),
        opens the hands that let go, carries the moving limbs through their way-points,
        places them exactly on their new holds and closes the hands that arrived on a
        rail. A step without moving limbs (straighten) only moves the body."""
        moving_limbs = step.primitive.moving_limbs
        support = tuple(h for h in stance.holds if h.limb not in moving_limbs)
        new_holds = tuple(self._sample_hold(seed, radius_m, q, attempt)
                          for seed in step.new_holds)
        next_stance = Stance(support + new_holds)
        fstats = FeasibleSearchStats()
        if not moving_limbs:
            return self._straighten(step, q, stance, stats, fstats)
        segments, q_cur, pelvis = self._lift_off(step, q, stance, support, stats, fstats,
                                                 attempt)
        opening, q_cur = self._open_hands(step, q_cur, stance, support)
        segments += opening
        limb_path, q_cur = self._carry(step, q_cur, stance, support, new_holds, pelvis, stats,
                                       fstats, attempt)
        segments.append(PathSegment(step, SegmentPhase.LIMB, support, moving_limbs, limb_path))
        q_cur = self._place(q_cur, next_stance, limb_path)
        closing, q_cur = self._close_hands(step, q_cur, support, new_holds)
        segments += closing
        stats.samples += fstats.attempts
        for k, v in (fstats.rejections or {}).items():
            stats.failures[k] = stats.failures.get(k, 0) + v
        return segments, q_cur, next_stance

    def _straighten(self, step: Step, q: np.ndarray, stance: Stance, stats: StepStats,
                    fstats: FeasibleSearchStats
                    ) -> tuple[list[PathSegment], np.ndarray, Stance]:
        """Every hold kept, the body rises to a feasible pose."""
        pelvis = self._pelvis_target(step, stance.holds)
        target = self._target(step, stance.holds, (), stance, self._contacts(stance.holds),
                              pelvis, q=q)
        q_new, verdict = find_feasible(self.kin, self.checker, q, target, self.rng,
                                       attempts=self.config.feasible_attempts, stats=fstats)
        if q_new is None:
            raise _StepRejected(StepFailure.NO_STRAIGHT_POSE,
                               f"no straightened pose: {_why(verdict)}", "straighten", verdict)
        path = self._interp(q, q_new, stance.holds, stance, self._contacts(stance.holds),
                            stats)
        return [PathSegment(step, SegmentPhase.BODY, stance.holds, (), path)], q_new, stance

    def _lift_off(self, step: Step, q: np.ndarray, stance: Stance, support: tuple[Hold, ...],
                  stats: StepStats, fstats: FeasibleSearchStats, attempt: int
                  ) -> tuple[list[PathSegment], np.ndarray, np.ndarray | None]:
        """The lift-off configuration: every current hold kept, stable without the moving
        limbs (``q`` itself when it already is). Returns the body's path there, the
        configuration and the step's pelvis target."""
        support_stance = Stance(support)
        contacts_all = self._contacts(stance.holds)
        pelvis = self._pelvis_target(step, support)
        lift_target = self._target(step, stance.holds, (), support_stance, contacts_all, pelvis,
                                   q=q)
        verdict = self.checker.check(q, support_stance, contacts_all)
        if verdict.ok:
            return [], q, pelvis
        q_lift, verdict = find_feasible(self.kin, self.checker, q, lift_target, self.rng,
                                        attempts=self.config.feasible_attempts,
                                        stats=fstats, q_hint=self._hint(step, 0, attempt))
        if q_lift is None:
            raise _StepRejected(StepFailure.NO_LIFT_OFF, f"no lift-off pose: {_why(verdict)}",
                                "lift-off", verdict)
        self._remember(step, 0, q_lift)
        path = self._interp(q, q_lift, stance.holds, stance, contacts_all, stats)
        return [PathSegment(step, SegmentPhase.BODY, stance.holds, (), path)], q_lift, pelvis

    def _open_hands(self, step: Step, q: np.ndarray, stance: Stance,
                    support: tuple[Hold, ...]) -> tuple[list[PathSegment], np.ndarray]:
        """The fingers of the moving hands that held a rail open, one hand after the other."""
        segments = []
        moving_limbs = step.primitive.moving_limbs
        for limb in moving_limbs:
            if Limb(limb).is_hand and stance.hold(limb) is not None:
                path = self._finger_path(q, Limb(limb).side, 0.0)
                segments.append(PathSegment(step, SegmentPhase.RELEASE, support, moving_limbs,
                                            path))
                q = path[-1]
        return segments, q

    def _carry(self, step: Step, q: np.ndarray, stance: Stance, support: tuple[Hold, ...],
               new_holds: tuple[Hold, ...], pelvis: np.ndarray | None, stats: StepStats,
               fstats: FeasibleSearchStats, attempt: int
               ) -> tuple[list[np.ndarray], np.ndarray]:
        """The moving limbs carried together through their way-points to their new holds
        (a feasible configuration per way-point, contact-space interpolation between them,
        the OMPL detour where that collides). Returns the path and where it ends."""
        prim = step.primitive
        support_stance = Stance(support)
        way = {}
        for hold in new_holds:
            T_from = self.kin.frame_pose(q, hold.frame)
            old = stance.hold(hold.limb)
            if hold.is_hand:
                way[hold.limb] = hand_waypoints(T_from, hold, self.geom, prim.waypoints,
                                                on_rail=old is not None)
            else:
                way[hold.limb] = foot_waypoints(T_from, hold, self.geom, self.kin.params,
                                                prim.waypoints, step.rung)
        n_way = max(len(w) for w in way.values())
        for w in way.values():  # equal counts: repeat the final pose
            w.extend([w[-1]] * (n_way - len(w)))
        contacts_support = self._contacts(support)
        limb_path: list[np.ndarray] = []
        q_cur = q
        for i in range(1, n_way):
            targets = tuple(Hold(h.limb, h.target, way[h.limb][i], h.points_m, h.normals,
                                 h.friction) for h in new_holds)
            contacts = dict(contacts_support)
            if i == 1:  # leaving: may still touch the old hold's object
                contacts.update({lb: stance.hold(lb).target for lb in prim.moving_limbs
                                 if stance.hold(lb) is not None})
            if i == n_way - 1:  # arriving
                contacts.update({h.limb: h.target for h in new_holds})
            target = self._target(step, support, targets, support_stance, contacts, pelvis,
                                  q=q_cur)
            final = i == n_way - 1
            q_next, verdict = find_feasible(
                self.kin, self.checker, q_cur, target, self.rng,
                attempts=self.config.feasible_attempts, stats=fstats,
                ik_config=self.ik_config if final else self.ik_waypoint_config,
                q_hint=self._hint(step, i, attempt))
            if q_next is None:
                raise _StepRejected(StepFailure.WAYPOINT,
                                    f"way-point {i}/{n_way - 1}: {_why(verdict)}",
                                    f"way-point {i}/{n_way - 1}", verdict)
            self._remember(step, i, q_next)
            try:
                limb_path += self._interp(q_cur, q_next, support, support_stance, contacts,
                                          stats, moving=targets)
            except InterpolationError as exc:
                limb_path += self._limb_detour(q_cur, q_next, prim.moving_limbs, support,
                                               support_stance, contacts, stats, exc, attempt)
            q_cur = q_next
        return limb_path, q_cur

    def _place(self, q: np.ndarray, next_stance: Stance, limb_path: list[np.ndarray]
               ) -> np.ndarray:
        """Polish: the new holds become hard tasks, met to solver precision, and the placed
        configuration must be feasible in the new stance too. The short move there is
        appended to ``limb_path``; returns the placed configuration.

        The posture task pins the other joints where they are: near a singular or
        limit-bound pose a millimetre of hold error can otherwise swing them far."""
        polished = solve_ik(self.kin, q, next_stance.holds, config=self.ik_config,
                            posture_rad=self.kin.posture(q), preferences=False)
        if not polished.converged:
            raise _StepRejected(StepFailure.HOLDS_NOT_MET,
                                f"placed pose does not meet its holds: {polished!r}", "placing",
                                Verdict.ik_failure(polished))
        correction = self.kin.joint_distance(polished.q, q)
        if correction > POLISH_MAX_RAD:
            raise _StepRejected(StepFailure.POLISH_TOO_FAR,
                                f"placing the holds exactly moves a joint {correction:.3f} rad",
                                "placing", joint_move_rad=correction)
        n = int(np.ceil(correction / self.config.resolution_rad))
        limb_path += [self.kin.interpolate(q, polished.q, (k + 1) / n) for k in range(n)]
        verdict = self.checker.check(polished.q, next_stance,
                                     self._contacts(next_stance.holds))
        if not verdict.ok:
            raise _StepRejected(StepFailure.UNSTABLE_PLACED,
                                f"placed pose unstable in the new stance: {verdict.reason}",
                                "placing", verdict)
        return polished.q

    def _close_hands(self, step: Step, q: np.ndarray, support: tuple[Hold, ...],
                     new_holds: tuple[Hold, ...]) -> tuple[list[PathSegment], np.ndarray]:
        """The fingers of the hands that arrived on a rail close, one hand after the other.
        A closing hand is not a hold yet: it joins the holds in contact once its fingers
        are closed."""
        segments = []
        in_contact = list(support) + [h for h in new_holds if not h.is_hand]
        for hold in new_holds:
            if hold.is_hand:
                path = self._finger_path(q, Limb(hold.limb).side, FINGER_CLOSED_RAD)
                segments.append(PathSegment(step, SegmentPhase.GRASP, tuple(in_contact),
                                            (hold.limb,), path))
                in_contact.append(hold)
                q = path[-1]
        return segments, q

    # ----------------------------------------------------------------------------------
    def plan(self, top_rung: int | None = None,
             progress: Callable[[int, int, Step, StepStats], None] | None = None
             ) -> SearchResult:
        """Search the whole climb; raises `PlanningFailed` when the time or samples run out."""
        t_start = time.perf_counter()
        top = self.top_rung() if top_rung is None else top_rung
        if not 0 <= top < self.spec.num_rungs:
            raise HuboLadderError(f"top rung {top} is not on the ladder "
                                  f"(0..{self.spec.num_rungs - 1})")
        steps = climb_sequence(top)
        q0, stance0 = self.start_configuration()
        # Stack of (segments, q, stance) after each completed step.
        states: list[tuple[list[PathSegment], np.ndarray, Stance]] = [([], q0, stance0)]
        failures = [0] * len(steps)
        stats = [StepStats(s.label) for s in steps]
        self.progress = reached = SearchProgress(steps, stats)
        i = 0
        while i < len(steps):
            step = steps[i]
            reached.current, reached.deepest = i, max(reached.deepest, i)
            _, q, stance = states[-1]
            t0 = time.perf_counter()
            radius = min(self.config.hold_radius_max_m,
                         failures[i] * self.config.hold_radius_step_m)
            if time.perf_counter() - t_start > self.config.time_limit_s:
                why = f"time limit of {self.config.time_limit_s:g} s reached"
                raise PlanningFailed(step, why, why, reached)
            relaxed = failures[i] >= self.config.leg_clearance_samples
            self.collision.set_leg_clearance(self.config.min_leg_clearance_m if relaxed
                                             else self.config.leg_clearance_m)
            self.checker.set_position_torque_share(self.config.torque_share(failures[i]))
            try:
                segs, q_new, stance_new = self.try_step(step, q, stance, radius, stats[i],
                                                        failures[i])
            except (_StepRejected, InterpolationError) as exc:
                failures[i] += 1
                stats[i].seconds += time.perf_counter() - t0
                key = exc.cause.value
                stats[i].failures[key] = stats[i].failures.get(key, 0) + 1
                stats[i].rejected.append(_sample_failure(exc))
                log.debug("%s sample %d failed: %s", step.label, failures[i], exc)
                if failures[i] >= self.config.samples_per_step:
                    if i == 0 or reached.backtracks >= self.config.max_backtracks:
                        stop = ("every sample failed" if i == 0 else
                                f"{reached.backtracks} backtracks, the most allowed")
                        raise PlanningFailed(
                            step, f"{failures[i]} samples failed; last: {exc}", stop,
                            reached) from None
                    # A dead end counts as a failure of the step before, and a step that is
                    # backtracked into gets half its budget next time, so repeated dead
                    # ends reach further back instead of cycling between two steps.
                    reached.backtracks += 1
                    stats[i - 1].backtracks += 1
                    failures[i] = self.config.samples_per_step // 2
                    failures[i - 1] += self.config.samples_per_step // 5
                    states.pop()
                    i -= 1
                continue
            stats[i].seconds += time.perf_counter() - t0
            stats[i].leg_clearance_m = self.collision.leg_clearance_m
            stats[i].position_torque_share = self.checker.position_torque_share
            states.append((segs, q_new, stance_new))
            if progress is not None:
                progress(i, len(steps), step, stats[i])
            i += 1
        segments = [seg for segs, _, _ in states for seg in segs]
        return SearchResult(segments, states[-1][2], stats, time.perf_counter() - t_start)


def _why(verdict) -> str:
    return verdict.reason if verdict is not None else "no candidate converged"


class _StepRejected(HuboLadderError):
    """One sample of a step failed (the search tries another).

    Attributes:
        cause: what failed; its value is the key of the step's ``failures`` count.
        failure: the same in figures, for a no-plan message (`SampleFailure`).
    """

    def __init__(self, cause: StepFailure, message: str, stage: str,
                 verdict: Verdict | None = None, joint_move_rad: float = np.nan):
        super().__init__(message)
        self.cause = cause
        self.failure = SampleFailure(cause.value, stage, verdict, joint_move_rad, message)


def _sample_failure(exc: _StepRejected | InterpolationError) -> SampleFailure:
    """What a failed sample's exception says, in figures (`SampleFailure`)."""
    if isinstance(exc, _StepRejected):
        return exc.failure
    return SampleFailure(exc.cause.value, "path", exc.verdict, detail=str(exc))
