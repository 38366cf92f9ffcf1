"""How much torque each arm joint can give while its hand holds a rail, per strategy.

The torque LP of `planner.statics.torque_lp` spreads the load over every joint that can carry
it. Which arm joints can carry how much depends on how the arms will be driven:

- ``position``: both arms rigid; every joint up to its torque limit.
- ``mixed`` (the thesis's best strategy, the default): an arm whose hand holds a rail is
  in PWM compliance. Its joints give at most the stall torque of their motor at the PWM
  clamp of the default gains, ``|η·gear·Kt·V·max_pwm/(100·R)|`` (`robot.motors`,
  `robot.pwm_gains`): at 48 V about 14 N·m at the shoulders, 5.8–7.2 N·m at the elbows
  and 1.4 N·m at the wrist pitch, against 27, 23 and 8.9 N·m rigid. The wrist roll
  cannot be compliant (it sits on the finger board) and keeps its limit.

A plan made for ``position`` arms asks the compliant arms of ``mixed`` for torque they do
not have: the legs then saturate and their boards trip (validate-plan shows it).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from functools import lru_cache
from types import MappingProxyType

import numpy as np

from planner.contacts import Stance
from robot.joints import ARM_JOINTS, JOINT_INDEX
from robot.motors import DEFAULT_BATTERY_V, motor_table
from robot.pwm_gains import climbing_gain_table, safe_default_gain_table
from robot.vocabulary import ArmStrategy

__all__ = ["ARM_STRATEGIES", "BACK_EMF_SHARE", "DEFAULT_ARM_STRATEGY",
           "DEFAULT_POSITION_TORQUE_SHARE",
           "arms_comply_while_gripping", "balance_stance", "compliant_speed_rad_s",
           "compliant_torque_nm",
           "gripping_sides", "gripping_torque_limits", "gripping_velocity_limits"]

#: The strategies the planner plans for (a PWM-only climb is not planned).
ARM_STRATEGIES = (ArmStrategy.MIXED, ArmStrategy.POSITION)
#: Share of its torque limit a joint in position mode (the legs, the waist, a rigid arm)
#: is planned to. The torque LP chooses how the legs and the compliant arms share the
#: load, but a compliant arm gives only what its feed-forward and its stiffness towards
#: the reference make, and a position-controlled leg takes the rest: the reserve keeps
#: that rest within the leg's limit. The value is a choice
#: (docs/decisions/position-torque-share.md).
DEFAULT_POSITION_TORQUE_SHARE = 0.9
DEFAULT_ARM_STRATEGY = "mixed"
#: Share of a compliant joint's PWM clamp its back-EMF may take while it moves: a PWM arm
#: on a rail is moved by the body at a speed its motor must follow, and the duty that
#: overcomes the back-EMF is duty the arm's load cannot have.
BACK_EMF_SHARE = 0.25


def arms_comply_while_gripping(strategy: str) -> bool:
    """Whether ``strategy`` puts an arm whose hand holds a rail in PWM compliance.

    Raises:
        ValueError: an unknown strategy.
    """
    if strategy not in ARM_STRATEGIES:
        raise ValueError(f"unknown arm strategy {strategy!r}; use one of {ARM_STRATEGIES}")
    return strategy != "position"


def balance_stance(stance: Stance, strategy: str = DEFAULT_ARM_STRATEGY) -> Stance:
    """The holds the CoM's static balance may rely on.

    A hand whose arm is the only compliant one gripping carries load but does not hold
    the balance: the feet must. One PWM arm is a soft spring (its pull grows by the
    reference error times kp), too soft against the body tipping about the feet's edge;
    two compliant arms, or a rigid one, hold it (docs/decisions/balance-rule.md).
    """
    hands = [h for h in stance.holds if h.is_hand]
    feet = tuple(h for h in stance.holds if not h.is_hand)
    if len(hands) != 1 or not feet or not arms_comply_while_gripping(strategy):
        return stance
    return Stance(feet)


def _clamp_torque_nm(gains: Mapping[str, tuple[float, float, float]],
                     battery_v: float) -> dict[str, float]:
    """Stall torque at each clamped joint's PWM clamp in ``gains`` [N·m]."""
    per_duty = np.abs(motor_table().torque_per_duty(battery_v))
    return {name: float(per_duty[JOINT_INDEX[name]] * max_pwm)
            for name, (_, _, max_pwm) in gains.items() if max_pwm > 0}


