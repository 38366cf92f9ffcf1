"""``hubo-view``: plans and simulated runs in 3D, as Rerun recordings.

- `scene_meshes`: the MuJoCo scene's geoms as meshes, one per body;
- `plan_poses`: the planned robot placed in the world line by line (check-plan's base
  placement, MuJoCo's forward kinematics);
- `plan_statics`: support regions and planned hold forces (check-plan's LPs);
- `recording`, `plan_layers`, `layout`, `output`: what goes in a recording, how it
  opens, where it goes;
- `plan_view`, `result_view`, `run_recording`: a plan, a result JSON, a simulated run;
- `viewer`: Rerun's viewer on a recording at a given time (``--open``, ``--screenshot``);
- `cli`: the ``hubo-view`` command.

Re-exported lazily: importing the package loads neither Rerun nor MuJoCo.
"""

from robot.lazy_exports import lazy_exports

_EXPORTS = {
    "PlanKinematics": "plan_poses",
    "PlanLayers": "plan_layers",
    "PlanPoses": "plan_poses",
    "read_plan": "plan_view",
    "record_plan": "plan_view",
    "record_result": "result_view",
    "record_run": "run_recording",
    "open_in_viewer": "viewer",
    "write_run_recording": "run_recording",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
