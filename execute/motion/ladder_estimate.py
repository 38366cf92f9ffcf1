"""Where the ladder stands in the state estimate's frame, from the hands on its rails.

A hand closed on a rail has the rail's axis in its grip centre, so each verified grasp
measures, through the encoders and leg odometry, where that rail is; `execute.motion.layer`
measures a holding hand again at every segment. Against the plan's hold on it, the
difference across the rail (its component along the rail says nothing) measures the
ladder's misplacement. The model, linear in the unknowns:

    p_real = p_plan + δ + ψ · ẑ × (p_plan − c)

δ the ladder's shift [m], ψ its yaw [rad] about the vertical through ``c`` (the middle
of the holds observed on the floor). Each observation constrains the two directions
across its rail; a small ridge keeps unobserved directions at zero.

On the floor leg odometry is exact: those observations fit δ, and ψ once both rails are
seen. On the ladder the estimate also carries the stance feet's creep on their rungs,
which odometry cannot see (on `ship`, 2026-11-27: 2–3 cm forward and 1–2° of heading over
500 s): the rails seem to move by as much the other way. Those observations move δ
alone, at the floor's ψ: hands seen at different times, and held one rung apart, cannot
tell the body's heading from their own lateral settling.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ladders.geometry import rot_z, wrap_rad
from ladders.spec import LadderSpec

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
        self._for_yaw: dict[str, RailObservation] = {}
        self.shift_m = np.zeros(3)
        self.yaw_rad = 0.0
        self.centre_m = np.zeros(3)

    @property
    def observed(self) -> bool:
        return bool(self._latest)

    @property
    def rails_fitting_yaw(self) -> int:
        """How many rails the yaw is fitted on (observed from the floor): 2 once both
        hands have held theirs."""
        return len(self._for_yaw)

    def placed(self, spec: LadderSpec, stance_m: np.ndarray | None = None,
               stance_heading_rad: float = 0.0) -> LadderSpec:
        """``spec`` with its placement where this estimate finds the ladder: turned by
        the yaw about the centre of the holds seen, then shifted horizontally (the ladder
        stands on the floor) by as much as the rails were seen to move across themselves.
        Along a sloped rail nothing is seen, so the estimate's own shift is the shortest
        that explains the grasps and lies partly along the rail, out of the floor; the
        horizontal shift that explains them is found again here.

        Args:
            spec: the ladder the observations' planned holds were planned on.
            stance_m, stance_heading_rad: where the robot now stands in the estimate's
                frame (its soles' middle [m] and heading [rad]): the placement returned
                is relative to that stance, as a new plan starting there needs it.
        """
        rows, seen = [], []
        for o in self._latest.values():
            P = np.eye(3) - np.outer(o.rail_direction, o.rail_direction)
            rows.append(P[:, :2])
            seen.append(P @ self.shift_m)
        shift = (np.linalg.lstsq(np.vstack(rows), np.concatenate(seen), rcond=None)[0]
                 if rows else np.zeros(2))
        c = self.centre_m[:2]
        origin = np.array([spec.placement_x_m, spec.placement_y_m])
        at = c + rot_z(self.yaw_rad)[:2, :2] @ (origin - c) + shift
        yaw = spec.placement_yaw_rad + self.yaw_rad
        if stance_m is not None:  # the same pose seen from the stance
            at = rot_z(stance_heading_rad)[:2, :2].T @ (at - np.asarray(stance_m)[:2])
            yaw -= stance_heading_rad
        return dataclasses.replace(spec, placement_x_m=float(at[0]),
                                   placement_y_m=float(at[1]),
                                   placement_yaw_rad=wrap_rad(yaw))

    def last_held_m(self, rail: str) -> np.ndarray | None:
        """Where a hand last held ``rail``: its measured palm in the world [m]; None if
        no hand has."""
        obs = self._latest.get(rail)
        return None if obs is None else obs.measured_m

    def add(self, obs: RailObservation, *, fits_yaw: bool = True) -> None:
        """Fold in a hand on its rail. The newest observation per rail counts: the frame
        drifts as the feet creep.

        Args:
            fits_yaw: the observation fits the yaw too: it was taken on the floor,
                where leg odometry is exact. Others move the shift alone, at the floor's
                yaw (module docstring).
        """
        self._latest[obs.rail] = obs
        if fits_yaw:
            self._for_yaw[obs.rail] = obs
            seen = list(self._for_yaw.values())
            self.centre_m = np.mean([o.planned_m for o in seen], axis=0)
            yaw = float(self._fit(seen, None)[3])
            self.yaw_rad = float(np.clip(yaw, -self.max_yaw_rad, self.max_yaw_rad))
        shift = self._fit(list(self._latest.values()), self.yaw_rad)
        length = float(np.linalg.norm(shift))
        if length > self.max_shift_m:
            shift = shift * (self.max_shift_m / length)
        self.shift_m = shift

    def _fit(self, observations: list[RailObservation], yaw_rad: float | None) -> np.ndarray:
        """Least squares across the rails: (shift, yaw), or the shift at ``yaw_rad``."""
        rows, rhs = [], []
        for o in observations:
            P = np.eye(3) - np.outer(o.rail_direction, o.rail_direction)
            turn = P @ _skew_z_times(o.planned_m - self.centre_m)
            residual = P @ (o.measured_m - o.planned_m)
            if yaw_rad is None:
                rows.append(np.hstack([P, turn[:, None]]))
            else:
                rows.append(P)
                residual = residual - yaw_rad * turn
            rhs.append(residual)
        n = 4 if yaw_rad is None else 3
        rows.append(np.sqrt(_RIDGE) * np.eye(n))
        rhs.append(np.zeros(n))
        return np.linalg.lstsq(np.vstack(rows), np.concatenate(rhs), rcond=None)[0]

    def correction_m(self, planned_m: np.ndarray) -> np.ndarray:
        """How far a hold planned at ``planned_m`` on the ladder really is [m]."""
        return self.shift_m + self.yaw_rad * _skew_z_times(np.asarray(planned_m) - self.centre_m)
