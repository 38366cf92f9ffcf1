"""The motion layer: closed-loop playback on sensed state (`execute.motion.layer`).

Its modules, from the sensors up: `sensed_state` (the state struct, the only input),
`estimator` (leg odometry, IMU tilt, limb poses), `robot_model` (pinocchio: gravity,
kinematics, limb IK), `gravity_compensation`, `grasp_check`, `ladder_estimate`, `events`,
`config` and `layer`; after a ``ladder_misplaced`` stop, `retract` (the way back) and
`replan` (the new plan's settings). Importing this package loads none of them: the layer
and the estimator need pinocchio, which callers import only when they close the loop.
"""

__all__: list[str] = []
