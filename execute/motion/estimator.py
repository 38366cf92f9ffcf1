"""The body's state from the sensors: tilt, pose, stance feet, grip closure.

- **Tilt** from the body IMU's accelerometer, low-pass filtered: at rest it measures the
  reaction to gravity, which gives the pelvis's roll and pitch (hubo-motion-rt used the
  waist IMU the same way).
- **Attitude** from the body IMU's gyro, integrated every sample. Its roll and pitch
  follow the accelerometer (``level_s``). While both feet stand on the floor, its heading
  follows theirs (leg odometry, ``heading_s``) and the gyro's bias is learnt from the
  disagreement; a foot whose heading departs from the gyro's by more than
  ``foot_turn_rad`` has turned and is anchored again at the gyro's heading. On the
  ladder the heading is the gyro's alone, less that bias: feet on rungs turn (on the DRC
  ladder they departed from the gyro by more than 0.3° 180 times in 400 s) and are no
  reference. Leg odometry alone cannot see a stance that turns as a whole: on `ship` the
  body turned 3.4° on its standing feet while a hand reached, and the reach closed 7 cm
  beside its rail (docs/decisions/gyro-heading.md).
- **Position** by leg odometry. The world frame is the robot's start frame: the soles
  stand flat, facing its x axis, where the plan's first stance puts them. A foot whose
  F/T sensor carries load (``foot_contact_on_n``) is anchored where the estimate puts its
  sole as it lands; while anchored, the pelvis follows from that point, the attitude and
  the leg's encoders (the anchors' mean, weighted by load). A foot that unloads
  (``foot_contact_off_n``) drops its anchor.
- **Limb poses**: palms and soles in the world from the pose and the encoders.
- **Finger curl** per hand, the mean of its five finger encoders: what grasp verification
  reads (`execute.motion.grasp_check`).

It reads `execute.motion.sensed_state.SensedState` only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from execute.motion.config import EstimatorConfig
from execute.motion.robot_model import MotionRobotModel
from execute.motion.sensed_state import SensedState
from robot.joints import FINGER_JOINTS, joint_indices

__all__ = ["BodyEstimate", "StateEstimator"]

SIDES = ("left", "right")
#: A sole within this of the start soles' height stands on the floor [m].
FLOOR_TOLERANCE_M = 0.02
_FRAMES = ("L_sole", "R_sole", "L_palm", "R_palm")


@dataclass(frozen=True, eq=False)
class BodyEstimate:
    """The estimate after one sample.

    Attributes:
        time_s: sample time [s].
        T_world_pelvis: pelvis pose (4, 4).
        R_tilt: pelvis orientation from the IMU alone (no yaw), for gravity (3, 3).
        standing: side → the foot carries load.
        palm_m, sole_m: side → palm / sole position in the world [m].
        finger_curl_rad: side → mean finger encoder [rad].
    """

    time_s: float
    T_world_pelvis: np.ndarray
    R_tilt: np.ndarray
    standing: dict[str, bool]
    palm_m: dict[str, np.ndarray]
    sole_m: dict[str, np.ndarray]
    finger_curl_rad: dict[str, float]


def tilt_from_gravity(up_in_pelvis: np.ndarray) -> np.ndarray:
    """The yaw-free rotation R_world_pelvis whose world z axis is ``up_in_pelvis`` seen
    from the pelvis (the smallest rotation from the pelvis z axis to it).

    Rodrigues' formula about k = (u × z)/|u × z| by the angle between u and z, written
    out for k's zero z component (K² = k kᵀ − I): it runs every tick.
    """
    x, y, z = (float(v) for v in up_in_pelvis)
    n = math.sqrt(x * x + y * y + z * z)
    ux, uy, c = x / n, y / n, z / n
    s = math.sqrt(ux * ux + uy * uy)  # sin of the angle; c = u·z its cos
    if s < 1e-12:
        return np.eye(3)
    kx, ky = uy / s, -ux / s
    v = 1.0 - c
    return np.array([[1.0 + v * (kx * kx - 1.0), v * kx * ky, s * ky],
                     [v * kx * ky, 1.0 + v * (ky * ky - 1.0), -s * kx],
                     [-s * ky, s * kx, c]])


def _turn_z(angle_rad: float) -> np.ndarray:
    """The rotation by ``angle_rad`` about the world's vertical."""
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _heading_rad(R: np.ndarray) -> float:
    """The heading of a frame's x axis in the world's horizontal plane [rad]."""
    return math.atan2(float(R[1, 0]), float(R[0, 0]))


