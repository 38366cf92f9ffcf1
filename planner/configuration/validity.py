"""Is a configuration feasible at a stance? Joint limits, collisions, static stability.

The one predicate every stage of the search and the interpolation uses (thesis §6.3.1):
every contact meets its hold, the joints are within limits, nothing collides with the
environment or the robot itself, and the pose is statically stable (CoM inside the
stance's support region and joint torques within limits). Arms whose hands hold a rail
get the torque their strategy gives them (`planner.statics.arm_capacity`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from planner.configuration.collision import CollisionModel
from planner.configuration.ik import HoldMiss, IKResult
from planner.configuration.kinematics import HuboKinematics
from planner.contacts import Stance
from planner.holds import WRIST_PITCH_JOINT, wrist_bound_hands
from planner.statics.arm_capacity import (
    DEFAULT_ARM_STRATEGY,
    balance_stance,
    gripping_sides,
    gripping_torque_limits,
)
from planner.statics.com_region import SupportRegion, support_region
from planner.statics.stability import check_stability
from planner.statics.torque_lp import TorqueCheck, torque_feasibility, torque_limits_by_joint
from robot.vocabulary import RejectCause

#: Tolerance on the joint limits [rad] (placo's QP meets them to solver precision).
LIMIT_TOL_RAD = 1e-6


@dataclass(frozen=True)
class Verdict:
    """Why a configuration is or is not feasible, with the figures the plan reports."""

    ok: bool
    reason: str
    com_margin_m: float
    torque_ratio: float
    clearance_m: float = float("nan")
    environment_only: bool = False  # the only problem is a collision with the ladder/floor
    cause: RejectCause | None = None  # why it is not feasible (None when it is)
    colliding: tuple[tuple[str, str], ...] = ()  # the colliding pairs, for a collision
    torque_joint: str = ""  # the joint of the worst torque ratio, for a torque rejection
    ik_misses: tuple[HoldMiss, ...] = ()  # the holds an IK failure left unmet

    def __bool__(self) -> bool:
        return self.ok

    @classmethod
    def ik_failure(cls, result: IKResult) -> Verdict:
        """The verdict on an IK solve that did not converge: the holds it left unmet."""
        return cls(False, f"ik {result!r}", np.nan, np.nan, cause=RejectCause.IK,
                   ik_misses=result.misses)


class FeasibilityChecker:
    """Caches the support region per stance and checks configurations against it."""

    def __init__(self, kin: HuboKinematics, collision: CollisionModel,
                 min_margin_m: float = 0.0, arm_strategy: str = DEFAULT_ARM_STRATEGY,
                 max_torque_ratio: float = 1.0, position_torque_share: float = 1.0,
                 held_wrist_margin_rad: float = 0.0):
        self.kin = kin
        self.held_wrist_margin_rad = held_wrist_margin_rad
        self.wrist_pitch_index = {limb: kin.q_index[joint]
                                  for limb, joint in WRIST_PITCH_JOINT.items()}
        self.collision = collision
        self.min_margin_m = min_margin_m
        self.max_torque_ratio = max_torque_ratio
        self.position_torque_share = position_torque_share
        self.arm_strategy = arm_strategy
        self.torque_max = torque_limits_by_joint(kin.params.name)
        self._torque_limits: dict[tuple[frozenset, float], dict[str, float]] = {}
        self._regions: dict[tuple, SupportRegion] = {}
        lower, upper = kin.model.lowerPositionLimit[7:], kin.model.upperPositionLimit[7:]
        self._lower, self._upper = lower.copy(), upper.copy()
        self.frame_ids = {limb: kin.model.getFrameId(frame) for limb, frame in
                          (("left_hand", "L_palm"), ("right_hand", "R_palm"),
                           ("left_foot", "L_sole"), ("right_foot", "R_sole"))}

    @staticmethod
    def stance_key(stance: Stance) -> tuple:
        return tuple(sorted((h.limb, h.target, tuple(np.round(h.T_world_frame[:3, 3], 6)))
                            for h in stance.holds))

    def region(self, stance: Stance) -> SupportRegion:
        """The CoM's support region on the holds that may balance it (`balance_stance`)."""
        key = self.stance_key(stance)
        if key not in self._regions:
            self._regions[key] = support_region(balance_stance(stance, self.arm_strategy),
                                                self.kin.params.total_mass_kg)
        return self._regions[key]

    def set_position_torque_share(self, share: float) -> None:
        """Plan position-mode joints to ``share`` of their torque limits from now on."""
        self.position_torque_share = share

    def torque_limits(self, stance: Stance) -> dict[str, float]:
        """Torque limit per joint [N·m] while ``stance`` carries the robot."""
        key = (gripping_sides(h.limb for h in stance.holds), self.position_torque_share)
        if key not in self._torque_limits:
            self._torque_limits[key] = gripping_torque_limits(
                self.torque_max, key[0], self.arm_strategy,
                position_share=self.position_torque_share)
        return self._torque_limits[key]

    def check(self, q: np.ndarray, stance: Stance, contacts: dict[str, str]) -> Verdict:
        """Feasibility of ``q`` when ``stance`` carries the robot.

        Args:
            q: configuration.
            stance: the holds that bear load (stability is tested against them).
            contacts: limb → environment object it may touch (its held object, and for a
                moving limb at the ends of its path the object it leaves or reaches).
        """
        if not self.within_limits(q):
            return Verdict(False, "joint limits", np.nan, np.nan,
                           cause=RejectCause.JOINT_LIMITS)
        if (limb := self.singular_held_wrist(q, stance)) is not None:
            return Verdict(False, f"{limb}'s wrist pitch within "
                                  f"{self.held_wrist_margin_rad:.2f} rad of its singularity",
                           np.nan, np.nan, cause=RejectCause.WRIST_SINGULARITY)
        self.collision.allow(contacts)
        if self.collision.in_collision(q):
            pairs = self.collision.colliding_pairs(q)
            env = set(self.collision.env_names)
            env_only = all(a.split("/")[0] in env or b.split("/")[0] in env for a, b in pairs)
            return Verdict(False, f"collision {pairs[0][0]}–{pairs[0][1]}" if pairs else
                           "collision", np.nan, np.nan, environment_only=env_only,
                           cause=RejectCause.COLLISION, colliding=tuple(map(tuple, pairs)))
        region = self.region(stance)
        if region.is_empty:
            return Verdict(False, "stance cannot balance gravity", -np.inf, np.inf,
                           cause=RejectCause.UNBALANCEABLE_STANCE)
        report = check_stability(self.kin.model, self.kin.data, q, stance, region,
                                 self.torque_limits(stance), min_margin_m=self.min_margin_m,
                                 frame_ids=self.frame_ids)
        ratio = report.torque.max_ratio if report.torque is not None else np.inf
        if not report.stable or ratio > self.max_torque_ratio:
            if report.torque is None:
                cause = RejectCause.COM_OUTSIDE
                why = f"CoM {report.margin_m * 100:.1f} cm outside the support region"
            else:
                cause = RejectCause.TORQUE
                why = f"torque {ratio:.2f}× limit at {report.torque.worst_joint}"
            return Verdict(False, why, report.margin_m, ratio, cause=cause,
                           torque_joint=report.torque.worst_joint if report.torque else "")
        return Verdict(True, "ok", report.margin_m, ratio)

    def singular_held_wrist(self, q: np.ndarray, stance: Stance) -> str | None:
        """The first hand in ``stance`` whose wrist pitch is within
        ``held_wrist_margin_rad`` of zero while the stance has fewer than two feet (a
        foot in the air: the grips carry the body with one leg), or None."""
        if self.held_wrist_margin_rad <= 0:  # no bound (the default): nothing to look at
            return None
        return next((limb for limb in wrist_bound_hands(h.limb for h in stance.holds)
                     if abs(float(q[self.wrist_pitch_index[limb]])) < self.held_wrist_margin_rad),
                    None)

    def within_limits(self, q: np.ndarray) -> bool:
        joints = q[7:]
        return not (np.any(joints < self._lower - LIMIT_TOL_RAD)
                    or np.any(joints > self._upper + LIMIT_TOL_RAD))

    def collision_free(self, q: np.ndarray, contacts: dict[str, str]) -> bool:
        """Within the joint limits and touching nothing but ``contacts`` (the first two
        parts of `check`, without the stability test)."""
        if not self.within_limits(q):
            return False
        self.collision.allow(contacts)
        return not self.collision.in_collision(q)

    def holding_torques(self, q: np.ndarray, stance: Stance) -> TorqueCheck:
        """The torque LP's joint torques that hold ``q`` on ``stance`` (limits as `check`)."""
        return torque_feasibility(self.kin.model, self.kin.data, q, stance,
                                  self.torque_limits(stance), self.frame_ids)

    def clearance(self, q: np.ndarray, contacts: dict[str, str]) -> float:
        """Smallest distance over the active collision pairs [m] (slower: for reports)."""
        self.collision.allow(contacts)
        return self.collision.report(q).min_distance_m
