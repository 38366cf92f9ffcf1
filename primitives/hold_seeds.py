"""Seed holds: where a limb should hold, relative to the ladder's rungs and rails.

A seed is a small descriptor, not a pose: the planner turns it into a `Hold` on a given
ladder, so one primitive adapts to every ladder. Offsets are in the ladder frame L.
"""

from __future__ import annotations

from dataclasses import dataclass

#: Lateral offset of each sole centre from the ladder centreline [m] (about hip width).
FOOT_LATERAL_M = 0.11
#: Sole centre relative to the rung's tread centre, along x_L [m]: the rung under the
#: ball of the foot, the way people climb ladders. The ankle then sits 6 cm nearer the
#: climber's hips than with the rung mid-foot, which is what lets a 60 N·m knee lift the
#: body onto a 0.3 m rung (planner experiment on the DRC ladder: lift-off torque ratio
#: 0.77–0.80 with the rung under the ball, no feasible pose found with it mid-foot).
FOOT_ALONG_M = -0.06


@dataclass(frozen=True)
class FloorSeed:
    """A foot flat on the floor where it stands at the start."""

    limb: str

    @property
    def target(self) -> str:
        return "floor"


@dataclass(frozen=True)
class RungSeed:
    """A foot flat on rung ``rung`` (0-based), ``lateral_m`` off centre, ``along_m`` up-ladder."""

    limb: str
    rung: int
    lateral_m: float
    along_m: float = FOOT_ALONG_M

    @property
    def target(self) -> str:
        return f"rung_{self.rung}"


@dataclass(frozen=True)
class RailSeed:
    """A palm closed on the ``side`` rail, at the rail point vertically above rung ``rung``
    (``rung`` may be one past the top rung: the rail extends that far), shifted
    ``along_m`` up the rail.

    With ``torso_along_m`` (the torso's place over rung ``rung``, up-ladder of its tread
    centre [m]) the hold moves further up the rail if it would be nearer that torso's
    shoulder than the arm needs (`planner.holds.shoulder_room_along_m`): close rails put
    the hand beside the shoulder.
    """

    limb: str
    side: str
    rung: int
    along_m: float = 0.0
    torso_along_m: float | None = None

    @property
    def target(self) -> str:
        return f"rail_{self.side}"


HoldSeed = FloorSeed | RungSeed | RailSeed


def foot_on_rung(limb: str, rung: int) -> RungSeed:
    lateral = FOOT_LATERAL_M if limb == "left_foot" else -FOOT_LATERAL_M
    return RungSeed(limb, rung, lateral)


#: Where the hands first take the rails from the floor, along the rail from the point
#: above rung 0 [m]: lower and nearer, within reach of a robot standing on the floor,
#: unless that is too near the shoulders once the body stands over rung 0 (`RailSeed`).
MOUNT_ALONG_RAIL_M = -0.2


def hand_on_rail(limb: str, rung: int, along_m: float = 0.0,
                 torso_along_m: float | None = None) -> RailSeed:
    return RailSeed(limb, "left" if limb == "left_hand" else "right", rung, along_m,
                    torso_along_m)
