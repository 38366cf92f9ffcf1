"""Static balance and the arms' share of it.

- `config`: the tests' tunables (`StabilityConfig`) and their error;
- `contact_wrenches`: linearised friction cones and grip wrenches, shared by both LPs;
- `com_region`: the CoM support region of a stance (Bretl–Lall projection);
- `torque_lp`: the joint-torque LP of one configuration (`highs_lp` solves it);
- `stability`: both tests on one configuration (`check_stability`);
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
    "GRIP_LOAD_COST": "torque_lp",
    "OBJECTIVES": "torque_lp",
    "StabilityConfig": "config",
    "StabilityError": "config",
    "StabilityReport": "stability",
    "SupportRegion": "com_region",
    "TorqueCheck": "torque_lp",
    "arms_comply_while_gripping": "arm_capacity",
    "balance_stance": "arm_capacity",
    "check_stability": "stability",
    "compliant_speed_rad_s": "arm_capacity",
    "compliant_torque_nm": "arm_capacity",
    "default_config": "config",
    "friction_cone_edges": "contact_wrenches",
    "gripping_sides": "arm_capacity",
    "gripping_torque_limits": "arm_capacity",
    "gripping_velocity_limits": "arm_capacity",
    "support_region": "com_region",
    "torque_feasibility": "torque_lp",
    "torque_limits_by_joint": "torque_lp",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
