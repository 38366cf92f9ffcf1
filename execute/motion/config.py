"""The motion layer's tunables, each refused outside its safe range."""

from __future__ import annotations

import argparse
import math
from dataclasses import dataclass, field

from robot.errors import InputError

__all__ = ["SETTINGS", "EstimatorConfig", "MotionConfig", "MotionConfigError", "default_config",
           "parse_setting"]


class MotionConfigError(InputError):
    """A motion-layer setting outside its safe range; names the field and the range."""

    def __init__(self, field_name: str, value: object, allowed: tuple[float, float]):
        self.field, self.value, self.allowed = field_name, value, allowed
        super().__init__(f"motion layer {field_name} = {value!r}: allowed "
                         f"[{allowed[0]:g}, {allowed[1]:g}]")


@dataclass(frozen=True)
class EstimatorConfig:
    """Attributes:
        foot_contact_on_n: foot F/T load above which a foot stands [N].
        foot_contact_off_n: load below which it has lifted [N] (hysteresis).
        tilt_filter_s: time constant of the accelerometer's low-pass filter [s].
        level_s: time constant with which the gyro-propagated attitude follows the
            accelerometer's roll and pitch [s].
        heading_s: time constant with which the gyro's heading follows the feet's (leg
            odometry) while both stand on the floor [s]; the gyro's bias is learnt at
            the same rate (a critically damped PI observer).
        foot_turn_rad: a foot on the floor whose heading disagrees with the gyro's by
            more than this has turned: it is anchored again at the gyro's heading [rad].
    """

    foot_contact_on_n: float = 60.0
    foot_contact_off_n: float = 25.0
    tilt_filter_s: float = 0.05
    level_s: float = 0.5
    heading_s: float = 20.0
    foot_turn_rad: float = math.radians(0.3)


#: field → (lowest, highest) allowed value.
_RANGES = {
    "holding_arm_stiffness": (0.0, 1.0),
    "max_reach_correction_m": (0.0, 0.10),
    "max_reach_correction_rad": (0.0, math.radians(30.0)),
    "grasp_retries": (0, 8),
    "search_step_m": (0.005, 0.05),
    "open_s": (0.2, 5.0),
    "shift_s": (0.2, 5.0),
    "close_s": (0.2, 5.0),
    "verify_timeout_s": (0.1, 5.0),
    "seat_timeout_s": (0.0, 5.0),
    "arrival_tolerance_m": (0.002, 0.05),
    "arrival_timeout_s": (0.0, 10.0),
    "aim_tolerance_m": (0.005, 0.05),
    "hold_after_stop_s": (0.0, 30.0),
    "landing_load_n": (5.0, 200.0),
    "landing_wait_s": (0.0, 5.0),
    "landing_reach_m": (0.0, 0.06),
    "landing_speed_m_s": (0.002, 0.05),
    "strike_load_n": (15.0, 200.0),
    "strike_backoff_m": (0.0, 0.06),
    "strike_backoff_s": (0.1, 3.0),
    "strike_tries": (0, 4),
    "hand_strike_load_n": (5.0, 100.0),
    "replan_beyond_m": (0.0, 0.2),
    "max_body_trim_m": (0.0, 0.05),
    "max_foot_aim_m": (0.0, 0.05),
    "grip_bending_onset": (0.0, 0.39),
}


