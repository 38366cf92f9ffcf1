"""Simulated sensors of the board model: 4 FT sensors, 3 IMUs, in hubo-state units.

Where they sit (DRC-Hubo, hubo-facts §4):

- FT sensors between ankle and foot (boards 1 right foot, 2 left foot) and between wrist
  and hand (6 right hand, 7 left hand): a site at the origin of the foot body (ankle
  roll axis) and of the hand body (wrist roll axis). Each reports ``mx, my`` [N·m] and
  ``fz`` [N] in the sensor frame (parallel to the link frame: z along the shank / the
  forearm). ``fz`` is the load the limb carries: positive when the foot is pressed
  onto the ground (standing gives ≈ half the robot's weight per foot, minus the foot's
  own weight below the sensor), likewise positive when the hand pushes on a rail.
- IMUs: the body IMU at the ``imu`` site (pelvis) and the two foot tilt sensors at the
  soles: ``ax, ay, az`` [m/s²] (specific force, so ``az ≈ +9.81`` at rest) and
  ``wx, wy, wz`` [rad/s], in the sensor frame.

Order in arrays: FT ``(R foot, L foot, R hand, L hand)`` as boards 1, 2, 6, 7; IMU
``(body, R foot, L foot)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

__all__ = ["FT_SENSORS", "IMU_SENSORS", "SensorReading", "add_sensors", "read_sensors"]

#: FT sensor name → body whose origin carries it.
FT_SENSORS = {"ft_r_foot": "R_foot", "ft_l_foot": "L_foot", "ft_r_hand": "R_hand",
              "ft_l_hand": "L_hand"}
#: IMU name → existing site.
IMU_SENSORS = {"imu_body": "imu", "imu_r_foot": "R_sole", "imu_l_foot": "L_sole"}


@dataclass(frozen=True, eq=False)
class SensorReading:
    """Attributes:
        ft: (4, 3) ``mx [N·m], my [N·m], fz [N]`` per FT sensor.
        imu: (3, 6) ``ax, ay, az [m/s²], wx, wy, wz [rad/s]`` per IMU.
    """

    ft: np.ndarray
    imu: np.ndarray


def add_sensors(spec: mujoco.MjSpec) -> None:
    """Add the FT sites and the force/torque/accelerometer/gyro sensors to a scene spec."""
    for name, body in FT_SENSORS.items():
        spec.body(body).add_site(name=name + "_site", pos=[0, 0, 0], size=[0.005, 0, 0])
        spec.add_sensor(name=name + "_f", type=mujoco.mjtSensor.mjSENS_FORCE,
                        objtype=mujoco.mjtObj.mjOBJ_SITE, objname=name + "_site")
        spec.add_sensor(name=name + "_t", type=mujoco.mjtSensor.mjSENS_TORQUE,
                        objtype=mujoco.mjtObj.mjOBJ_SITE, objname=name + "_site")
    for name, site in IMU_SENSORS.items():
        spec.add_sensor(name=name + "_a", type=mujoco.mjtSensor.mjSENS_ACCELEROMETER,
                        objtype=mujoco.mjtObj.mjOBJ_SITE, objname=site)
        spec.add_sensor(name=name + "_w", type=mujoco.mjtSensor.mjSENS_GYRO,
                        objtype=mujoco.mjtObj.mjOBJ_SITE, objname=site)


class SensorIndex:
    """sensordata addresses of the sensors added by `add_sensors`."""

    def __init__(self, model: mujoco.MjModel):
        def adr(name: str) -> int:
            return int(model.sensor_adr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR,
                                                          name)])
        self.ft = [(adr(n + "_f"), adr(n + "_t")) for n in FT_SENSORS]
        self.imu = [(adr(n + "_a"), adr(n + "_w")) for n in IMU_SENSORS]


def read_sensors(data: mujoco.MjData, index: SensorIndex,
                 gyro_bias_rad_s: np.ndarray | None = None) -> SensorReading:
    """The sensors' values after ``mj_step`` / ``mj_forward`` (see the module docstring).

    ``gyro_bias_rad_s``: what every gyro reads at rest, ``wx, wy, wz`` [rad/s]: MuJoCo's
    gyro is exact, a MEMS gyro's is not (`BoardModelConfig.gyro_bias_rad_s`)."""
    sd = data.sensordata
    ft = np.empty((4, 3))
    for k, (fa, ta) in enumerate(index.ft):
        # MuJoCo gives the wrench the child subtree receives from its parent; the load the
        # limb carries (ground pushing the foot up) is its opposite.
        ft[k] = (-sd[ta], -sd[ta + 1], -sd[fa + 2])
    imu = np.empty((3, 6))
    for k, (aa, wa) in enumerate(index.imu):
        imu[k, :3] = sd[aa:aa + 3]
        imu[k, 3:] = sd[wa:wa + 3]
    if gyro_bias_rad_s is not None:
        imu[:, 3:] += gyro_bias_rad_s
    return SensorReading(ft, imu)
