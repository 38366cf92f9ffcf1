"""Paths of a moving limb: way-points along an arc in world space, then IK and
contact-space interpolation between them (thesis §6.3.1, "Paths").

Hands back off the rail towards the climber, travel parallel to it and approach the new
hold. Feet lift, pull back and rise until the toes clear the target rung, move over it
and set down.
"""

from __future__ import annotations

import numpy as np

from ladders.geometry import LadderGeometry
from planner.contacts import Hold
from planner.holds import hand_retreat_direction
from primitives.primitive import LimbWaypoints
from robot.params import RobotParams

#: The first grasp approaches from this far inboard of the rail [m].
INBOARD_APPROACH_M = 0.15


def _shifted(T: np.ndarray, dp: np.ndarray) -> np.ndarray:
    out = T.copy()
    out[:3, 3] = T[:3, 3] + dp
    return out


def hand_waypoints(T_from: np.ndarray, target: Hold, geom: LadderGeometry,
                   recipe: LimbWaypoints, on_rail: bool) -> list[np.ndarray]:
    """Palm poses from ``T_from`` to the new rail hold, backing off away from the hand's
    open side, travelling along the rail and approaching the new hold the same way.

    ``on_rail`` says whether the hand starts closed on a rail (it then backs off first).
    """
    away = hand_retreat_direction(target.limb, target.T_world_frame) * recipe.clearance_m
    T_to = target.T_world_frame
    T_pre = _shifted(T_to, away)
    points = [T_from]
    if on_rail:
        back = hand_retreat_direction(target.limb, T_from) * recipe.clearance_m
        points.append(_shifted(T_from, back))
    else:
        # From the floor the hand rises inside the rail, then moves out to it: a straight
        # line from the hanging pose would sweep past the rail's lower end.
        side = 1.0 if target.limb == "left_hand" else -1.0
        points.append(_shifted(T_pre, -side * geom.lateral_direction * INBOARD_APPROACH_M))
    points += [T_pre, T_to]
    return points


def foot_waypoints(T_from: np.ndarray, target: Hold, geom: LadderGeometry,
                   params: RobotParams, recipe: LimbWaypoints, rung: int) -> list[np.ndarray]:
    """Sole poses from ``T_from`` to a rung hold: lift, pull back until the toes are behind
    the rung's rear edge, rise above it with clearance, move over the tread, set down."""
    spec = geom.spec
    to_L = geom.to_ladder
    p_from_L, p_to_L = to_L(T_from[:3, 3]), to_L(target.T_world_frame[:3, 3])
    top_z = spec.rung_height_m(rung) + recipe.clearance_m
    rear_edge_x = spec.rung_run_m(rung) - spec.rung_depth_m / 2
    # Toes (half a foot ahead of the sole centre) must stay behind the rear edge while rising.
    x_clear = min(p_from_L[0], rear_edge_x - params.foot_length_m / 2 - recipe.clearance_m / 2)
    lift_L = p_from_L + [0.0, 0.0, recipe.lift_m]
    # Pull back at lift height first: on deep treads the toes start under the next rung.
    back_L = np.array([x_clear, lift_L[1], lift_L[2]])
    rise_L = np.array([x_clear, p_from_L[1] + (p_to_L[1] - p_from_L[1]) / 2,
                       max(top_z, lift_L[2])])
    over_L = np.array([p_to_L[0], p_to_L[1], top_z])
    R = target.T_world_frame[:3, :3]
    poses = [T_from]
    for p_L in (lift_L, back_L, rise_L, over_L):
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = R, geom.to_world(p_L)
        poses.append(T)
    poses.append(target.T_world_frame)
    return poses