@lru_cache(maxsize=16)
def compliant_torque_nm(battery_v: float = DEFAULT_BATTERY_V) -> Mapping[str, float]:
    """Stall torque at the default gains' PWM clamp, per compliant joint [N·m]."""
    return MappingProxyType(_clamp_torque_nm(safe_default_gain_table(), battery_v))


@lru_cache(maxsize=16)
def compliant_speed_rad_s(battery_v: float = DEFAULT_BATTERY_V) -> Mapping[str, float]:
    """Speed at which a compliant joint's back-EMF takes `BACK_EMF_SHARE` of the PWM clamp
    it climbs with, ``share · τ_clamp / b`` (b: back-EMF damping, `robot.motors`;
    the clamp of `robot.pwm_gains.climbing_gain_table`, which the motion layer drives the
    arms with) [rad/s].

    The load the planner gives a compliant arm stays within the documented defaults'
    clamp (`compliant_torque_nm`). On the elbows and wrists (4–5 %) the climbing clamp,
    7.9 %, holds that load and the back-EMF together; the shoulders' default clamp is
    already the safety ceiling, and their speed is what it was. Timed by the defaults'
    clamp, a gripping elbow followed the body at 0.04 rad/s and one
    DRC step lasted 69 s (docs/decisions/arm-speed.md).
    """
    damping = motor_table().back_emf_damping
    return MappingProxyType({
        name: BACK_EMF_SHARE * torque / float(damping[JOINT_INDEX[name]])
        for name, torque in _clamp_torque_nm(climbing_gain_table(), battery_v).items()})


def gripping_velocity_limits(nominal_rad_s: np.ndarray, sides: Iterable[str],
                             strategy: str = DEFAULT_ARM_STRATEGY,
                             battery_v: float = DEFAULT_BATTERY_V) -> np.ndarray | None:
    """Velocity limits (40,) [rad/s] while the arms of ``sides`` hold rails and
    ``strategy`` drives them: the nominal ones, the compliant arms' joints capped at
    `compliant_speed_rad_s`; None when nothing is capped."""
    if not arms_comply_while_gripping(strategy) or not sides:
        return None
    limits = np.array(nominal_rad_s, dtype=float)
    speed = compliant_speed_rad_s(battery_v)
    for side in sides:
        for name in ARM_JOINTS[side]:
            if name in speed:
                j = JOINT_INDEX[name]
                limits[j] = min(limits[j], speed[name])
    return limits


def gripping_sides(limbs: Iterable[str]) -> frozenset[str]:
    """The arms ("left"/"right") whose hands are among ``limbs`` (limb names)."""
    return frozenset(limb.removesuffix("_hand") for limb in limbs if limb.endswith("_hand"))


def gripping_torque_limits(torque_max_nm: Mapping[str, float], sides: Iterable[str],
                           strategy: str = DEFAULT_ARM_STRATEGY,
                           battery_v: float = DEFAULT_BATTERY_V,
                           position_share: float = 1.0) -> dict[str, float]:
    """Torque limits by joint [N·m] with the arms of ``sides`` ("left"/"right") driven as
    ``strategy`` drives a gripping arm.

    Joints in position mode get ``position_share`` of their limit (the planner's reserve
    for their loops, `planner.search.PlannerConfig.position_torque_share`); a compliant
    joint's PWM clamp is its ceiling in the plan and on the robot alike, and is not
    shared.
    """
    limits = {name: tau * position_share for name, tau in torque_max_nm.items()}
    if not arms_comply_while_gripping(strategy):
        return limits
    compliant = compliant_torque_nm(battery_v)
    for side in sides:
        for name in ARM_JOINTS[side]:
            if name in compliant and name in limits:
                limits[name] = min(torque_max_nm[name], compliant[name])
    return limits
