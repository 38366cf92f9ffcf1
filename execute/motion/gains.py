"""The PWM gains the motion layer runs the compliant arms with: the climbing gains of
`robot.pwm_gains.climbing_gain_table` (every clamped arm joint at the safety ceiling,
7.9 % < 8 %), validated against the safety limits by `daemon.pwm.PwmGains`.

At the documented 4–5 % clamp the gripping wrist pitch of DRC seed 3 stood 0.17 rad off
its reference and the grip bent open at 9 N·m (146 s); with the arm joints' clamp at the
safety ceiling, the same plan climbed to rung 5 (857 s, docs/decisions/motion-layer.md).
"""

from __future__ import annotations

from daemon.pwm import PwmGains
from robot.pwm_gains import SAFE_MAX_PWM_PCT, climbing_gain_table

__all__ = ["motion_pwm_gains"]


def motion_pwm_gains(max_pwm_pct: float = SAFE_MAX_PWM_PCT) -> PwmGains:
    """The climbing gains with every clamped arm joint's clamp at ``max_pwm_pct`` [%]."""
    return PwmGains.from_table(climbing_gain_table(max_pwm_pct))
