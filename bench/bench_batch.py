"""Benchmark: batch-eval throughput in jobs per core-minute.

Workloads (each through the real runner, `execute.batch.runner.run_batch`):

1. **real, small** (default): the stair ladder up to its first rung, 2 seeds × 3
   strategies with ``placement=0.03`` on a local pool of 2 workers: 2 real plans
   (~6 s each) and 6 real simulations (they end early when the climb fails). Set
   ``HUBO_BENCH_BATCH_LADDER=drc`` (and optionally ``HUBO_BENCH_BATCH_TOP_RUNG``) for
   full DRC climbs: ~50-70 s per plan, up to ~30 s per simulation; then the issue's
   target applies: 10 seeds × 3 strategies = 40 jobs in 30 min on 2 cores, i.e.
   ≥ 0.67 jobs per core-minute.
2. **runner cost per job**: the toy jobs of ``tests/batch_small_jobs.py`` (milliseconds
   each, no planner, no MuJoCo) on the local pool and on a Dask LocalCluster: what the
   scheduling, pickling and results file cost per job. These are labelled "toy": they
   say nothing about planning or simulation speed.

Jobs per core-minute = jobs / (wall minutes × workers).
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

WORKERS = 2
#: The issue's run: 10 plans + 30 validations in 30 min on 2 cores [jobs / core-min].
ISSUE_TARGET = 40 / (30 * 2)


def _throughput(n_jobs: int, wall_s: float, workers: int) -> float:
    return n_jobs / (wall_s / 60.0 * workers)


def run() -> list[dict]:
    from execute.batch.engine import dask_engine, local_engine
    from execute.batch.jobs import JobFunctions, expand_jobs
    from execute.batch.perturb import parse_perturb
    from execute.batch.runner import run_batch
    from ladders.loader import load_ladder

    workers = max(1, min(WORKERS, os.cpu_count() or 1))
    ladder = os.environ.get("HUBO_BENCH_BATCH_LADDER", "stair")
    top = os.environ.get("HUBO_BENCH_BATCH_TOP_RUNG")
    top_rung = int(top) if top else (0 if ladder == "stair" else None)
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        plans, vals = expand_jobs([(ladder, load_ladder(ladder), {})], [1, 2],
                                  ["mixed", "position", "pwm"], parse_perturb("placement=0.03"),
                                  top_rung=top_rung)
        t0 = time.perf_counter()
        with local_engine(workers) as eng:
            batch = run_batch(plans, vals, Path(tmp) / "real", eng)
        wall = time.perf_counter() - t0
        n = len(batch.records)
        climbs = sum(r.get("outcome") == "climbed" for r in batch.records)
        label = f"{ladder}{'' if top_rung is None else f'_to_rung{top_rung}'}"
        full_drc = ladder == "drc" and top_rung is None
        tput = _throughput(n, wall, workers)
        out.append({"name": f"batch_jobs_per_core_minute_real_{label}", "value": round(tput, 2),
                    "unit": f"jobs/core-min ({n} jobs, {climbs} climbs, {wall:.0f} s, "
                            f"{workers} workers)",
                    "target": f">= {ISSUE_TARGET:.2f}" if full_drc else None,
                    "ok": tput >= ISSUE_TARGET if full_drc else None})
        plan_s = [r["plan_s"] for r in batch.records if r.get("kind") == "plan" and
                  r.get("plan_s") is not None]
        if plan_s:
            out.append({"name": f"batch_plan_s_median_{label}",
                        "value": round(sorted(plan_s)[len(plan_s) // 2], 1), "unit": "s",
                        "target": None, "ok": None})

        sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
        import batch_small_jobs as small

        fns = JobFunctions(plan=small.small_plan, validate=small.small_validate)
        ladders = [(n_, load_ladder(n_), {}) for n_ in ("drc", "stair")]
        plans, vals = expand_jobs(ladders, range(1, 11), ["mixed", "position", "pwm"],
                                  parse_perturb("placement=0.03"), draws=3)
        for name, make in (("local", lambda: local_engine(workers)),
                           ("dask", lambda: dask_engine(workers=workers))):
            with make() as eng:
                t0 = time.perf_counter()
                batch = run_batch(plans, vals, Path(tmp) / f"toy-{name}", eng, functions=fns)
                wall = time.perf_counter() - t0
            n = len(batch.records) - len(batch.errors)
            out.append({"name": f"batch_cost_ms_per_toy_job_{name}",
                        "value": round(wall / max(n, 1) * 1000 * workers, 2),
                        "unit": f"core-ms/job ({n} toy jobs ok, {len(batch.errors)} errors, "
                                f"{workers} workers; scheduling + fsync'd record + toy work)",
                        "target": None, "ok": None if not batch.errors else False})
    return out


if __name__ == "__main__":
    for row in run():
        print(row)
