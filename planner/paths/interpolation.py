"""Contact-space recursive interpolation (thesis §6.3.1).

Between two configurations feasible at the same stance: take the joint-space midpoint,
project it by IK so the supporting limbs stay on their holds (and a moving limb stays on
the straight line between its two poses), check it, and recurse on both halves until
neighbours are closer than the resolution.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from planner.configuration.ik import IKConfig, solve_ik
from planner.configuration.kinematics import HuboKinematics
from planner.configuration.validity import FeasibilityChecker, Verdict
from planner.contacts import Hold, Stance
from robot.errors import HuboLadderError
from robot.vocabulary import InterpolationFailure, RejectCause

#: The projection's pull towards the joint-space midpoint (keeps it local).
MIDPOINT_POSTURE_WEIGHT = 0.1
#: A moving limb's midpoint target is halfway between its neighbours' actual poses, so it
#: is reachable: meet it tightly, or tolerance noise keeps the bisection from closing [m].
PROJECTION_TOL_M = 2e-4
#: A projected midpoint farther than this fraction of the interval from either end has
#: jumped to another IK branch: bisection would never close the gap.
JUMP_RATIO = 0.8


class InterpolationError(HuboLadderError):
    """A midpoint could not be projected, or its projection is infeasible.

    Attributes:
        cause: what failed.
        reason: the message, with the figures.
        depth: recursion depth of the failing midpoint.
        verdict: the refused midpoint's verdict (a failed projection's holds left unmet
            as an IK verdict), for a failure message in user terms; None otherwise.
    """

    def __init__(self, cause: InterpolationFailure, reason: str, depth: int,
                 verdict: Verdict | None = None):
        super().__init__(f"{reason} (recursion depth {depth})")
        self.cause = cause
        self.reason = reason
        self.depth = depth
        self.verdict = verdict

    @property
    def verdict_cause(self) -> RejectCause | None:
        """Why the predicate refused the midpoint (its verdict's cause), if it did."""
        return None if self.verdict is None else self.verdict.cause


@dataclass
class InterpolationStats:
    projections: int = 0
    max_depth: int = 0
    min_margin_m: float = np.inf
    max_torque_ratio: float = 0.0


def _interp_pose(Ta: np.ndarray, Tb: np.ndarray, s: float) -> np.ndarray:
    """Position linear, rotation along the geodesic."""
    T = np.eye(4)
    T[:3, 3] = (1 - s) * Ta[:3, 3] + s * Tb[:3, 3]
    T[:3, :3] = Ta[:3, :3] @ pin.exp3(s * pin.log3(Ta[:3, :3].T @ Tb[:3, :3]))
    return T


def contact_space_interpolate(kin: HuboKinematics, checker: FeasibilityChecker,
                              qa: np.ndarray, qb: np.ndarray, support: tuple[Hold, ...],
                              stability_stance: Stance, contacts: dict[str, str], *,
                              moving: tuple[Hold, ...] = (), resolution_rad: float = 0.01,
                              max_depth: int = 14, ik_config: IKConfig | None = None,
                              stats: InterpolationStats | None = None) -> list[np.ndarray]:
    """Configurations from ``qa`` (excluded) to ``qb`` (included), each within
    ``resolution_rad`` of the next in every joint, all on the contact constraints.

    Args:
        moving: hold templates of the moving limbs; at each midpoint a moving frame's
            target is the pose halfway between its poses at the two neighbours.

    Raises:
        InterpolationError: a midpoint did not project or is infeasible.
    """
    stats = stats if stats is not None else InterpolationStats()
    ik_config = ik_config or IKConfig()
    # Only restore the contacts, staying near the midpoint; stability is checked after.
    cfg = IKConfig(**{**ik_config.__dict__, "posture_weight": MIDPOINT_POSTURE_WEIGHT,
                      "torso_upright_weight": 0.0, "moving_tol_m": PROJECTION_TOL_M,
                      "moving_angle_tol_rad": ik_config.angle_tol_rad})

    def project(q0: np.ndarray, q1: np.ndarray, span: float, qm: np.ndarray, moving_targets,
                com_polygon_cw: np.ndarray | None, depth: int):
        """``qm`` projected onto the holds (its CoM pulled into ``com_polygon_cw`` if
        given) and its verdict; raises if it does not project or jumps IK branch."""
        res = solve_ik(kin, qm, support, moving_targets, posture_rad=kin.posture(qm),
                       com_polygon_cw=com_polygon_cw, preferences=False, config=cfg)
        stats.projections += 1
        if not res.converged:
            raise InterpolationError(InterpolationFailure.PROJECTION_FAILED,
                                     f"projection failed: {res!r}", depth,
                                     verdict=Verdict.ik_failure(res))
        if max(kin.joint_distance(q0, res.q), kin.joint_distance(res.q, q1)) > JUMP_RATIO * span:
            worst = int(np.argmax(np.abs(res.q[7:] - qm[7:])))
            raise InterpolationError(
                InterpolationFailure.BRANCH_JUMP,
                f"projection jumped to another IK branch at joint "
                f"{kin.model.names[worst + 2]} ({qm[7 + worst]:.3f} → {res.q[7 + worst]:.3f} rad)",
                depth)
        return res.q, checker.check(res.q, stability_stance, contacts)

    def rec(q0: np.ndarray, q1: np.ndarray, depth: int) -> list[np.ndarray]:
        span = kin.joint_distance(q0, q1)
        if span <= resolution_rad:
            return [q1]
        if depth >= max_depth:
            raise InterpolationError(InterpolationFailure.RESOLUTION, "resolution not reached",
                                     depth)
        stats.max_depth = max(stats.max_depth, depth + 1)
        qm = kin.interpolate(q0, q1, 0.5)
        moving_targets = tuple(
            Hold(h.limb, h.target, _interp_pose(kin.frame_pose(q0, h.frame),
                                                kin.frame_pose(q1, h.frame), 0.5),
                 h.points_m, h.normals, h.friction)
            for h in moving)
        q_mid, verdict = project(q0, q1, span, qm, moving_targets, None, depth)
        region = checker.region(stability_stance) if verdict.com_margin_m < 0 else None
        if region is not None and not region.is_empty:
            # The CoM left the support region between two stable ends: project again,
            # pulling the CoM into the region as the ends were found. Only then: on every
            # projection the pull also bends paths that were fine, and lengthens them.
            q_mid, verdict = project(q0, q1, span, qm, moving_targets,
                                     region.clockwise_vertices(), depth)
        if not verdict.ok:
            raise InterpolationError(InterpolationFailure.MIDPOINT_INFEASIBLE,
                                     f"midpoint infeasible: {verdict.reason}", depth,
                                     verdict)
        stats.min_margin_m = min(stats.min_margin_m, verdict.com_margin_m)
        stats.max_torque_ratio = max(stats.max_torque_ratio, verdict.torque_ratio)
        return rec(q0, q_mid, depth + 1) + rec(q_mid, q1, depth + 1)

    return rec(qa, qb, 0)