@dataclass(frozen=True)
class MotionConfig:
    """Attributes:
        gravity_compensation: feed the compliant arms the model's gravity torques at the
            sensed configuration and IMU tilt (thesis §4.3.4) instead of the plan's.
        holding_arm_stiffness: share of the daemon's PWM stiffness (kp) with which a
            gripping compliant arm is pulled towards the plan's reference: its reference is
            sent as ``pos + share·(plan − pos)``. 1 is hubo-ach's PWM law on the plan; 0
            leaves the feed-forward and damping alone (the thesis's gravity-compensation
            mode). A stiff arm fights the closed chain and bends the grip; a limp one leaves
            the legs the load the plan gave the arms.
        max_reach_correction_m: largest shift of a hold target, estimate plus search [m].
        max_reach_correction_rad: largest ladder yaw the estimate may apply [rad].
        grasp_retries: re-reaches after a grasp the fingers show empty.
        search_step_m: spacing of the re-reach pattern around the target [m].
        open_s, shift_s, close_s: durations of a re-reach's opening, move and closing [s].
        verify_timeout_s: how long a closed hand may take to read on-rail or empty [s].
        seat_timeout_s: the longest wait, once the fingers read on-rail, for the palm to
            stand still in the grip before the grasp is taken as verified and its palm as
            where the rail is [s] (`execute.motion.layer.SEATED_SPEED_M_S`).
        arrival_tolerance_m: how close the palm must come to where its reference puts it
            before the hand closes [m].
        arrival_timeout_s: the longest wait for that [s].
        aim_tolerance_m: an arrived palm farther than this across its rail from where the
            holding hands measured the rails is moved there before it closes [m].
        hold_after_stop_s: how long the pose is held after the layer stops, before the
            run ends (validation only) [s].
        landing_load_n: foot F/T load that shows a foot standing on its rung at the end
            of its step [N]; a foot in the air reads its own weight, about −12 N.
        landing_wait_s: how long the player waits at the end of a step for that load
            before the foot reaches further [s].
        landing_reach_m: how far beyond its planned hold, down towards its rung, a foot
            may reach to find it [m].
        landing_speed_m_s: how fast it reaches [m/s].
        strike_load_n: how far below zero a swinging foot's F/T load must fall to show
            that something presses on the foot from above (its toe rising under a rung):
            a foot in the air reads its own weight, about −12 N [N].
        strike_backoff_m: how far such a foot backs away from the ladder, each time [m].
        strike_backoff_s: how long the back-off takes, the player paused [s].
        strike_tries: back-offs per step before the layer stops the climb.
        hand_strike_load_n: a reaching hand whose wrist F/T reads more than this along
            the forearm is pushed by the ladder (in the air it reads its own weight,
            −3 to −12 N) [N]; it backs off as a foot does (``strike_backoff_m``,
            ``strike_tries``), along the push.
        replan_beyond_m: when both first grasps, made from the floor, put some hold of
            the plan further than this from where the ladder really has it, the layer
            stops before any weight moves onto the ladder (``ladder_misplaced``, with the
            ladder's measured placement): the plan is for another ladder pose, and bounded
            corrections of each reach leave the body's posture, and its loads, the
            plan's for the wrong ladder. ``validate-plan`` then re-plans for the measured
            placement and climbs that plan; on the robot the operator does. 0: never
            (each reach is corrected instead) [m].
        max_body_trim_m: once the ladder alone carries the robot, the body is moved back
            to the plan's posture relative to the rails its hands hold, as their arms'
            encoders measure it, by at most this [m]; 0: never (the default: on, it
            tripped hip rolls and climbed fewer DRC draws, docs/decisions/body-trim.md).
            A stance foot creeping on its rung and compliant arms pulling on their grips
            move the body 1–3 cm towards the ladder over a climb, where the plan keeps
            its shins 1–2.5 cm clear of the rungs.
        max_foot_aim_m: once the ladder alone carries the robot, each foot's reach to a
            rung is aimed against the body's offset from the plan's posture relative to
            the held rails (horizontally, towards the ladder and along the rungs, as the
            holding arms' encoders read it; `max_body_trim_m`'s reading), by at most this
            [m]; the body itself stays. 0: never (the default; experimental,
            docs/decisions/foot-aim.md). A foot placed relative to a body that stands
            on already-offset feet lands offset again: on `ship` the feet drift 0.5 cm
            towards the ladder per rung.
        grip_bending_onset: share of a closed grip's bending capacity above which its
            compliant arm's feed-forward asks the rail for the opposite moment, until the
            bending estimated from the arm's currents is back at this share
            (`execute.motion.grip_bending_relief`); 0: never (the default;
            experimental, docs/decisions/grip-bending-relief.md) [-]. It stays below
            the leg relief's 0.4, under which a lift that gave way to a bent grip may
            grow again: a grip held between the two keeps the lift off.
        estimator: the state estimator's thresholds.
    """

    gravity_compensation: bool = True
    holding_arm_stiffness: float = 1.0
    max_reach_correction_m: float = 0.06
    max_reach_correction_rad: float = math.radians(15.0)
    grasp_retries: int = 8
    search_step_m: float = 0.025
    open_s: float = 0.8
    shift_s: float = 1.5
    close_s: float = 1.0
    verify_timeout_s: float = 1.5
    seat_timeout_s: float = 1.5
    arrival_tolerance_m: float = 0.01
    arrival_timeout_s: float = 4.0
    aim_tolerance_m: float = 0.015
    hold_after_stop_s: float = 2.0
    landing_load_n: float = 20.0
    landing_wait_s: float = 0.5
    landing_reach_m: float = 0.03
    landing_speed_m_s: float = 0.01
    strike_load_n: float = 30.0
    strike_backoff_m: float = 0.03
    strike_backoff_s: float = 0.3
    strike_tries: int = 2
    hand_strike_load_n: float = 15.0
    replan_beyond_m: float = 0.0
    max_body_trim_m: float = 0.0
    max_foot_aim_m: float = 0.0
    grip_bending_onset: float = 0.0
    estimator: EstimatorConfig = field(default_factory=EstimatorConfig)

    def __post_init__(self) -> None:
        for name, (lo, hi) in _RANGES.items():
            value = getattr(self, name)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and lo <= value <= hi):
                raise MotionConfigError(name, value, (lo, hi))

    def changed_settings(self) -> dict[str, bool | int | float]:
        """The `SETTINGS` whose value is not the default, for a run's record."""
        default = MotionConfig()
        return {name: getattr(self, name) for name in SETTINGS
                if getattr(self, name) != getattr(default, name)}


