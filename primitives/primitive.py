"""The seven motion primitives of the thesis (§6.3.1), plus the straightening body move.

A primitive is data: which limbs move, what stance results, the seed whole-body posture
and how the moving limb travels (its way-point recipe). The planner's search samples
around these seeds.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from primitives.hold_seeds import HoldSeed


@dataclass(frozen=True)
class LimbWaypoints:
    """How a moving limb travels from its old hold to its new one.

    Hands: open the fingers, back off the rail by ``clearance_m`` away from the hand's
    open side, travel parallel to the rail, approach, close the fingers.
    Feet: lift ``lift_m``, pull back until the toes clear the target rung's edge by
    ``clearance_m`` while rising ``clearance_m`` above its top, move over it, set down.
    """

    lift_m: float = 0.04
    clearance_m: float = 0.06


@dataclass(frozen=True)
class Primitive:
    """One motion primitive.

    Attributes:
        name: thesis name (``moveLHand`` ...).
        moving_limbs: limbs that leave their holds and take the new ones (empty for a
            body move with every hold kept).
        posture_rad: seed posture, joint name → angle [rad], a soft preference for IK.
        pelvis_offset_m: seed pelvis position relative to the mean of the supporting
            foot holds, in the ladder frame (x up-ladder, y left, z up) [m]. Standing on
            one foot, this puts the pelvis over it with the stance leg nearly straight:
            a bent knee under the body's weight exceeds its 60 N·m.
        waypoints: the moving limb's way-point recipe.
        pelvis_below_standing_m: when set, the seed pelvis height is this far below the
            robot's standing height on the floor instead of ``pelvis_offset_m``'s height
            above the supporting feet: while a foot is still on the floor, its leg bounds
            how high the pelvis can rise, however high the other foot stands.
    """

    name: str
    moving_limbs: tuple[str, ...]
    posture_rad: dict[str, float] = field(default_factory=dict)
    pelvis_offset_m: tuple[float, float, float] = (-0.1, 0.0, 0.88)
    waypoints: LimbWaypoints = LimbWaypoints()
    pelvis_below_standing_m: float | None = None


@dataclass(frozen=True)
class Step:
    """A primitive applied at a place on the ladder: the holds its moving limbs take."""

    primitive: Primitive
    new_holds: tuple[HoldSeed, ...]
    rung: int  # the rung the feet stand on, or will stand on, for progress reports

    @property
    def label(self) -> str:
        return f"{self.primitive.name}@rung{self.rung}"
