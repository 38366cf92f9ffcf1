"""The daemon side: per-joint control law, the 200 Hz loop, channels and backends.

- here: channel structs (`structs`), latest-value channels (`channels`), the control law
  (`control_modes`, `joint_control`, `pwm`), the loop (`loop`) and the interface its
  backends implement (`backend`), joint/sensor tables (`tables`), the state log and its
  MCAP export (`state_log`, `log_export`), the neck's keys (`neck`), the player's pause
  and stop from another process (`player_control`), and the ``hubo-daemon``,
  ``hubo-console``, ``hubo-read``, ``hubo-neck``, ``hubo-log-mcap`` CLIs;
- `daemon.can`: the CAN protocol, backend and board emulator;
- `daemon.sim`: the MuJoCo board model and the simulated world (grip, sensors, trips);
- `daemon.remote`: ``hubo-bridge``, the channels over the network (zenoh, mutual TLS);
- `daemon.station`: ``hubo-init``, the operator's web page, locally or through the bridge.

Re-exports only light, numpy-only names; backends (MuJoCo, CAN) are imported from their
own modules when needed.
"""

from daemon.control_modes import (
    DAEMON_RATE_HZ,
    TICK_S,
    ReferenceFilterConfig,
    ReferenceModeError,
    RefMode,
    default_filter_config,
)
from daemon.joint_control import (
    ComplianceState,
    ControlInputError,
    ControlOutput,
    JointController,
    default_compliance_capable,
)
from daemon.pwm import (
    PwmGainError,
    PwmGains,
    default_drc_gains,
    pwm_duty,
    validate_pwm_gains,
)

__all__ = [
    "DAEMON_RATE_HZ",
    "TICK_S",
    "ComplianceState",
    "ControlInputError",
    "ControlOutput",
    "JointController",
    "PwmGainError",
    "PwmGains",
    "RefMode",
    "ReferenceFilterConfig",
    "ReferenceModeError",
    "default_compliance_capable",
    "default_drc_gains",
    "default_filter_config",
    "pwm_duty",
    "validate_pwm_gains",
]
