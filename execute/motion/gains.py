"""The PWM gains the motion layer runs the compliant arms with.

hubo-ach's documented DRC-Hubo defaults clamp the elbow at 4–5 % of duty and the wrist
yaw and pitch at 4–5 % (hubo-facts §3): a wrist pitch gives at most 1.4 N·m, less than a
gripping hand needs. At that clamp the gripping wrist pitch of DRC seed 3 stood 0.17 rad
off its reference and the grip bent open at 9 N·m (146 s); with the arm joints' clamp at
the safety ceiling, the same plan climbed to rung 5 (857 s, docs/decisions/motion-layer.md).
hubo-motion-rt ran its arms with gains of its own for the same reason. Every arm joint
that has a clamp gets ``max_pwm_pct`` (at most the safety ceiling, 7.9 % < 8 %); kp and
kd stay the safe defaults (`robot.pwm_gains.safe_default_gain_table`).
"""

from __future__ import annotations

from daemon.pwm import PwmGains
from robot.joints import ARM_JOINTS
from robot.pwm_gains import SAFE_MAX_PWM_PCT, safe_default_gain_table

__all__ = ["motion_pwm_gains"]


def motion_pwm_gains(max_pwm_pct: float = SAFE_MAX_PWM_PCT) -> PwmGains:
    """The safe default gains with every clamped arm joint's clamp at ``max_pwm_pct`` [%]
    (validated against the safety limits by `daemon.pwm.PwmGains`)."""
    table = dict(safe_default_gain_table())
    for joints in ARM_JOINTS.values():
        for name in joints:
            kp, kd, clamp = table.get(name, (0.0, 0.0, 0.0))
            if clamp > 0.0:
                table[name] = (kp, kd, max(clamp, max_pwm_pct))
    return PwmGains.from_table(table)
