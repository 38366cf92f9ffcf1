"""What the robot's sensors report, and nothing else: the motion layer's only input.

`SensedState.from_sample` reads one ``daemon.structs.STATE_DTYPE`` sample, the struct
the daemon publishes on its ``state`` channel on the robot and in simulation alike:
encoders (joints and fingers), joint velocities, motor currents, the four F/T sensors,
the three IMUs, which boards are powered and which joints comply. There is no other way
into the motion layer, so it cannot see the simulator's ground truth, contacts or grip
latch.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from daemon.structs import FT_DTYPE, FT_NAMES, IMU_DTYPE, IMU_NAMES, STATE_DTYPE

__all__ = ["SensedState"]

_FT_SLOT = {name: k for k, name in enumerate(FT_NAMES)}
_IMU_SLOT = {name: k for k, name in enumerate(IMU_NAMES)}


@dataclass(frozen=True, eq=False)
class SensedState:
    """One state sample, in hubo-state units.

    Attributes:
        time_s: daemon time [s].
        pos_rad: encoder positions by file column [rad], shape (40,).
        vel_rad_s: joint velocities [rad/s], shape (40,).
        ft: (4, 3) ``mx [N·m], my [N·m], fz [N]`` per sensor, ``daemon.structs.FT_NAMES``
            order (right foot, left foot, right hand, left hand).
        imu: (3, 6) ``ax, ay, az [m/s²], wx, wy, wz [rad/s]`` per IMU (body, feet).
        ref_rad: the reference each board runs on, shape (40,).
        cur_a: motor currents [A], shape (40,).
        active: the joint's board is powered, shape (40,) bool.
        comply: the joint runs in PWM mode, shape (40,) bool.
    """

    time_s: float
    pos_rad: np.ndarray
    vel_rad_s: np.ndarray
    ft: np.ndarray
    imu: np.ndarray
    ref_rad: np.ndarray
    cur_a: np.ndarray
    active: np.ndarray
    comply: np.ndarray

    @classmethod
    def from_sample(cls, sample: np.ndarray) -> SensedState:
        """Read a ``STATE_DTYPE`` sample (a 0-d structured array)."""
        if sample.dtype != STATE_DTYPE:
            raise TypeError(f"expected a state sample ({STATE_DTYPE.itemsize} bytes), got "
                            f"dtype {sample.dtype}")
        ft = np.column_stack([sample["ft"][f] for f in FT_DTYPE.names])
        imu = np.column_stack([sample["imu"][f] for f in IMU_DTYPE.names])
        return cls(float(sample["time_s"]), np.array(sample["pos"], dtype=float),
                   np.array(sample["vel"], dtype=float), ft, imu,
                   np.array(sample["ref"], dtype=float), np.array(sample["cur"], dtype=float),
                   np.array(sample["active"], dtype=bool), np.array(sample["comply"], dtype=bool))

    def foot_load_n(self, side: str) -> float:
        """The load a foot carries, from its F/T sensor's fz [N] (positive pressed down)."""
        return float(self.ft[_FT_SLOT["RFFT" if side == "right" else "LFFT"], 2])

    def hand_wrench(self, side: str) -> np.ndarray:
        """``mx [N·m], my [N·m], fz [N]`` of a wrist's F/T sensor."""
        return self.ft[_FT_SLOT["RHFT" if side == "right" else "LHFT"]]

    def body_specific_force(self) -> np.ndarray:
        """The body IMU's accelerometer ``ax, ay, az`` [m/s²] (pelvis frame)."""
        return self.imu[_IMU_SLOT["IMU"], :3]

    def body_angular_rate(self) -> np.ndarray:
        """The body IMU's gyro ``wx, wy, wz`` [rad/s] (pelvis frame)."""
        return self.imu[_IMU_SLOT["IMU"], 3:]
