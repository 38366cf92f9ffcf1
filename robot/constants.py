"""Constants shared by every layer, each with one home.

- The control rate: hubo-ach's daemon runs its loop at 200 Hz, and a trajectory file is
  written at that rate unless the user asks for another (``plan-ladder --rate``).
- Standard gravity, for weights and for an accelerometer's reading at rest.
"""

from __future__ import annotations

__all__ = ["DAEMON_RATE_HZ", "GRAVITY_M_S2", "TICK_S"]

#: The daemon's control loop rate, and the default rate of a trajectory file [Hz].
DAEMON_RATE_HZ: float = 200.0
#: One daemon tick [s] (5 ms).
TICK_S: float = 1.0 / DAEMON_RATE_HZ
#: Standard gravity [m/s²].
GRAVITY_M_S2: float = 9.81
