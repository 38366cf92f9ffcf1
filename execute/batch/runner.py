"""Run a batch: schedule plan and validate jobs on an engine, record each as it finishes,
resume from the results file, and survive jobs that raise or kill their worker.

Scheduling: plan jobs are queued first; when a plan finishes, its validate jobs go to
the front of the queue (so an interrupted run leaves whole (ladder, seed) groups done).
At most ``engine.slots`` jobs are in flight. A validate job whose plan found no plan is
recorded at once as a failure with cause ``no_plan`` (not simulated); one whose plan job
errored is recorded as an error (and retried with it on resume).

A worker that dies (segfault, ``os._exit``, out of memory) breaks a process pool: every
job in flight gets `BrokenProcessPool`. Those jobs are *suspects*: the pool is
restarted and they are re-run one at a time, alone, so a second break names the job
that caused it, which is recorded as an error; the others run normally.
"""

from __future__ import annotations

import logging
import os
import socket
import time
import traceback
from collections import deque
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, wait
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path

from execute.batch.engine import Engine
from execute.batch.jobs import DEFAULT_JOB_FUNCTIONS, JobFunctions, PlanJob, ValidateJob
from execute.batch.results import ResultsLog

__all__ = ["BatchRun", "RESULTS_FILE", "run_batch", "timed_call"]

log = logging.getLogger(__name__)

RESULTS_FILE = "results.jsonl"


def timed_call(fn: Callable[..., dict], *args) -> dict:
    """Run a job function on a worker; add its wall time [s] and the worker's identity."""
    t0 = time.perf_counter()
    out = fn(*args)
    return {**out, "wall_s": time.perf_counter() - t0,
            "worker": f"{socket.gethostname()}:{os.getpid()}"}


@dataclass
class BatchRun:
    """What a batch run did.

    Attributes:
        records: the latest record of every job of the batch, in job order.
        skipped: jobs already finished in the results file (not re-run).
        ran: jobs run now (including those recorded without running: no plan).
        errors: records with status ``error`` among ``records``.
        wall_s: wall time of this run [s].
        engine: the engine's description.
    """

    records: list[dict]
    skipped: int
    ran: int
    wall_s: float
    engine: str
    errors: list[dict] = field(default_factory=list)


def _now() -> str:
    return datetime.now(UTC).isoformat(timespec="seconds")


def _error_text(exc: BaseException) -> tuple[str, str]:
    cause = exc.__cause__  # ProcessPoolExecutor: the worker's traceback as _RemoteTraceback
    tb = str(cause) if cause is not None and "Traceback" in str(cause) else \
        "".join(traceback.format_exception(exc))
    return f"{type(exc).__name__}: {exc}", tb[-4000:]


