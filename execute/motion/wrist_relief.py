"""Relief of a gripping compliant arm's wrist roll, the one joint of the arm that cannot
comply (it shares a 3-channel board with the fingers, hubo-facts §2).

With the hand closed on its rail, a twist of the grip loads its position loop; when its
board trips, the fingers let go. And the hand grips across its rail, so the wrist roll's
axis, the forearm's, lies across the rail: whatever torque the rigid roll holds is
bending on the grip, which pries the fingers open at 9 N·m
(`ladders.contact_model.GripCapacity`). The motor current says how hard a joint pushes
(``τ = η·gear·Kt·I``, `robot.motors.MotorTable.torque_nm`, which the motion layer applies
once a tick to every column). While that torque is above ``relief_fraction`` of the
joint's limit, its reference walks towards where the grip wants it, at
``relief_speed_rad_s``, within ``max_offset_rad``; the offset is kept while the hand
holds and unwound while it moves in the air.

The fraction is 0.1 (0.48 N·m of the roll's 4.8). At half the limit, DRC seed 12 under a
1.3 cm placement error let its right grip go to bending at the mount, the roll holding
2.1 N·m of the 9.3 N·m that opened it; at 0.1 it climbed (S26, 2026-11-28,
docs/decisions/motion-layer.md).
"""

from __future__ import annotations

import math

import numpy as np

from robot.joints import JOINT_INDEX
from robot.limits import joint_limits

__all__ = ["WRIST_ROLL", "WristRelief"]

WRIST_ROLL = {"left": JOINT_INDEX["LWR"], "right": JOINT_INDEX["RWR"]}


class WristRelief:
    """Offsets of rigid joints from their sensed torques (module docstring).

    Args:
        robot: robot name (torque limits).
        relief_fraction: share of the torque limit above which the reference gives way.
        relief_speed_rad_s: how fast it gives way [rad/s].
        max_offset_rad: largest offset [rad].
    """

    def __init__(self, robot: str = "drc-hubo", relief_fraction: float = 0.1,
                 relief_speed_rad_s: float = 0.3, max_offset_rad: float = 0.6):
        self.limit_nm = joint_limits(robot).torque_max_nm
        self.relief_fraction = relief_fraction
        self.speed = relief_speed_rad_s
        self.max_offset_rad = max_offset_rad
        self.offset_rad: dict[int, float] = {}

    def update(self, joint: int, holding: bool, torque_nm: np.ndarray, dt_s: float) -> float:
        """The offset of column ``joint`` after one tick [rad]; ``torque_nm``: the sensed
        joint torques by column [N·m]."""
        j = joint
        off = self.offset_rad.get(j, 0.0)
        if holding:
            torque = float(torque_nm[j])
            if abs(torque) > self.relief_fraction * self.limit_nm[j]:
                # the loop pushes with +τ towards a reference above the joint: give way
                off -= math.copysign(self.speed * dt_s, torque)
        elif off != 0.0:
            off -= math.copysign(min(abs(off), self.speed * dt_s), off)
        off = min(max(off, -self.max_offset_rad), self.max_offset_rad)
        self.offset_rad[j] = off
        return off
