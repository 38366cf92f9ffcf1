"""What the motion layer did: one record per correction, grasp check, re-reach, foot
landing, foot strike or stop."""

from __future__ import annotations

import enum
from dataclasses import asdict, dataclass, field

from robot.vocabulary import FailureCause

__all__ = ["MotionEvent", "MotionEventKind", "MotionStop"]


class MotionEventKind(enum.Enum):
    REACH_CORRECTION = "reach correction"  #: a limb's target moved by the ladder estimate
    GRASP_VERIFIED = "grasp verified"  #: the fingers read closed on a rail
    GRASP_MISSED = "grasp missed"  #: the fingers closed on nothing
    RE_REACH = "re-reach"  #: a missed hand opens, moves and closes again
    AIM = "aim"  #: an arrived hand moved onto its rail as the holding hands measured it
    ARRIVAL_WAIT = "arrival wait"  #: a hand lagged its reference; the grasp waited for it
    STIFF_REACH = "stiff reach"  #: a compliant arm short of its hold finished in position mode
    LEG_RELIEF = "leg relief"  #: the gripping arms began to lift more: a leg joint neared its limit
    GRIP_RELIEF = "grip relief"  #: a grip's bending neared its capacity; its arm took it off
    LADDER_ESTIMATE = "ladder estimate"  #: the estimate of the ladder's pose changed
    BODY_TRIM = "body trim"  #: the body moved back to the plan's posture relative to the rails
    FOOT_LANDING = "foot landing"  #: a step ended with its foot unloaded; it reached further
    FOOT_STRIKE = "foot strike"  #: a swinging foot met something from above; it backed off
    HAND_STRIKE = "hand strike"  #: a reaching hand was pushed by the ladder; it backed off
    STOP = "stop"  #: the layer holds the pose and stops the climb


@dataclass(frozen=True)
class MotionEvent:
    """Attributes:
        kind: what happened.
        time_s: when [s].
        line: 1-based trajectory line.
        segment: index of the plan's segment.
        limb: the limb concerned ("" for the ladder estimate).
        size_m: how far a target moved [m] (corrections, re-reaches).
        cause: a sentence with the sensed quantities behind it.
    """

    kind: MotionEventKind
    time_s: float
    line: int
    segment: int
    limb: str
    size_m: float
    cause: str

    def to_json(self) -> dict:
        d = asdict(self)
        d["kind"] = self.kind.value
        d["time_s"], d["size_m"] = round(self.time_s, 3), round(self.size_m, 4)
        return d

    def __str__(self) -> str:
        size = f" {self.size_m * 100:.1f} cm" if self.size_m else ""
        who = f" {self.limb}" if self.limb else ""
        return (f"t = {self.time_s:.2f} s, line {self.line}: {self.kind.value}{who}{size}: "
                f"{self.cause}")


@dataclass(frozen=True)
class MotionStop:
    """Why the layer stopped the climb: it holds the pose, every verified grip kept.
    ``cause`` is the run's failure cause (a grasp or a foothold it could not verify)."""

    time_s: float
    line: int
    limb: str
    reason: str
    cause: FailureCause
    tries: int = 0
    details: dict = field(default_factory=dict)
