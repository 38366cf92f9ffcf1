"""``batch-eval``: success rates over many ladders, seeds, strategies and perturbations.

- `sweep`, `perturb`: what to run (sweep files, seeded perturbation draws);
- `jobs`: a plan job and a validate job, each self-contained and picklable;
- `engine`, `runner`: a local process pool or a Dask cluster, one code path;
- `results`, `stats`, `report`, `plots`: the results log, Wilson intervals, tables, plots;
- `cli`: the ``batch-eval`` command.

Re-exported lazily: the jobs import the planner and MuJoCo.
"""

from robot.lazy_exports import lazy_exports

_EXPORTS = {
    "BatchRun": "runner",
    "DEFAULT_JOB_FUNCTIONS": "jobs",
    "Distribution": "stats",
    "Draw": "perturb",
    "Engine": "engine",
    "HARD_LIMIT_GRACE_S": "jobs",
    "JobFunctions": "jobs",
    "NONDETERMINISTIC_FIELDS": "results",
    "PERTURB_KEYS": "perturb",
    "PerturbSpec": "perturb",
    "PlanJob": "jobs",
    "PlanRow": "report",
    "RESULTS_FILE": "runner",
    "ResultsLog": "results",
    "SWEEP_FIELDS": "sweep",
    "SuccessRate": "stats",
    "Summary": "report",
    "SummaryRow": "report",
    "SweepCell": "sweep",
    "ValidateJob": "jobs",
    "Z_95": "stats",
    "comparable": "results",
    "dask_engine": "engine",
    "draw": "perturb",
    "expand_jobs": "jobs",
    "load_sweep": "sweep",
    "local_engine": "engine",
    "open_engine": "engine",
    "parse_perturb": "perturb",
    "parse_sweep_yaml": "sweep",
    "plan_job": "jobs",
    "print_summary": "report",
    "run_batch": "runner",
    "summarize": "stats",
    "summarize_records": "report",
    "timed_call": "runner",
    "validate_job": "jobs",
    "wilson_interval": "stats",
    "write_csv": "report",
    "write_markdown": "report",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
