"""Where the ladder really stands, from the grasps the fingers confirmed while the robot
stood on the floor (`execute.motion.layer` adds only those: there leg odometry is exact).

A hand closed on a rail has the rail's axis in its grip centre, so each verified grasp
measures, through the encoders and leg odometry, where that rail is. Against the plan's
hold on it, the difference across the rail (its component along the rail says nothing)
is a measurement of the ladder's misplacement. With one rail seen the shift is all we
estimate; with both, the yaw too. The model, linear in the unknowns:

    p_real = p_plan + δ + ψ · ẑ × (p_plan − c)

δ the ladder's shift [m], ψ its yaw [rad] about the vertical through ``c`` (the middle
of the observed holds). Each observation constrains the two directions across its
rail; a small ridge keeps unobserved directions at zero.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["LadderEstimate", "RailObservation"]

_Z = np.array([0.0, 0.0, 1.0])
_RIDGE = 1e-4  #: weight of the prior "no shift" [m² per m² of residual]


def _skew_z_times(v: np.ndarray) -> np.ndarray:
    return np.cross(_Z, v)


@dataclass(frozen=True)
class RailObservation:
    """One verified grasp: the planned hold point, the measured palm, the rail direction
    (unit), all in the world [m]."""

    rail: str
    planned_m: np.ndarray
    measured_m: np.ndarray
    rail_direction: np.ndarray


class LadderEstimate:
    """The ladder's shift and yaw from rail observations (module docstring).

    Args:
        max_shift_m: the estimate's shift is scaled down to this length [m].
        max_yaw_rad: and its yaw clipped to this [rad].
    """

    def __init__(self, max_shift_m: float, max_yaw_rad: float):
        self.max_shift_m, self.max_yaw_rad = max_shift_m, max_yaw_rad
        self._latest: dict[str, RailObservation] = {}
        self.shift_m = np.zeros(3)
        self.yaw_rad = 0.0
        self.centre_m = np.zeros(3)

    @property
    def observed(self) -> bool:
        return bool(self._latest)

    def add(self, obs: RailObservation) -> None:
        """Fold in a verified grasp (the newest one per rail counts)."""
        self._latest[obs.rail] = obs
        observations = list(self._latest.values())
        self.centre_m = np.mean([o.planned_m for o in observations], axis=0)
        rows, rhs = [], []
        for o in observations:
            P = np.eye(3) - np.outer(o.rail_direction, o.rail_direction)
            A = np.hstack([P, (P @ _skew_z_times(o.planned_m - self.centre_m))[:, None]])
            rows.append(A)
            rhs.append(P @ (o.measured_m - o.planned_m))
        rows.append(np.sqrt(_RIDGE) * np.eye(4))
        rhs.append(np.zeros(4))
        x = np.linalg.lstsq(np.vstack(rows), np.concatenate(rhs), rcond=None)[0]
        shift, yaw = x[:3], float(x[3])
        length = float(np.linalg.norm(shift))
        if length > self.max_shift_m:
            shift = shift * (self.max_shift_m / length)
        self.shift_m = shift
        self.yaw_rad = float(np.clip(yaw, -self.max_yaw_rad, self.max_yaw_rad))

    def correction_m(self, planned_m: np.ndarray) -> np.ndarray:
        """How far a hold planned at ``planned_m`` on the ladder really is [m]."""
        return self.shift_m + self.yaw_rad * _skew_z_times(np.asarray(planned_m) - self.centre_m)
