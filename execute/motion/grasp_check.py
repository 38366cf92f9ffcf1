"""Is the hand closed on its rail? Read from the finger encoders alone.

A hand's fingers stop where they meet a rail lying in the grip
(`robot.kinematic_tree.finger_contact_curl_rad`: 0.09 rad on a 25 mm rail) and close to
``FINGER_CLOSED_RAD`` (1.6 rad) on nothing. So, with the fingers commanded closed:

- **on rail**: the mean curl stands still where this rail stops the fingers (from its
  contact curl, less ``CONTACT_SLACK_RAD``, up to half of closed); fingers that stand
  still short of the rail have not closed at all;
- **empty**: it has passed ``EMPTY_FRACTION`` of closed;
- **closing**: neither yet.

The thesis's operator could not tell this from the wrist F/T sensors (§6.2: their fz
varied with the climbing forces, not with the grasp); finger closure on the rail's
diameter can.
"""

from __future__ import annotations

import enum
import functools

import numpy as np

from robot.joints import FINGER_JOINTS, joint_indices
from robot.kinematic_tree import FINGER_CLOSED_RAD, finger_contact_curl_rad

__all__ = ["GraspReading", "closed_around_rail", "read_grasp"]

_FINGER_COLS = {side: joint_indices(FINGER_JOINTS[side]) for side in FINGER_JOINTS}
ON_RAIL_FRACTION = 0.5  #: below this share of closed, a still hand holds something
EMPTY_FRACTION = 0.8  #: past this share of closed, the hand closed on nothing
STILL_RAD_S = 0.2  #: mean finger speed under which the fingers stand still [rad/s]
CONTACT_SLACK_RAD = 0.03  #: how far short of the rail's contact curl a grip may read [rad]


class GraspReading(enum.Enum):
    ON_RAIL = "on rail"
    EMPTY = "closed on nothing"
    CLOSING = "closing"


@functools.lru_cache(maxsize=8)
def _rail_stop_curl_rad(rail_radius_m: float) -> float:
    """The least mean curl that reads as fingers stopped by a rail of this radius [rad]:
    its contact curl less ``CONTACT_SLACK_RAD`` (one ladder's radius; asked every tick)."""
    return finger_contact_curl_rad(rail_radius_m) - CONTACT_SLACK_RAD


def _curl_rad(side: str, pos_rad: np.ndarray) -> float:
    """One hand's mean finger encoder [rad]."""
    return float(np.mean(pos_rad[_FINGER_COLS[side]]))


def read_grasp(side: str, pos_rad: np.ndarray, vel_rad_s: np.ndarray,
               rail_radius_m: float) -> GraspReading:
    """What the finger encoders of one hand, commanded closed on a rail of radius
    ``rail_radius_m`` [m], say (module docstring)."""
    curl = _curl_rad(side, pos_rad)
    if curl >= EMPTY_FRACTION * FINGER_CLOSED_RAD:
        return GraspReading.EMPTY
    speed = float(np.mean(np.abs(vel_rad_s[_FINGER_COLS[side]])))
    if _rail_stop_curl_rad(rail_radius_m) <= curl < ON_RAIL_FRACTION * FINGER_CLOSED_RAD \
            and speed < STILL_RAD_S:
        return GraspReading.ON_RAIL
    return GraspReading.CLOSING


def closed_around_rail(side: str, pos_rad: np.ndarray, rail_radius_m: float) -> bool:
    """Whether one hand's fingers still stand closed at least as far as a rail of radius
    ``rail_radius_m`` [m] stops them, and short of closed on nothing, moving or not: the
    grip still holds (or is just closing on, or opening from) its rail."""
    curl = _curl_rad(side, pos_rad)
    return _rail_stop_curl_rad(rail_radius_m) <= curl < EMPTY_FRACTION * FINGER_CLOSED_RAD
