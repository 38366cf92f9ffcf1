"""Execution: the trajectory player (and, alongside, validate-plan, play-trajectory, batch-eval).

Re-exports only the light player; the MuJoCo and Dask paths are imported from their own
modules when needed.
"""

from execute.player import (
    ArmModeSchedule,
    ModeScheduleError,
    PlayerOptionError,
    PlayerOptions,
    PlayerStateError,
    PlayerTick,
    TrajectoryPlayer,
    compliant_arms_from_flags,
)

__all__ = [
    "ArmModeSchedule",
    "ModeScheduleError",
    "PlayerOptionError",
    "PlayerOptions",
    "PlayerStateError",
    "PlayerTick",
    "TrajectoryPlayer",
    "compliant_arms_from_flags",
]
