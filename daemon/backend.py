"""The interface between the daemon's loop and the boards, real or simulated.

Each tick the loop (`daemon.loop`) asks a `Backend` to step, reads a `SensorFrame` from
it and sends it `BoardCommands`; `daemon.sim.backend` (the MuJoCo board model) and
`daemon.can.backend` (CAN buses) implement it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from daemon.joint_control import ControlOutput
from daemon.structs import NUM_FT, NUM_IMU, BoardCommandType
from robot.joints import NUM_JOINTS

__all__ = ["Backend", "BoardCommands", "SensorFrame"]


@dataclass(eq=False)
class SensorFrame:
    """What the boards reported for one tick, in ``hubo-state`` units.

    Attributes:
        pos_rad: encoder positions [rad], (40,), finite (a backend holds the last value
            of a joint that did not answer and flags it).
        vel_rad_s: velocities [rad/s], (40,).
        cur_a: motor currents [A], (40,).
        status: `StatusFlag` bits per joint from the boards (NO_REPLY, TRIPPED, …).
        active: motor powered and board answering, (40,) bool.
        ft: (4, 3) ``mx, my`` [N·m], ``fz`` [N].
        imu: (3, 6) ``ax, ay, az`` [m/s²], ``wx, wy, wz`` [rad/s].
        power: ``V`` [V], ``I`` [A], ``P`` [W].
        latched: grasp latch of the left and right hand (simulation only), or None.
    """

    pos_rad: np.ndarray
    vel_rad_s: np.ndarray
    cur_a: np.ndarray
    status: np.ndarray
    active: np.ndarray
    ft: np.ndarray
    imu: np.ndarray
    power: np.ndarray
    latched: np.ndarray | None = None

    @classmethod
    def zeros(cls) -> SensorFrame:
        """A robot at the zero pose, everything quiet."""
        return cls(np.zeros(NUM_JOINTS), np.zeros(NUM_JOINTS), np.zeros(NUM_JOINTS),
                   np.zeros(NUM_JOINTS, np.uint32), np.ones(NUM_JOINTS, bool),
                   np.zeros((NUM_FT, 3)), np.zeros((NUM_IMU, 6)), np.zeros(3))


@dataclass(frozen=True, eq=False)
class BoardCommands:
    """What the boards get this tick, from the control law's output, arrays (40,).

    Attributes:
        ref_rad: position reference [rad] (PWM joints: the reference of their duty).
        duty_pct: PWM duty [%] (hubo-ach sign), 0 for position-mode joints.
        pwm: the joint's board runs PWM (open loop) this tick.
    """

    ref_rad: np.ndarray
    duty_pct: np.ndarray
    pwm: np.ndarray

    @classmethod
    def from_output(cls, out: ControlOutput, off: np.ndarray | None = None) -> BoardCommands:
        """Commands from a `ControlOutput`; joints in ``off`` get PWM with zero duty."""
        if off is None or not off.any():
            return cls(out.ref_sent_rad, out.duty_pct, out.pwm)
        return cls(out.ref_sent_rad, np.where(off, 0.0, out.duty_pct), out.pwm | off)


class Backend(Protocol):
    """What the loop needs from the boards (`daemon.sim.backend`, `daemon.can.backend`).

    Attributes:
        name: ``"sim"`` or ``"can"``.
        homes_to_zero: a home command moves the joint to its zero (real boards); False
            when the joint stays where it is (simulation).
    """

    name: str
    homes_to_zero: bool

    def zeroed_at_start(self) -> np.ndarray:
        """(40,) bool: joints whose encoder needs no homing."""

    def step(self, dt_s: float) -> None:
        """The boards have run ``dt_s`` [s] since the last tick with the last commands."""

    def read_sensors(self) -> SensorFrame:
        """The boards' report at the start of this tick."""

    def write_commands(self, cmd: BoardCommands) -> None:
        """Send this tick's references, duties and modes."""

    def idle(self, until_ns: int) -> None:
        """Use the rest of the period (spread sends); return before ``until_ns``."""

    def board_command(self, kind: BoardCommandType, joint: int) -> None:
        """Carry out a board command on ``joint`` (−1: every joint) on the hardware side."""

    def close(self) -> None:
        """Release buses and models."""