def run_batch(plans: Sequence[PlanJob], validations: Sequence[ValidateJob],
              out_dir: str | os.PathLike[str], engine: Engine, *,
              functions: JobFunctions = DEFAULT_JOB_FUNCTIONS,
              on_start: Callable[[int, int], None] | None = None,
              on_record: Callable[[dict], None] | None = None,
              max_jobs: int | None = None) -> BatchRun:
    """Run every job not yet finished in ``OUT/results.jsonl``, appending as they end.

    Args:
        plans: plan jobs of the batch.
        validations: validate jobs (each refers to one of ``plans``).
        out_dir: output directory (results file, plans).
        engine: where to run.
        functions: the job functions (tests inject small ones).
        on_start: called once with (jobs to run, jobs skipped as finished).
        on_record: called with each record as it is appended.
        max_jobs: stop submitting after this many jobs (simulates an interrupted run).

    Returns:
        The run's records and counts.
    """
    t_start = time.perf_counter()
    out = Path(out_dir)
    out_s = str(out)
    results = ResultsLog(out / RESULTS_FILE)
    plan_done: dict[str, dict] = {}
    ready: deque = deque()
    for p in plans:
        rec = results.finished(p.key, p.fingerprint)
        if rec is not None and (rec.get("outcome") != "planned" or
                                (out / rec.get("traj", "")).is_file()):
            plan_done[p.key] = rec
        else:
            ready.append(p)
    waiting: dict[str, list[ValidateJob]] = {}
    skipped = len(plans) - len(ready)
    for v in validations:
        if results.finished(v.key, v.fingerprint) is not None:
            skipped += 1
        else:
            waiting.setdefault(v.plan.key, []).append(v)
    to_run = len(ready) + sum(len(vs) for vs in waiting.values())
    if on_start is not None:
        on_start(to_run, skipped)

    ran = 0

    def record(job, status: str, fields: dict) -> None:
        nonlocal ran
        rec = {**job.describe(), "status": status, **fields, "finished_at": _now()}
        results.append(rec)
        ran += 1
        if on_record is not None:
            on_record(rec)

    def release(plan_key: str) -> None:
        prec = plan_done[plan_key]
        for v in reversed(waiting.pop(plan_key, [])):
            if prec.get("status") == "ok" and prec.get("outcome") == "planned":
                ready.appendleft(v)
            elif prec.get("status") == "ok":
                record(v, "ok", {"outcome": "failed", "cause": "no_plan",
                                 "why": f"no plan: {prec.get('why', '')}",
                                 "simulated_s": 0.0, "simulated_s_per_rung": None})
            else:
                record(v, "error", {"error": f"its plan job {plan_key} failed: "
                                             f"{prec.get('error', '?')}"})

    for key in list(waiting):
        if key in plan_done:
            release(key)

    in_flight: dict[Future, object] = {}
    suspects: deque = deque()
    isolated = False
    submitted: set[str] = set()  # keys of jobs submitted (re-runs of suspects count once)

    def submit(job) -> None:
        args = (functions.plan, job, out_s) if isinstance(job, PlanJob) else \
            (functions.validate, job, plan_done[job.plan.key], out_s)
        try:
            fut = engine.submit(timed_call, *args)
        except BrokenProcessPool:  # the pool broke after the last wait: start a new one
            engine.restart()
            fut = engine.submit(timed_call, *args)
        in_flight[fut] = job
        submitted.add(job.key)

    def finish(job, status: str, fields: dict) -> None:
        record(job, status, fields)
        if isinstance(job, PlanJob):
            plan_done[job.key] = results.latest[job.key]
            release(job.key)

    try:
        while True:
            if isolated and not in_flight:
                isolated = False
            if suspects or isolated:
                if not in_flight:
                    submit(suspects.popleft())
                    isolated = True
            else:
                while len(in_flight) < engine.slots and ready and \
                        (max_jobs is None or len(submitted) < max_jobs):
                    submit(ready.popleft())
            if not in_flight:
                break
            done, _ = wait(list(in_flight), return_when=FIRST_COMPLETED)
            broken = False
            for fut in done:
                job = in_flight.pop(fut)
                try:
                    outcome = fut.result()
                except BrokenProcessPool:
                    broken = True
                    if isolated:
                        finish(job, "error", {"error": "BrokenProcessPool: the worker process "
                                              "died while running this job alone"})
                    else:
                        suspects.append(job)
                    continue
                except Exception as exc:  # a job error: record it, go on
                    msg, tb = _error_text(exc)
                    log.warning("%s failed: %s", job.key, msg)
                    finish(job, "error", {"error": msg, "traceback": tb})
                    continue
                finish(job, "ok", outcome)
            if broken:
                for fut in list(in_flight):  # the rest of the pool is gone too
                    suspects.append(in_flight.pop(fut))
                log.warning("a worker died; re-running %d job(s) in flight one at a time",
                            len(suspects))
                engine.restart()
    except BaseException:
        for fut in in_flight:
            fut.cancel()
        raise

    records = [results.latest[j.key] for j in [*plans, *validations] if j.key in results.latest]
    return BatchRun(records, skipped, ran, time.perf_counter() - t_start, engine.description,
                    [r for r in records if r.get("status") == "error"])
