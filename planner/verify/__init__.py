"""``check-plan``: a kinematic verifier of a planned climb, independent of the planner.

- `check`: the library (`check_plan`, `planned_loads`, the contact rule);
- `cli`: the ``check-plan`` command.

Re-exported lazily: the checks load pinocchio and coal.
"""

from robot.lazy_exports import lazy_exports

_EXPORTS = {
    "CHECKS": "check",
    "CheckResult": "check",
    "HOLD_TOL_M": "check",
    "PlannedLoad": "check",
    "allowed_contacts": "check",
    "check_plan": "check",
    "planned_loads": "check",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
