"""The trajectory player and ``play-trajectory``.

- `player`: a trajectory, the hubo-read-trajectory flags and the sidecar's arm-mode
  schedule turned into per-tick references, modes and feed-forward duty;
- `arm_modes`: the sidecar's per-arm position/PWM runs as one flag per line;
- `cli`: the ``play-trajectory`` command, playing in real time against the daemon.

The player needs numpy only, so its names are re-exported directly.
"""

from execute.play.arm_modes import ArmModeSchedule, ModeScheduleError
from execute.play.player import (
    ALLOWED_RATES_HZ,
    ARM_MODES,
    ARMS,
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
