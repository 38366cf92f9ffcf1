"""Small, real job functions for the batch tests (injected through `JobFunctions`).

They do what the real ones do, at a toy scale: the plan job derives a "plan" from the
ladder and seed with its own seeded random generator and writes it under ``OUT/plans/``
(so the file hand-off between jobs is exercised); the validate job reads that file and
decides from the plan and the drawn perturbation whether the "climb" succeeds. No
planner, no MuJoCo: milliseconds per job.

Seeds with a special meaning (to exercise error paths):

- ``RAISE_PLAN_SEED``: the plan job raises;
- ``RAISE_VALIDATE_SEED``: validate jobs with strategy ``position`` raise ValueError;
- ``CRASH_SEED``: validate jobs with strategy ``pwm`` kill their worker process
  (``os._exit``), which breaks a process pool.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np

from execute.batch.jobs import PlanJob, ValidateJob

RAISE_PLAN_SEED = 99
RAISE_VALIDATE_SEED = 13
CRASH_SEED = 666


def small_plan(job: PlanJob, out_dir: str) -> dict:
    if job.seed == RAISE_PLAN_SEED:
        raise RuntimeError(f"planner blew up on seed {job.seed}")
    rng = np.random.default_rng(job.seed)
    # "reach margin": how much slack the plan leaves, worse on steep ladders [m]
    margin = float(0.05 + 0.02 * rng.standard_normal() - 0.001 * (job.ladder.slope_deg - 60))
    if margin < 0.0:
        return {"outcome": "no_plan", "cause": "no_plan", "plan_s": 0.0,
                "where": "climbRung at rung 1",
                "why": f"no plan: climbRung at rung 1: margin {margin:.3f} m < 0"}
    name = f"plans/{job.ladder_key}-s{job.seed}.json"
    path = Path(out_dir) / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps({"margin_m": margin}))
    return {"outcome": "planned", "traj": name, "plan_s": 0.001, "top_rung": 0}


def small_validate(job: ValidateJob, plan_outcome: dict, out_dir: str) -> dict:
    if job.plan.seed == RAISE_VALIDATE_SEED and job.strategy == "position":
        raise ValueError(f"simulation diverged on {job.key}")
    if job.plan.seed == CRASH_SEED and job.strategy == "pwm":
        os._exit(3)
    margin = json.loads((Path(out_dir) / plan_outcome["traj"]).read_text())["margin_m"]
    d = job.draw
    error = float(np.hypot(d.dx_m, d.dy_m)) + {"mixed": 0.0, "position": 0.02,
                                               "pwm": 0.035}[job.strategy]
    climbed = error < margin
    return {"outcome": "climbed" if climbed else "failed",
            "cause": None if climbed else ("grasp_lost" if job.strategy == "position"
                                           else "grasp_not_latched"),
            "why": f"error {error:.4f} m vs margin {margin:.4f} m", "simulated_s": 10.0,
            "simulated_s_per_rung": 10.0 if climbed else None}
