"""Static balance and the arms' share of it.

- `stability`: the support region (friction cones, Bretl–Lall) and the joint-torque LP;
- `arm_capacity`: what an arm may hold by its strategy (position, PWM, mixed), and which
  holds may balance the body.

Re-exported lazily.
"""

from robot.lazy_exports import lazy_exports

_EXPORTS = {
    "ARM_STRATEGIES": "arm_capacity",
    "BACK_EMF_SHARE": "arm_capacity",
    "DEFAULT_ARM_STRATEGY": "arm_capacity",
    "DEFAULT_POSITION_TORQUE_SHARE": "arm_capacity",
    "StabilityConfig": "stability",
    "StabilityError": "stability",
    "StabilityReport": "stability",
    "SupportRegion": "stability",
    "TorqueCheck": "stability",
    "arms_comply_while_gripping": "arm_capacity",
    "balance_stance": "arm_capacity",
    "check_stability": "stability",
    "compliant_speed_rad_s": "arm_capacity",
    "compliant_torque_nm": "arm_capacity",
    "default_config": "stability",
    "friction_cone_edges": "stability",
    "gripping_sides": "arm_capacity",
    "gripping_torque_limits": "arm_capacity",
    "gripping_velocity_limits": "arm_capacity",
    "support_region": "stability",
    "torque_feasibility": "stability",
    "torque_limits_by_joint": "stability",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
