"""The arms' position/PWM schedule of a timed plan, from the palms' poses.

PWM (compliant) mode is scheduled for an arm while its hand holds a rail or its palm is
within `PWM_RAIL_DISTANCE_M` of its rail's axis (closing, opening, the first and last
centimetres of a reach); position mode while the hand moves through the air, and
throughout a plan made for rigid arms (``arm_strategy`` ``position``). The sidecar
(`planner.output`) records the schedule as run-length runs per arm, and how far each held
palm turns on its rail.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from planner.statics.arm_capacity import arms_comply_while_gripping
from robot.plan_sidecar import Segment, hand_holding_lines
from robot.vocabulary import SIDES

if TYPE_CHECKING:
    from planner.search import ClimbPlanner
    from planner.timing import TimedPlan

__all__ = ["PWM_RAIL_DISTANCE_M", "arm_mode_runs", "arm_schedule", "held_palm_turn_rad",
           "palm_poses", "palm_rail_distances"]

#: An arm is compliant (PWM) while its palm is this close to its rail's axis [m].
PWM_RAIL_DISTANCE_M = 0.03
ARMS = SIDES


def arm_schedule(planner: ClimbPlanner, segments: list[Segment], timed: TimedPlan
                 ) -> tuple[dict[str, list[tuple[int, int, str]]], dict[str, np.ndarray]]:
    """Per arm, its position/PWM runs: PWM (for a strategy whose gripping arms comply)
    while its hand holds a rail or its palm is within `PWM_RAIL_DISTANCE_M` of one; and
    per line, how far a held palm has turned about its rail [rad]."""
    palms = palm_poses(timed.configs, planner.kin)
    distances = palm_rail_distances(palms, planner.geom)
    # A plan for rigid arms loads them beyond what a compliant arm gives: never PWM.
    comply = arms_comply_while_gripping(planner.config.arm_strategy)
    holding = {side: hand_holding_lines(segments, timed.line_count, side) for side in ARMS}
    arm_modes = {side: arm_mode_runs((holding[side] | (distances[side] <= PWM_RAIL_DISTANCE_M))
                                     & comply) for side in ARMS}
    return arm_modes, held_palm_turn_rad(palms, holding)


def palm_poses(configs: np.ndarray, kin) -> dict[str, np.ndarray]:
    """Each palm's pose per line, arm → (N, 4, 4): one forward kinematics per line.

    Args:
        configs: (N, nq) full configurations.
        kin: `HuboKinematics` (palm frames ``L_palm``/``R_palm``).
    """
    frames = {side: kin.model.getFrameId("L_palm" if side == "left" else "R_palm")
              for side in ARMS}
    out = {side: np.empty((len(configs), 4, 4)) for side in ARMS}
    for i, q in enumerate(configs):
        pin.framesForwardKinematics(kin.model, kin.data, q)
        for side, fid in frames.items():
            out[side][i] = kin.data.oMf[fid].homogeneous
    return out


def palm_rail_distances(palms: dict[str, np.ndarray], geom) -> dict[str, np.ndarray]:
    """Distance of each palm to its own side's rail axis, per line [m].

    Args:
        palms: arm → (N, 4, 4) palm poses (`palm_poses`).
        geom: `LadderGeometry` (``closest_rail_point``).
    """
    return {side: np.linalg.norm(T[:, :3, 3] - geom.closest_rail_point(side, T[:, :3, 3]),
                                 axis=1) for side, T in palms.items()}


def held_palm_turn_rad(palms: dict[str, np.ndarray], holding: dict[str, np.ndarray]
                       ) -> dict[str, np.ndarray]:
    """How far each held palm has turned since its hand closed on the rail, per line [rad].

    The holds fix a palm's position and grip axis only, so a held hand may turn about its
    rail from line to line, as a hooked hand does (`daemon.sim.grasp_latch`: the turn costs
    the friction of the load across the rail); a grip that squeezed the rail would resist
    it with more than a compliant arm gives.

    Args:
        palms: arm → (N, 4, 4) palm poses (`palm_poses`).
        holding: arm → bool (N,) lines on which that hand holds its rail.

    Returns:
        arm → (N,) rotation angle of the palm from its orientation on the first line of
        the current hold; 0 where the hand holds nothing.
    """
    out = {}
    for side, held in holding.items():
        R = palms[side][:, :3, :3]
        grasped = held & ~np.r_[False, held[:-1]]  # the hand has just closed on its rail
        first = np.maximum.accumulate(np.where(grasped, np.arange(len(held)), 0))
        cos = (np.einsum("nij,nij->n", R[first], R) - 1.0) / 2.0  # trace(R0ᵀ R)
        out[side] = np.where(held, np.arccos(np.clip(cos, -1.0, 1.0)), 0.0)
    return out


def arm_mode_runs(pwm: np.ndarray) -> list[tuple[int, int, str]]:
    """Run-length schedule of one arm from a per-line PWM flag.

    Args:
        pwm: (N,) True where the arm is compliant.

    Returns:
        ``[(first_line, last_line, "position"|"pwm"), ...]``, 1-based inclusive, covering
        lines 1..N in order.
    """
    pwm = np.asarray(pwm, dtype=bool)
    if pwm.size == 0:
        return []
    change = np.flatnonzero(pwm[1:] != pwm[:-1]) + 1
    starts = np.concatenate([[0], change])
    ends = np.concatenate([change, [len(pwm)]])
    return [(int(a) + 1, int(b), "pwm" if pwm[a] else "position") for a, b in zip(starts, ends,
                                                                                    strict=True)]
