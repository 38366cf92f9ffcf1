"""The ladder-climbing planner (thesis §6.3.1).

One concept per module or sub-package:
- `contacts` (holds, stances) and `holds` (hold geometry on rungs, rails and floor);
- `statics`: the support region and torque LP (`stability`), the arms' share (`arm_capacity`);
- `configuration`: robot model, collision, IK, the feasibility predicate and the search for
  a feasible configuration (Algorithm 6);
- `paths`: contact-space recursive interpolation and the moving limb's path;
- `search` (Algorithm 5), `timing` (toppra), `time_limit`;
- `output` (trajectory and sidecar), `plots`, `cli` (``plan-ladder``);
- `verify`: ``check-plan``, a verifier independent of the planner.

Importing the package itself loads nothing heavy.
"""
