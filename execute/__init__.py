"""Execution: a planned climb played, in simulation or on the robot, and measured.

Sub-packages, from the robot side up:
- `execute.play`: the trajectory player and ``play-trajectory`` (numpy only);
- `execute.motion`: the closed-loop motion layer between the player and the daemon;
- `execute.validate`: ``validate-plan``, lock-step MuJoCo playback, verdict and metrics;
- `execute.batch`: ``batch-eval``, many plans and climbs on a process pool or Dask.

Re-exports only the light player; the MuJoCo and Dask paths are imported from their own
modules when needed.
"""

from execute.play import (
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
