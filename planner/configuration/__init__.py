"""Feasible configurations (thesis Algorithm 6): a whole-body pose that holds its stance.

- `kinematics`: the placo/pinocchio robot model;
- `collision`: robot–ladder and self-collision (coal);
- `ik`: whole-body IK onto the holds;
- `validity`: the feasibility predicate (limits, collision, stability);
- `feasible`: the sampling search for a feasible configuration.

Re-exported lazily: importing the package does not load placo.
"""

from robot.lazy_exports import lazy_exports

_EXPORTS = {
    "CollisionModel": "collision",
    "CollisionReport": "collision",
    "FeasibilityChecker": "validity",
    "FeasibleSearchStats": "feasible",
    "HuboKinematics": "kinematics",
    "IKConfig": "ik",
    "IKResult": "ik",
    "SearchTarget": "feasible",
    "find_feasible": "feasible",
    "solve_ik": "ik",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
