"""The PWM (compliance) gains the robot ships with, and the safety limits they must obey.

Robot data shared by the daemon, which drives compliant joints with these gains
(`daemon.pwm`), and the planner, which must know how much torque a compliant arm can give
(`planner.statics.arm_capacity`). Units are hubo-ach's: kp [%/rad], kd [%/(rad/s)], max_pwm [%].

Safety limits (thesis manual): ``kp < 70``, ``kd < 10``, ``max_pwm < 8``. The DRC-Hubo
documented defaults break them (shoulder pitch/roll 80/0/8, shoulder yaw 70/0/7).
Decision: the documented table stays here, verbatim, as reference data
(:data:`DRC_DOCUMENTED_GAINS`), and the default set (:func:`safe_default_gain_table`)
clips each field to the largest value inside its limit at the resolution the original
used: kp to 69 (integer gains in ``joint.table``) and max_pwm to 7.9 % (0.1 % units).
Other values are kept. Effect on the shoulders: stiffness −14 % (80 → 69 %/rad), peak
duty −1.25 % (8 → 7.9 %), so the duty saturates at 0.114 rad of error instead of
0.100 rad; the shoulder yaw only loses kp (70 → 69). We clip field by field rather than
scale a joint's gains together because the peak duty (what holds the arm on the rail) is
what a grasp needs, and the limit is on each field separately.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

__all__ = [
    "DRC_DOCUMENTED_GAINS",
    "KD_LIMIT",
    "KP_LIMIT",
    "MAX_PWM_LIMIT_PCT",
    "PWM_COMMAND_LIMIT_PCT",
    "SAFE_KP",
    "SAFE_MAX_PWM_PCT",
    "climbing_gain_table",
    "safe_default_gain_table",
]

KP_LIMIT = 70.0  # [%/rad] kp must stay strictly below (thesis manual)
KD_LIMIT = 10.0  # [%/(rad/s)] kd must stay strictly below (thesis manual)
MAX_PWM_LIMIT_PCT = 8.0  # [%] max_pwm must stay strictly below (thesis manual)
PWM_COMMAND_LIMIT_PCT = 100.0  # [%] a feed-forward beyond full duty is meaningless

#: The largest kp inside the limit at ``joint.table``'s integer resolution [%/rad].
SAFE_KP = 69.0
#: The largest max_pwm inside the limit at the board's 0.1 % resolution [%].
SAFE_MAX_PWM_PCT = 7.9


def _arm_table(elbow: tuple[float, float, float]) -> dict[str, tuple[float, float, float]]:
    return {
        "SP": (80.0, 0.0, 8.0),
        "SR": (80.0, 0.0, 8.0),
        "SY": (70.0, 0.0, 7.0),
        "EB": elbow,
        "WY": (50.0, 0.0, 5.0),
        "WP": (40.0, 0.0, 4.0),
    }


#: DRC-Hubo default PWM gains as documented (hubo-facts §3), joint → (kp, kd, max_pwm %).
#: Reference data only: several entries break the safety limits, so the daemon refuses
#: this table; :func:`safe_default_gain_table` is the safe set derived from it.
#: Joints not listed (legs, wrist roll, neck, waist, fingers) are 0/0/0: limp if compliant.
DRC_DOCUMENTED_GAINS: Mapping[str, tuple[float, float, float]] = MappingProxyType(
    {
        side + s: g
        for side, elbow in (("R", (50.0, 0.0, 5.0)), ("L", (40.0, 0.0, 4.0)))
        for s, g in _arm_table(elbow).items()
    }
)


def safe_default_gain_table() -> dict[str, tuple[float, float, float]]:
    """The safe DRC-Hubo default gains, joint → (kp, kd, max_pwm %).

    :data:`DRC_DOCUMENTED_GAINS` with each field clipped into the safety limits:
    kp ≤ 69 [%/rad] and max_pwm ≤ 7.9 [%] (kd is 0 in the table). Shoulder pitch and
    roll become 69/0/7.9, shoulder yaw 69/0/7; elbows and wrists are unchanged.
    """
    return {name: (min(kp, SAFE_KP), kd, min(max_pwm, SAFE_MAX_PWM_PCT))
            for name, (kp, kd, max_pwm) in DRC_DOCUMENTED_GAINS.items()}


def climbing_gain_table(max_pwm_pct: float = SAFE_MAX_PWM_PCT
                        ) -> dict[str, tuple[float, float, float]]:
    """The gains a compliant arm climbs with, joint → (kp, kd, max_pwm %).

    hubo-ach's documented defaults clamp the elbows and wrists at 4–5 % of duty: a wrist
    pitch then gives at most 1.4 N·m, less than a gripping hand needs, and DRC grips bent
    open (docs/decisions/motion-layer.md). hubo-motion-rt ran its arms with gains of its
    own for the same reason. Here every arm joint that has a clamp gets ``max_pwm_pct``
    (never below its default; whoever loads the table into the daemon checks it against
    the safety limits, `daemon.pwm.PwmGains`); kp and kd stay the safe defaults. The
    motion layer drives the arms with these (`execute.motion.gains`), and the planner
    times a gripping arm's motion by the speed they can follow
    (`planner.statics.arm_capacity.compliant_speed_rad_s`).
    """
    table = safe_default_gain_table()
    for name, (kp, kd, clamp) in table.items():
        if clamp > 0.0:
            table[name] = (kp, kd, max(clamp, max_pwm_pct))
    return table
