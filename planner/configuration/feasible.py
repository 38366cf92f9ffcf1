"""Algorithm 6 of the thesis: find a configuration feasible at a stance.

Start IK from the seed plus a perturbation that grows with the attempt number; accept a
result that converged, collides with nothing and is statically stable; if the only
problem is a collision with the environment, try to retract the body away from the
ladder and project again. If the only problem is joint torque (the contacts can balance
gravity but some joint would exceed its limit), descend the worst torque ratio by a local
random search over the pelvis position and the posture: on a ladder the feasible set is
thin (a bent stance knee, 8.9 N·m wrists) and uniform sampling rarely lands in it.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from planner.configuration.ik import FIXED_JOINT_PREFIXES, IKConfig, solve_ik
from planner.configuration.kinematics import HuboKinematics
from planner.configuration.validity import FeasibilityChecker, Verdict
from planner.contacts import Hold, Stance
from robot.vocabulary import RejectCause

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class SearchTarget:
    """What a feasible configuration must satisfy.

    Attributes:
        support: holds kept during the search (hard IK tasks).
        moving: holds the moving limbs must reach (soft IK tasks, must converge).
        stability_stance: the holds that bear the load (stability test and CoM polygon).
        contacts: limb → object it may touch.
        posture_rad: seed posture.
        pelvis_target_m: preferred pelvis position [m] or None.
        pelvis_weight: weight of the pelvis preference.
        torso_R: preferred torso orientation.
        joint_bounds_rad: joint → (lower, upper) [rad] the IK keeps it within, inside its
            limits (a held wrist's pitch on its side of the singularity).
    """

    support: tuple[Hold, ...]
    moving: tuple[Hold, ...]
    stability_stance: Stance
    contacts: dict[str, str]
    posture_rad: dict[str, float]
    pelvis_target_m: np.ndarray | None
    pelvis_weight: float
    torso_R: np.ndarray
    retreat_direction: np.ndarray  # unit vector away from the ladder, for retraction
    joint_bounds_rad: dict[str, tuple[float, float]] | None = None  # narrower limits


@dataclass
class FeasibleSearchStats:
    attempts: int = 0
    ik_failures: int = 0
    rejections: dict[str, int] | None = None

    def reject(self, cause: RejectCause) -> None:
        self.rejections = self.rejections or {}
        self.rejections[cause.value] = self.rejections.get(cause.value, 0) + 1


#: Torque descent: evaluations per attempt; it gives up after ``PATIENCE`` candidates in
#: a row without improvement. Step sizes (standard deviations) of the pelvis target [m],
#: the posture preferences [rad] and the torso's turn (roll, lean towards the ladder,
#: yaw) [rad]: fixed, large enough to cross the shallow local minima that the ladder's
#: torque landscape is full of (shrinking steps stalled at 1.05–1.3× on the DRC mount
#: where these reach 0.8×). Roll and yaw matter when one foot is on a rung and the other
#: on the floor: turning the hips over the high foot unloads its hip roll and knee. With
#: the lean alone, descents of the DRC mount's lift-off (legs planned at 0.9 of their
#: limits) ended at 1.01–1.5× of the bound; with roll and yaw, at 0.88–1.4×.
TORQUE_DESCENT_EVALUATIONS = 600
TORQUE_DESCENT_PATIENCE = 150
TORQUE_DESCENT_PELVIS_STEP_M = 0.04
TORQUE_DESCENT_POSTURE_STEP_RAD = 0.1
TORQUE_DESCENT_TURN_STEP_RAD = (0.05, 0.05, 0.05)  # roll, lean, yaw
#: The descent stops once the worst torque ratio is this share of the checker's bound; a
#: pose just under the bound leaves the path to its neighbours no room.
TORQUE_DESCENT_TARGET_SHARE = 0.9


def _turn(roll_lean_yaw_rad: np.ndarray) -> np.ndarray:
    """Rotation ``Rz(yaw)·Ry(lean)·Rx(roll)``: applied to the ladder-facing torso
    orientation, a positive lean tilts the torso towards the ladder."""
    return pin.rpy.rpyToMatrix(*(float(a) for a in roll_lean_yaw_rad))


def _descend_torque(kin: HuboKinematics, checker: FeasibilityChecker, target: SearchTarget,
                    rng: np.random.Generator, q_start: np.ndarray, ratio: float, polygon,
                    ik_config: IKConfig, stats: FeasibleSearchStats
                    ) -> tuple[np.ndarray | None, Verdict | None]:
    """Local random search that lowers the worst joint-torque ratio below 1.

    It varies the pelvis target, the torso's turn (its lean towards the ladder, its roll
    and yaw) and the preference of every body joint around the best candidate so far.
    Stepping up onto a rung with compliant arms takes a forward lean (the upper body's
    weight ahead of the hips unloads the bent knee) and arms that carry their load along
    their length (a 1.4 N·m wrist pitch): coordinated changes no single joint's
    preference makes. Returns the first pose at or under `TORQUE_DESCENT_TARGET_SHARE`
    of the bound, else the best feasible one.
    """
    # Around where the pelvis and joints are, not their targets: a target the holds keep
    # out of reach (e.g. over a foot on the rung while the other is still on the floor)
    # stalls the walk.
    best_pelvis = q_start[:3].copy()
    best_posture = {name: float(q_start[i]) for name, i in kin.q_index.items()
                    if not name.startswith(FIXED_JOINT_PREFIXES)}
    best_ratio, best_q, best_turn, best_verdict = ratio, q_start, np.zeros(3), None
    last = None
    stale = 0
    for _ in range(TORQUE_DESCENT_EVALUATIONS):
        if stale >= TORQUE_DESCENT_PATIENCE:
            break
        cand_pelvis = best_pelvis + rng.normal(0.0, TORQUE_DESCENT_PELVIS_STEP_M, 3)
        cand_posture = {k: v + rng.normal(0.0, TORQUE_DESCENT_POSTURE_STEP_RAD)
                        for k, v in best_posture.items()}
        cand_turn = best_turn + rng.normal(0.0, TORQUE_DESCENT_TURN_STEP_RAD)
        result = solve_ik(kin, best_q, target.support, target.moving, posture_rad=cand_posture,
                          torso_R=target.torso_R @ _turn(cand_turn),
                          pelvis_target_m=cand_pelvis,
                          pelvis_weight=max(target.pelvis_weight, 1.0), com_polygon_cw=polygon,
                          preferences=False, joint_bounds_rad=target.joint_bounds_rad,
                          config=ik_config)
        stats.attempts += 1
        stale += 1
        if not result.converged:
            continue
        verdict = checker.check(result.q, target.stability_stance, target.contacts)
        last = verdict
        if not (np.isfinite(verdict.torque_ratio) and verdict.torque_ratio < best_ratio):
            continue
        best_ratio, best_pelvis, best_posture = verdict.torque_ratio, cand_pelvis, cand_posture
        best_q, best_turn, stale = result.q, cand_turn, 0
        if verdict.ok:
            best_verdict = verdict
            if best_ratio <= TORQUE_DESCENT_TARGET_SHARE * checker.max_torque_ratio:
                break
    if best_verdict is not None:
        return best_q, best_verdict
    return None, last


def find_feasible(kin: HuboKinematics, checker: FeasibilityChecker, q_seed: np.ndarray,
                  target: SearchTarget, rng: np.random.Generator, *, attempts: int = 10,
                  posture_perturb_rad: float = 0.3, pelvis_perturb_m: float = 0.08,
                  retract_step_m: float = 0.04, ik_config: IKConfig | None = None,
                  stats: FeasibleSearchStats | None = None,
                  q_hint: np.ndarray | None = None
                  ) -> tuple[np.ndarray | None, Verdict | None]:
    """A feasible configuration near ``q_seed`` for ``target``, or (None, last verdict).

    A ``q_hint`` (e.g. the same stage solved on the rung below, moved up) is projected
    onto the target first, its own posture preferred; if that is not feasible, the
    perturbation radius is 0 on the first attempt and grows linearly to the given maxima
    on the last one.
    """
    stats = stats or FeasibleSearchStats()
    ik_config = ik_config or IKConfig()
    region = checker.region(target.stability_stance)
    polygon = None if region.is_empty else region.clockwise_vertices()
    last: Verdict | None = None
    if q_hint is not None:
        stats.attempts += 1
        result = solve_ik(kin, q_hint, target.support, target.moving,
                          posture_rad=kin.posture(q_hint), pelvis_target_m=q_hint[:3].copy(),
                          pelvis_weight=1.0, com_polygon_cw=polygon, preferences=False,
                          joint_bounds_rad=target.joint_bounds_rad, config=ik_config)
        if result.converged:
            verdict = checker.check(result.q, target.stability_stance, target.contacts)
            if verdict.ok:
                return result.q, verdict
    for i in range(attempts):
        stats.attempts += 1
        scale = i / max(attempts - 1, 1)
        posture = {k: v + rng.uniform(-1, 1) * posture_perturb_rad * scale
                   for k, v in target.posture_rad.items()}
        pelvis = None
        if target.pelvis_target_m is not None:
            pelvis = target.pelvis_target_m + rng.uniform(-1, 1, 3) * pelvis_perturb_m * scale
        q_try = q_seed
        for retract in range(3):
            result = solve_ik(kin, q_try, target.support, target.moving, posture_rad=posture,
                              torso_R=target.torso_R, pelvis_target_m=pelvis,
                              pelvis_weight=target.pelvis_weight, com_polygon_cw=polygon,
                              joint_bounds_rad=target.joint_bounds_rad, config=ik_config)
            if not result.converged:
                stats.ik_failures += 1
                last = Verdict.ik_failure(result)
                break
            verdict = checker.check(result.q, target.stability_stance, target.contacts)
            if verdict.ok:
                return result.q, verdict
            last = verdict
            stats.reject(verdict.cause)
            if verdict.cause is RejectCause.TORQUE and np.isfinite(verdict.torque_ratio):
                q_ok, v = _descend_torque(kin, checker, target, rng, result.q,
                                          verdict.torque_ratio, polygon,
                                          ik_config, stats)
                if q_ok is not None:
                    return q_ok, v
                last = v or last
                break
            if not verdict.environment_only:
                break
            # Retract: pull the pelvis away from the ladder and project again.
            q_try = result.q.copy()
            q_try[:3] += target.retreat_direction * retract_step_m * (retract + 1)
            pelvis = q_try[:3].copy()
    return None, last