def default_config() -> MotionConfig:
    return MotionConfig()


#: The settings a batch may vary (`parse_setting`): every ranged field and the switch.
SETTINGS: tuple[str, ...] = ("gravity_compensation", *_RANGES)

_SWITCH_WORDS = {"on": True, "true": True, "1": True, "off": False, "false": False, "0": False}


def parse_setting(name: str, text: str) -> bool | int | float:
    """A `MotionConfig` field's value from text, typed as its default and checked against
    its range.

    Args:
        name: one of `SETTINGS`.
        text: ``on``/``off`` for a switch, an integer for a count, a number otherwise.

    Raises:
        InputError: an unknown field or a value that does not parse.
        MotionConfigError: a value outside the field's range.
    """
    if name not in SETTINGS:
        raise InputError(f"motion layer setting {name!r} is unknown; known: "
                         f"{', '.join(SETTINGS)}")
    default = getattr(MotionConfig(), name)
    word = text.strip().lower()
    if isinstance(default, bool):
        if word not in _SWITCH_WORDS:
            raise InputError(f"motion layer {name} = {text!r}: give on or off")
        return _SWITCH_WORDS[word]
    try:
        value: int | float = int(word) if isinstance(default, int) else float(word)
    except ValueError:
        kind = "an integer" if isinstance(default, int) else "a number"
        raise InputError(f"motion layer {name} = {text!r}: give {kind}") from None
    MotionConfig(**{name: value})
    return value


def add_motion_arguments(parser: argparse.ArgumentParser) -> None:
    """The motion layer's flags, shared by ``validate-plan`` and ``play-trajectory`` (the
    same layer runs in simulation and on the robot); `motion_config_from_args` reads
    them."""
    cfg = MotionConfig()

    def within(name: str) -> str:
        lo, hi = _RANGES[name]
        return f"within [{lo:g}, {hi:g}] (default {getattr(cfg, name):g})"

    parser.add_argument("--max-reach-correction", type=float,
                        default=cfg.max_reach_correction_m, metavar="M",
                        help="closed loop: largest shift of a hold target [m], "
                             + within("max_reach_correction_m"))
    parser.add_argument("--grasp-retries", type=int, default=cfg.grasp_retries, metavar="N",
                        help="closed loop: re-reaches of a hand that closed on nothing, "
                             + within("grasp_retries"))
    parser.add_argument("--holding-arm-stiffness", type=float,
                        default=cfg.holding_arm_stiffness, metavar="S",
                        help="closed loop: share of the PWM stiffness pulling a gripping arm "
                             "towards the plan, " + within("holding_arm_stiffness"))
    parser.add_argument("--replan-beyond", type=float, default=cfg.replan_beyond_m,
                        metavar="M",
                        help="closed loop: when the first two grasps find the plan's holds "
                             "further than M [m] from the real ones, stop before the ladder "
                             "takes any weight, open the hands and retrace the plan to its "
                             "start; validate-plan then plans again for the ladder where the "
                             "hands found it and climbs that plan, play-trajectory writes "
                             "that ladder for plan-ladder; " + within("replan_beyond_m")
                             + ", 0 never")
    parser.add_argument("--max-body-trim", type=float, default=cfg.max_body_trim_m,
                        metavar="M",
                        help="closed loop: largest move of the body back to the plan's "
                             "posture relative to the rails its hands hold [m], "
                             + within("max_body_trim_m") + ", 0 never (experimental: "
                             "docs/decisions/body-trim.md)")
    parser.add_argument("--max-foot-aim", type=float, default=cfg.max_foot_aim_m,
                        metavar="M",
                        help="closed loop: on the ladder, largest shift of a foot's reach "
                             "against the body's offset from the plan's posture relative "
                             "to the held rails [m], " + within("max_foot_aim_m")
                             + ", 0 never (experimental: docs/decisions/foot-aim.md)")
    parser.add_argument("--grip-bending-onset", type=float, default=cfg.grip_bending_onset,
                        metavar="SHARE",
                        help="closed loop: share of a grip's bending capacity above which "
                             "the compliant arm holding it takes the excess off by "
                             "feed-forward, " + within("grip_bending_onset") + ", 0 never "
                             "(experimental: docs/decisions/grip-bending-relief.md)")


def motion_config_from_args(args: argparse.Namespace) -> MotionConfig:
    """The motion layer's settings from `add_motion_arguments`' flags.

    Raises:
        MotionConfigError: a value outside its safe range (exit 2, naming it).
    """
    return MotionConfig(max_reach_correction_m=args.max_reach_correction,
                        grasp_retries=args.grasp_retries,
                        holding_arm_stiffness=args.holding_arm_stiffness,
                        replan_beyond_m=args.replan_beyond,
                        max_body_trim_m=args.max_body_trim,
                        max_foot_aim_m=args.max_foot_aim,
                        grip_bending_onset=args.grip_bending_onset)
