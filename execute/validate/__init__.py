"""``validate-plan``: a plan played in MuJoCo, in lock-step, through the robot's control code.

- `simulate`: player → joint control → board model, one tick at a time;
- `verdict`: the failure checks (fall, lost grip, board trip, …);
- `metrics`, `plan_compare`: figures of merit, and the run's end against the plan;
- `artifacts`: plots, snapshot strip, video;
- `cli`: the ``validate-plan`` command.

Re-exported lazily: importing the package does not load MuJoCo.
"""

from robot.lazy_exports import lazy_exports

_EXPORTS = {
    "Failure": "verdict",
    "JointLoad": "plan_compare",
    "PlanComparison": "plan_compare",
    "RunMetrics": "metrics",
    "STRATEGIES": "simulate",
    "SimulationLog": "simulate",
    "SimulationOptions": "simulate",
    "SimulationRun": "simulate",
    "Verdict": "verdict",
    "VerdictConfig": "verdict",
    "VerdictMonitor": "verdict",
    "compare_with_plan": "plan_compare",
    "compute_metrics": "metrics",
    "line_samples": "metrics",
    "planned_torque_history": "plan_compare",
    "simulate": "simulate",
    "tracking_error_by_arm": "metrics",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
