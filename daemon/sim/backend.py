"""The ``sim`` backend: the MuJoCo board model behind the daemon loop, in real time.

The same `daemon.sim.board_model.BoardModel` that ``validate-plan`` steps in lock-step: its
physics runs at its own rate (1.25 ms, four steps per 5 ms tick), the control law at the
loop's 200 Hz. The loop's absolute deadlines make it real time: each tick,
``step(dt)`` integrates the ``dt`` of wall-clock time since the last tick with the last
commands (one board tick per 5 ms; after an overrun the missed ticks too, up to
``max_catch_up_s``, beyond which simulated time falls behind and that is logged).

Board commands: ``RESET`` clears board trips; ``INIT_SENSORS`` zeroes the FT readings
and the IMU rates and horizontal accelerations where the robot stands (hubo-ach nulled
them on the boards; do it while the robot hangs still); homing needs no motion here (the
encoders of a simulation are right): the loop's gates do the rest.
"""

from __future__ import annotations

import logging
import math

import numpy as np

from daemon.backend import BoardCommands, SensorFrame
from daemon.joint_control import ControlOutput
from daemon.sim.board_model import TICK_S, BoardModel, BoardModelConfig
from daemon.structs import BoardCommandType, StatusFlag
from ladders.spec import LadderSpec
from robot.constants import GRAVITY_M_S2
from robot.joints import NUM_JOINTS

__all__ = ["SimBackend"]

log = logging.getLogger(__name__)

_FALSE = np.zeros(NUM_JOINTS, bool)
_FALSE.setflags(write=False)


class SimBackend:
    """The MuJoCo board model as a daemon backend.

    Args:
        ladder: the ladder in the scene.
        robot: robot name.
        config: board-model tunables (battery, trips, grip).
        start_pose_rad: joint pose at start (40,) [rad]; the zero pose when None. The
            robot stands on the floor at the world origin.
        homed: start with every joint homed (skips ``homeAll``).
        max_catch_up_s: most simulated time one ``step`` integrates [s].
    """

    name = "sim"
    homes_to_zero = False

    def __init__(self, ladder: LadderSpec, robot: str = "drc-hubo",
                 config: BoardModelConfig | None = None,
                 start_pose_rad: np.ndarray | None = None, homed: bool = False,
                 max_catch_up_s: float = 0.1):
        self.board = BoardModel(ladder, robot, config)
        self.board.reset(start_pose_rad)
        self._homed = homed
        self._max_ticks = max(1, int(round(max_catch_up_s / TICK_S)))
        self._owed_s = 0.0
        self.behind_s = 0.0  # simulated time dropped after long stalls [s]
        self._ft_offset = np.zeros((4, 3))
        self._imu_offset = np.zeros((3, 6))
        self.trips: list = []
        self.grasps: list = []

    def zeroed_at_start(self) -> np.ndarray:
        return np.full(NUM_JOINTS, self._homed)

    def step(self, dt_s: float) -> None:
        self._owed_s += dt_s
        n = int(math.floor(self._owed_s / TICK_S + 1e-6))
        if n > self._max_ticks:
            dropped = (n - self._max_ticks) * TICK_S
            self.behind_s += dropped
            log.warning("simulation fell %.0f ms behind the wall clock (stall of %.0f ms)",
                        dropped * 1e3, dt_s * 1e3)
            self._owed_s -= dropped
            n = self._max_ticks
        for _ in range(n):
            trips, grasps = self.board.step()
            self.trips += trips
            self.grasps += grasps
        self._owed_s -= n * TICK_S

    def read_sensors(self) -> SensorFrame:
        s = self.board.state()
        status = np.where(s.active, 0, int(StatusFlag.TRIPPED)).astype(np.uint32)
        latched = np.array([self.board.latches["left"].latched,
                            self.board.latches["right"].latched])
        return SensorFrame(s.pos_rad, s.vel_rad_s, s.cur_a, status, s.active,
                           s.sensors.ft - self._ft_offset, s.sensors.imu - self._imu_offset,
                           np.array([s.power_v, s.power_a, s.power_w]), latched)

    def write_commands(self, cmd: BoardCommands) -> None:
        self.board.apply(ControlOutput(
            ref_sent_rad=cmd.ref_rad, duty_pct=cmd.duty_pct, pwm=cmd.pwm, returning=_FALSE,
            limp=_FALSE, duty_saturated=_FALSE, limit_clamped=_FALSE,
            comply_unsupported=_FALSE, state=np.zeros(NUM_JOINTS, np.int8)))

    def idle(self, until_ns: int) -> None:
        pass

    def board_command(self, kind: BoardCommandType, joint: int) -> None:
        if kind is BoardCommandType.RESET:
            self.board.trips.reset()  # the next apply() powers the boards again
        elif kind is BoardCommandType.INIT_SENSORS:
            s = self.board.state().sensors
            self._ft_offset = s.ft.copy()
            self._imu_offset = s.imu.copy()
            self._imu_offset[:, 2] -= GRAVITY_M_S2  # keep gravity on z: the robot hangs upright

    def close(self) -> None:
        pass
