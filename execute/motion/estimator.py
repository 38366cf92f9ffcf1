"""The body's state from the sensors: tilt, pose, stance feet, grip closure.

- **Tilt** from the body IMU's accelerometer, low-pass filtered: at rest it measures the
  reaction to gravity, which gives the pelvis's roll and pitch (hubo-motion-rt used the
  waist IMU the same way).
- **Pose** by leg odometry. The world frame is the robot's start frame: the soles stand
  flat, facing its x axis, where the plan's first stance puts them. A foot whose F/T
  sensor carries load (``foot_contact_on_n``) is anchored where the estimate puts it as
  it lands; while anchored, the pelvis pose follows from that foot's pose and the leg's
  encoders. A foot that unloads (``foot_contact_off_n``) drops its anchor.
- **Limb poses**: palms and soles in the world from the pose and the encoders.
- **Finger curl** per hand, the mean of its five finger encoders: what grasp verification
  reads (`execute.motion.grasp_check`).

It reads `execute.motion.sensed_state.SensedState` only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from execute.motion.config import EstimatorConfig
from execute.motion.robot_model import MotionRobotModel
from execute.motion.sensed_state import SensedState
from robot.joints import FINGER_JOINTS, joint_indices

__all__ = ["BodyEstimate", "StateEstimator"]

SIDES = ("left", "right")
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


def _rigid_inverse(T: np.ndarray) -> np.ndarray:
    """The inverse of a rigid transform (4, 4): (Rᵀ, −Rᵀ p)."""
    out = np.eye(4)
    Rt = T[:3, :3].T
    out[:3, :3] = Rt
    out[:3, 3] = -Rt @ T[:3, 3]
    return out


class StateEstimator:
    """Leg odometry, IMU tilt and limb poses (see the module docstring).

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
        self._fingers = {side: joint_indices(FINGER_JOINTS[side]) for side in SIDES}
        self._up: np.ndarray | None = None
        self._T_world_pelvis: np.ndarray | None = None
        self._anchors: dict[str, np.ndarray] = {}
        self._last_t: float | None = None

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

    def update(self, s: SensedState) -> BodyEstimate:
        """Fold one sample into the estimate."""
        cfg = self.config
        R_tilt = self._tilt(s)
        self._last_t = s.time_s
        q = s.pos_rad
        T = self.model.frames_in_pelvis(q, _FRAMES)
        frames = {side: (T[f"{side[0].upper()}_sole"], T[f"{side[0].upper()}_palm"])
                  for side in SIDES}
        feet = {side: frames[side][0] for side in SIDES}
        if self._T_world_pelvis is None:
            self._T_world_pelvis = self._start_pose(feet)
            self._anchors = {side: self._T_world_pelvis @ feet[side] for side in SIDES}
        load = {side: s.foot_load_n(side) for side in SIDES}
        for side in SIDES:
            if side in self._anchors and load[side] < cfg.foot_contact_off_n:
                del self._anchors[side]
        candidates = [(load[side], self._anchors[side] @ _rigid_inverse(feet[side]))
                      for side in SIDES if side in self._anchors]
        if candidates:
            total = sum(max(w, 1e-6) for w, _ in candidates)
            T = max(candidates, key=lambda c: c[0])[1].copy()
            T[:3, 3] = sum(max(w, 1e-6) * Tc[:3, 3] for w, Tc in candidates) / total
            self._T_world_pelvis = T
        T_wp = self._T_world_pelvis
        for side in SIDES:
            if side not in self._anchors and load[side] > cfg.foot_contact_on_n:
                self._anchors[side] = T_wp @ feet[side]
        return BodyEstimate(
            s.time_s, T_wp.copy(), R_tilt, {side: side in self._anchors for side in SIDES},
            {side: (T_wp @ frames[side][1])[:3, 3] for side in SIDES},
            {side: (T_wp @ feet[side])[:3, 3] for side in SIDES},
            {side: float(q[self._fingers[side]].sum()) / len(self._fingers[side])
             for side in SIDES})
