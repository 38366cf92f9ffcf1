"""The 40 joints of a Hubo, in the column order of the trajectory file.

This is the one place the order is written down; code, URDF, MJCF and CAN tables all
use these names.
"""

from __future__ import annotations

LEG_SUFFIXES = ("HY", "HR", "HP", "KN", "AP", "AR")
ARM_SUFFIXES = ("SP", "SR", "SY", "EB", "WY", "WR", "WP")
FINGER_SUFFIXES = ("F1", "F2", "F3", "F4", "F5")

RIGHT_LEG = tuple("R" + s for s in LEG_SUFFIXES)
LEFT_LEG = tuple("L" + s for s in LEG_SUFFIXES)
RIGHT_ARM = tuple("R" + s for s in ARM_SUFFIXES)
LEFT_ARM = tuple("L" + s for s in ARM_SUFFIXES)
NECK_AND_WAIST = ("NKY", "NK1", "NK2", "WST")
RIGHT_FINGERS = tuple("R" + s for s in FINGER_SUFFIXES)
LEFT_FINGERS = tuple("L" + s for s in FINGER_SUFFIXES)

#: Column order of the 40-column trajectory file (hubo-read-trajectory).
JOINT_NAMES: tuple[str, ...] = (
    RIGHT_LEG + LEFT_LEG + RIGHT_ARM + LEFT_ARM + NECK_AND_WAIST + RIGHT_FINGERS + LEFT_FINGERS
)
NUM_JOINTS = len(JOINT_NAMES)
JOINT_INDEX: dict[str, int] = {name: i for i, name in enumerate(JOINT_NAMES)}

#: An "arm" for compliance switching: shoulder, elbow and wrist (hubo-facts §2).
ARM_JOINTS = {"right": RIGHT_ARM, "left": LEFT_ARM}
LEG_JOINTS = {"right": RIGHT_LEG, "left": LEFT_LEG}
FINGER_JOINTS = {"right": RIGHT_FINGERS, "left": LEFT_FINGERS}


def joint_indices(names: tuple[str, ...] | list[str]) -> list[int]:
    """Column indices of the given joint names."""
    return [JOINT_INDEX[n] for n in names]


assert NUM_JOINTS == 40
