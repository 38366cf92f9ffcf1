"""The project's vocabulary: limbs, sides, arm modes and strategies, segment phases, hold
targets and failure causes, each an enum with one definition.

They are string enums (`enum.StrEnum`): a member equals its string, formats as it and is
written to JSON as it. The sidecar, the result JSON and the trajectory files keep the
strings they always had; code compares and builds members instead of parsing strings.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from enum import StrEnum

from robot.errors import InputError

__all__ = [
    "ARM_MODES",
    "ArmMode",
    "ArmStrategy",
    "FailureCause",
    "HoldTarget",
    "HoldTargetError",
    "HoldTargetKind",
    "InterpolationFailure",
    "LIMBS",
    "Limb",
    "RejectCause",
    "SIDES",
    "SegmentPhase",
    "Side",
    "StepFailure",
]


class Side(StrEnum):
    """A side of the robot (and of the ladder: ``rail_left``)."""

    LEFT = "left"
    RIGHT = "right"


class Limb(StrEnum):
    """A limb that holds or moves: the sidecar's names."""

    LEFT_HAND = "left_hand"
    RIGHT_HAND = "right_hand"
    LEFT_FOOT = "left_foot"
    RIGHT_FOOT = "right_foot"

    @property
    def side(self) -> Side:
        return Side.LEFT if self in (Limb.LEFT_HAND, Limb.LEFT_FOOT) else Side.RIGHT

    @property
    def is_hand(self) -> bool:
        return self in (Limb.LEFT_HAND, Limb.RIGHT_HAND)

    @property
    def is_foot(self) -> bool:
        return not self.is_hand

    @classmethod
    def hand(cls, side: Side | str) -> Limb:
        return cls.LEFT_HAND if Side(side) is Side.LEFT else cls.RIGHT_HAND

    @classmethod
    def foot(cls, side: Side | str) -> Limb:
        return cls.LEFT_FOOT if Side(side) is Side.LEFT else cls.RIGHT_FOOT


class ArmMode(StrEnum):
    """How an arm's joints are driven on a line (the sidecar's per-arm schedule)."""

    POSITION = "position"  # the board's position loop, stiff
    PWM = "pwm"  # hubo-ach's PWM law: compliant, plus feed-forward duty


class ArmStrategy(StrEnum):
    """Which arm modes a climb uses: ``mixed`` (the thesis's: PWM while a hand holds a
    rail), or one mode throughout."""

    MIXED = "mixed"
    POSITION = "position"
    PWM = "pwm"


class SegmentPhase(StrEnum):
    """What a sidecar segment does."""

    BODY = "body"  # every hold kept, the body moves
    LIMB = "limb"  # the moving limbs are in the air
    GRASP = "grasp"  # fingers closing on a rail
    RELEASE = "release"  # fingers opening
    DWELL = "dwell"  # standing still


class HoldTargetKind(StrEnum):
    FLOOR = "floor"
    RUNG = "rung"
    RAIL = "rail"


class HoldTargetError(InputError):
    """A hold target that is not ``floor``, ``rung_<i>`` or ``rail_left|right``."""

    def __init__(self, text: str):
        super().__init__(f"hold target {text!r} is not 'floor', 'rung_<i>' or "
                         f"'rail_left'/'rail_right'")
        self.text = text


_RUNG = re.compile(r"rung_(0|[1-9][0-9]*)")


@dataclass(frozen=True)
class HoldTarget:
    """What a hold is on: the floor, rung ``rung`` (0-based) or the ``side`` rail.

    Its string form is the sidecar's: ``floor``, ``rung_3``, ``rail_left``.
    """

    kind: HoldTargetKind
    rung: int | None = None
    side: Side | None = None

    @classmethod
    def floor(cls) -> HoldTarget:
        return cls(HoldTargetKind.FLOOR)

    @classmethod
    def on_rung(cls, rung: int) -> HoldTarget:
        return cls(HoldTargetKind.RUNG, rung=int(rung))

    @classmethod
    def on_rail(cls, side: Side | str) -> HoldTarget:
        return cls(HoldTargetKind.RAIL, side=Side(side))

    @classmethod
    def parse(cls, text: str) -> HoldTarget:
        """``"rung_3"`` → ``HoldTarget(RUNG, rung=3)``; raises `HoldTargetError`."""
        if text == HoldTargetKind.FLOOR:
            return cls.floor()
        if text in ("rail_left", "rail_right"):
            return cls.on_rail(text[len("rail_"):])
        match = _RUNG.fullmatch(text) if isinstance(text, str) else None
        if match is None:
            raise HoldTargetError(str(text))
        return cls.on_rung(int(match.group(1)))

    def __str__(self) -> str:
        if self.kind is HoldTargetKind.RUNG:
            return f"rung_{self.rung}"
        if self.kind is HoldTargetKind.RAIL:
            return f"rail_{self.side}"
        return "floor"


class FailureCause(StrEnum):
    """Why a simulated climb failed (`execute.validate.verdict`), as in the result JSON."""

    FALL = "fall"
    HARD_CONTACT = "hard_contact"
    BOARD_TRIP = "board_trip"
    GRASP_NOT_LATCHED = "grasp_not_latched"
    GRASP_LOST = "grasp_lost"
    FINAL_STANCE = "final_stance"
    GRASP_UNVERIFIED = "grasp_unverified"  # the motion layer stopped (`execute.motion`)
    FOOTHOLD_UNVERIFIED = "foothold_unverified"  # it stopped: a foot found no rung
    LADDER_MISPLACED = "ladder_misplaced"  # it stopped: the hands found the ladder elsewhere
    NO_PLAN = "no_plan"  # batch-eval: the plan job found no plan, nothing was simulated


class RejectCause(StrEnum):
    """Why the planner's feasibility predicate refused a configuration. The values are
    the keys of a step's ``failures`` in the sidecar's metrics."""

    JOINT_LIMITS = "joint"
    COLLISION = "collision"
    UNBALANCEABLE_STANCE = "stance"
    COM_OUTSIDE = "CoM"
    TORQUE = "torque"
    IK = "ik"
    WRIST_SINGULARITY = "wrist"


class InterpolationFailure(StrEnum):
    """Why contact-space interpolation between two configurations failed."""

    PROJECTION_FAILED = "projection failed"
    BRANCH_JUMP = "projection jumped to another IK branch"
    RESOLUTION = "resolution not reached"
    MIDPOINT_INFEASIBLE = "midpoint infeasible"


class StepFailure(StrEnum):
    """Why one sample of a planning step failed (the search then tries another)."""

    NO_STRAIGHT_POSE = "no straightened pose"
    NO_LIFT_OFF = "no lift-off pose"
    WAYPOINT = "way-point"
    HOLDS_NOT_MET = "placed pose does not meet its holds"
    POLISH_TOO_FAR = "placing the holds exactly moves a joint"
    UNSTABLE_PLACED = "placed pose unstable in the new stance"


#: Every limb, in the sidecar's order.
LIMBS: tuple[Limb, ...] = tuple(Limb)
#: Both sides, left first.
SIDES: tuple[Side, ...] = tuple(Side)
#: Both arm modes.
ARM_MODES: tuple[ArmMode, ...] = tuple(ArmMode)
