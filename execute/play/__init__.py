"""The trajectory player and ``play-trajectory``.

- `player`: a trajectory, the hubo-read-trajectory flags and the sidecar's arm-mode
  schedule turned into per-tick references, modes and feed-forward duty;
- `cli`: the ``play-trajectory`` command, playing in real time against the daemon.

The player needs numpy only, so its names are re-exported directly.
"""

from execute.play.player import (
    ALLOWED_RATES_HZ,
    ARM_MODES,
    ARMS,
    ArmModeSchedule,
    ModeScheduleError,
    PlayerOptionError,
    PlayerOptions,
    PlayerStateError,
    PlayerTick,
    TrajectoryPlayer,
    compliant_arms_from_flags,
    min_jerk,
)

__all__ = [
    "ALLOWED_RATES_HZ",
    "ARMS",
    "ARM_MODES",
    "ArmModeSchedule",
    "ModeScheduleError",
    "PlayerOptionError",
    "PlayerOptions",
    "PlayerStateError",
    "PlayerTick",
    "TrajectoryPlayer",
    "compliant_arms_from_flags",
    "min_jerk",
]
