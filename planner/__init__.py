"""The ladder-climbing planner (thesis §6.3.1).

Modules, one concept each: ``contacts`` (holds, stances), ``stability`` (support region,
torque LP), ``kinematics`` (placo/pinocchio model), ``collision`` (coal), ``ik``,
``validity`` (the feasibility predicate), ``feasible`` (Algorithm 6), ``interpolation``
(contact-space recursive interpolation), ``limb_path``, ``search`` (Algorithm 5),
``timing`` (toppra), ``output`` (trajectory and sidecar), ``cli`` (``plan-ladder``),
``check_plan`` (``check-plan``). Importing the package itself loads nothing heavy.
"""
