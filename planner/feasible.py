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

from planner.contacts import Hold, Stance
from planner.ik import IKConfig, solve_ik
from planner.kinematics import HuboKinematics
from planner.validity import FeasibilityChecker, Verdict

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


@dataclass
class FeasibleSearchStats:
    attempts: int = 0
    ik_failures: int = 0
    rejections: dict[str, int] | None = None

    def reject(self, reason: str) -> None:
        self.rejections = self.rejections or {}
        key = reason.split(" ")[0]
        self.rejections[key] = self.rejections.get(key, 0) + 1


#: Torque descent: evaluations per attempt, and step sizes of the pelvis [m] and posture
#: [rad] perturbations.
TORQUE_DESCENT_EVALUATIONS = 40
TORQUE_DESCENT_PELVIS_STEP_M = 0.04
TORQUE_DESCENT_POSTURE_STEP_RAD = 0.2
#: Joints whose preference the torque descent also varies: elbows and wrist rolls set
#: how a hand's load runs through the wrist.
TORQUE_DESCENT_JOINTS = ("LEB", "REB", "LWR", "RWR")


def _descend_torque(kin: HuboKinematics, checker: FeasibilityChecker, q_seed: np.ndarray,
                    target: SearchTarget, rng: np.random.Generator, q_start: np.ndarray,
                    ratio: float, posture: dict[str, float], pelvis: np.ndarray | None,
                    polygon, ik_config: IKConfig, stats: FeasibleSearchStats
                    ) -> tuple[np.ndarray | None, Verdict | None]:
    """Local random search that lowers the worst joint-torque ratio until it is ≤ 1."""
    best_pelvis = q_start[:3].copy() if pelvis is None else pelvis.copy()
    best_posture = dict(posture)
    for name in TORQUE_DESCENT_JOINTS:
        if name not in best_posture and name in kin.q_index:
            best_posture[name] = float(q_start[kin.q_index[name]])
    best_ratio = ratio
    last = None
    for _ in range(TORQUE_DESCENT_EVALUATIONS):
        cand_pelvis = best_pelvis + rng.normal(0.0, TORQUE_DESCENT_PELVIS_STEP_M, 3)
        cand_posture = {k: v + rng.normal(0.0, TORQUE_DESCENT_POSTURE_STEP_RAD)
                        for k, v in best_posture.items()}
        result = solve_ik(kin, q_seed, target.support, target.moving, posture_rad=cand_posture,
                          torso_R=target.torso_R, pelvis_target_m=cand_pelvis,
                          pelvis_weight=max(target.pelvis_weight, 1.0), com_polygon_cw=polygon,
                          config=ik_config)
        stats.attempts += 1
        if not result.converged:
            continue
        verdict = checker.check(result.q, target.stability_stance, target.contacts)
        last = verdict
        if verdict.ok:
            return result.q, verdict
        if np.isfinite(verdict.torque_ratio) and verdict.torque_ratio < best_ratio:
            best_ratio, best_pelvis, best_posture = verdict.torque_ratio, cand_pelvis, cand_posture
    return None, last


def find_feasible(kin: HuboKinematics, checker: FeasibilityChecker, q_seed: np.ndarray,
                  target: SearchTarget, rng: np.random.Generator, *, attempts: int = 10,
                  posture_perturb_rad: float = 0.3, pelvis_perturb_m: float = 0.08,
                  retract_step_m: float = 0.04, ik_config: IKConfig | None = None,
                  stats: FeasibleSearchStats | None = None
                  ) -> tuple[np.ndarray | None, Verdict | None]:
    """A feasible configuration near ``q_seed`` for ``target``, or (None, last verdict).

    The perturbation radius is 0 on the first attempt and grows linearly to the given
    maxima on the last one.
    """
    stats = stats or FeasibleSearchStats()
    ik_config = ik_config or IKConfig()
    region = checker.region(target.stability_stance)
    polygon = None if region.is_empty else region.clockwise_vertices()
    last: Verdict | None = None
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
                              config=ik_config)
            if not result.converged:
                stats.ik_failures += 1
                last = Verdict(False, f"ik {result!r}", np.nan, np.nan)
                break
            verdict = checker.check(result.q, target.stability_stance, target.contacts)
            if verdict.ok:
                return result.q, verdict
            last = verdict
            stats.reject(verdict.reason)
            if verdict.reason.startswith("torque") and np.isfinite(verdict.torque_ratio):
                q_ok, v = _descend_torque(kin, checker, q_seed, target, rng, result.q,
                                          verdict.torque_ratio, posture, pelvis, polygon,
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