def _wrap(angle_rad: float) -> float:
    return (angle_rad + math.pi) % (2.0 * math.pi) - math.pi


class StateEstimator:
    """Gyro attitude, leg odometry and limb poses (see the module docstring).

    Args:
        model: the robot model.
        start_soles_m: side → where the plan's first stance puts that sole [m].
        config: thresholds.
    """

    def __init__(self, model: MotionRobotModel, start_soles_m: dict[str, np.ndarray],
                 config: EstimatorConfig | None = None):
        self.model = model
        self.config = config or EstimatorConfig()
        self.start_soles_m = {k: np.asarray(v, dtype=float) for k, v in start_soles_m.items()}
        self._floor_m = min(float(p[2]) for p in self.start_soles_m.values())
        self._fingers = {side: joint_indices(FINGER_JOINTS[side]) for side in SIDES}
        self._up: np.ndarray | None = None
        self._T_world_pelvis: np.ndarray | None = None
        #: side → (sole position [m], sole heading [rad]) where the standing foot landed
        self._anchors: dict[str, tuple[np.ndarray, float]] = {}
        self._last_t: float | None = None
        self.gyro_bias_rad_s = 0.0  #: the heading rate the gyro reads at rest [rad/s]
        self.foot_turns = 0  #: standing feet anchored again at the gyro's heading

    def _tilt(self, s: SensedState) -> np.ndarray:
        f = s.body_specific_force()
        if self._up is None or self._last_t is None:
            self._up = f.copy()
        else:
            a = min(1.0, max(0.0, s.time_s - self._last_t) / self.config.tilt_filter_s)
            self._up = self._up + a * (f - self._up)
        return tilt_from_gravity(self._up)

    def _start_pose(self, feet: dict[str, np.ndarray]) -> np.ndarray:
        """Pelvis pose at the start: soles flat on the floor, facing the world's x (the
        start frame), their mean where the plan starts them."""
        R = np.linalg.inv(feet["left"][:3, :3])
        T = np.eye(4)
        T[:3, :3] = R
        sides = [k for k in SIDES if k in self.start_soles_m]
        got = np.mean([R @ feet[k][:3, 3] for k in sides], axis=0)
        want = np.mean([self.start_soles_m[k] for k in sides], axis=0)
        T[:3, 3] = want - got
        return T

    def _attitude(self, R: np.ndarray, s: SensedState, dt: float) -> np.ndarray:
        """The pelvis attitude after ``dt`` [s]: the gyro's turn (less its learnt
        heading bias), then a step towards the accelerometer's up."""
        R = _turn_z(-self.gyro_bias_rad_s * dt) @ R @ pin.exp3(s.body_angular_rate() * dt)
        # the axis and angle from the accelerometer's up to the attitude's (pelvis frame),
        # written out for three-vectors: it runs every tick
        ux, uy, uz = (float(v) for v in self._up)
        n = math.sqrt(ux * ux + uy * uy + uz * uz)
        ux, uy, uz = ux / n, uy / n, uz / n
        vx, vy, vz = (float(v) for v in R[2])  # the world's z seen from the pelvis
        axis = np.array([uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx])
        sin_gap = math.sqrt(float(axis @ axis))
        if sin_gap < 1e-12:
            return R
        gap = math.atan2(sin_gap, ux * vx + uy * vy + uz * vz)
        return R @ pin.exp3(axis * (gap / sin_gap * min(1.0, dt / self.config.level_s)))

    def _on_start_floor(self) -> bool:
        """Whether every anchored foot stands on the floor the robot started on."""
        return bool(self._anchors) and all(
            abs(float(sole_m[2]) - self._floor_m) < FLOOR_TOLERANCE_M
            for sole_m, _heading in self._anchors.values())

    def _follow_feet(self, R: np.ndarray, feet: dict[str, np.ndarray],
                     load: dict[str, float], dt: float) -> np.ndarray:
        """On the floor, turn the heading towards the standing feet's where they agree
        with the gyro, learn the gyro's bias, and anchor again a foot that turned."""
        if not self._on_start_floor():
            return R
        cfg = self.config
        gaps, weights = [], []
        for side, (sole_m, heading) in list(self._anchors.items()):
            gap = _wrap(heading - _heading_rad(R @ feet[side][:3, :3]))
            if abs(gap) > cfg.foot_turn_rad:
                self._anchors[side] = (sole_m, heading - gap)
                self.foot_turns += 1
                continue
            gaps.append(gap)
            weights.append(max(load[side], 1e-6))
        if not gaps or dt <= 0.0:
            return R
        gap = float(np.average(gaps, weights=weights))
        self.gyro_bias_rad_s -= gap * dt / cfg.heading_s ** 2
        return _turn_z(2.0 * gap * min(1.0, dt / cfg.heading_s)) @ R

    def update(self, s: SensedState) -> BodyEstimate:
        """Fold one sample into the estimate."""
        cfg = self.config
        dt = 0.0 if self._last_t is None else max(0.0, s.time_s - self._last_t)
        R_tilt = self._tilt(s)
        self._last_t = s.time_s
        q = s.pos_rad
        T = self.model.frames_in_pelvis(q, _FRAMES)
        frames = {side: (T[f"{side[0].upper()}_sole"], T[f"{side[0].upper()}_palm"])
                  for side in SIDES}
        feet = {side: frames[side][0] for side in SIDES}
        load = {side: s.foot_load_n(side) for side in SIDES}
        if self._T_world_pelvis is None:
            self._T_world_pelvis = self._start_pose(feet)
            self._anchors = {side: self._landing(self._T_world_pelvis, feet[side])
                             for side in SIDES}
        T_wp = self._T_world_pelvis.copy()
        for side in SIDES:
            if side in self._anchors and load[side] < cfg.foot_contact_off_n:
                del self._anchors[side]
        R = self._follow_feet(self._attitude(T_wp[:3, :3], s, dt), feet, load, dt)
        T_wp[:3, :3] = R
        if self._anchors:
            # the anchors' pelvis positions, weighted by their feet's loads
            at, w = np.zeros(3), 0.0
            for side, (sole_m, _heading) in self._anchors.items():
                load_n = max(load[side], 1e-6)
                at += load_n * (sole_m - R @ feet[side][:3, 3])
                w += load_n
            T_wp[:3, 3] = at / w
        self._T_world_pelvis = T_wp
        for side in SIDES:
            if side not in self._anchors and load[side] > cfg.foot_contact_on_n:
                self._anchors[side] = self._landing(T_wp, feet[side])
        return BodyEstimate(
            s.time_s, T_wp.copy(), R_tilt, {side: side in self._anchors for side in SIDES},
            {side: (T_wp @ frames[side][1])[:3, 3] for side in SIDES},
            {side: (T_wp @ feet[side])[:3, 3] for side in SIDES},
            {side: float(q[self._fingers[side]].sum()) / len(self._fingers[side])
             for side in SIDES})

    @staticmethod
    def _landing(T_world_pelvis: np.ndarray,
                 foot_in_pelvis: np.ndarray) -> tuple[np.ndarray, float]:
        """A foot's anchor as it lands: its sole's position and heading in the world."""
        T = T_world_pelvis @ foot_in_pelvis
        return T[:3, 3].copy(), _heading_rad(T[:3, :3])
