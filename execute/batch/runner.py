"""Run a batch: schedule plan and validate jobs on an engine, record each as it finishes,
resume from the results file, and survive jobs that raise or kill their worker.

Scheduling: plan jobs are queued first; when a plan finishes, its validate jobs go to
the front of the queue (so an interrupted run leaves whole (ladder, seed) groups done).
At most ``engine.slots`` jobs are in flight. A validate job whose plan found no plan is
recorded at once as a failure with cause ``no_plan`` (not simulated); one whose plan job
errored is recorded as an error (and retried with it on resume).

A local worker that dies (segfault, ``os._exit``, out of memory) fails only its own job
with `BrokenProcessPool` (each job has a process of its own,
`execute.batch.engine.FreshProcessExecutor`), which is recorded as an error; the others
run normally.
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
from robot.vocabulary import FailureCause

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
    """A job's error as one line and its traceback (the last 4,000 characters): the
    worker's own, which ProcessPoolExecutor attaches as the cause's ``tb`` field
    (``_RemoteTraceback``), else this process's."""
    remote_tb = getattr(exc.__cause__, "tb", None)
    tb = remote_tb if isinstance(remote_tb, str) else "".join(traceback.format_exception(exc))
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
    results = ResultsLog(out / RESULTS_FILE)
    pending = _pending_jobs(plans, validations, results, out)
    if on_start is not None:
        on_start(pending.to_run, pending.skipped)
    scheduler = _Scheduler(pending, results, engine, functions, str(out), on_record)
    for key in list(pending.waiting):
        if key in pending.plan_done:
            scheduler.release(key)
    scheduler.run(max_jobs)

    records = [results.latest[j.key] for j in [*plans, *validations] if j.key in results.latest]
    return BatchRun(records, pending.skipped, scheduler.ran, time.perf_counter() - t_start,
                    engine.description, [r for r in records if r.get("status") == "error"])


@dataclass
class _Pending:
    """What the results file leaves of a batch to run.

    Attributes:
        plan_done: the record of every plan job already finished, by job key.
        ready: jobs that can run now (the unfinished plan jobs, at first).
        waiting: unfinished validate jobs by the key of the plan job they need.
        skipped: jobs finished in the results file.
    """

    plan_done: dict[str, dict]
    ready: deque
    waiting: dict[str, list[ValidateJob]]
    skipped: int

    @property
    def to_run(self) -> int:
        return len(self.ready) + sum(len(vs) for vs in self.waiting.values())


def _pending_jobs(plans: Sequence[PlanJob], validations: Sequence[ValidateJob],
                  results: ResultsLog, out: Path) -> _Pending:
    """Sort the batch's jobs by the results file: a plan job counts as finished only if
    its trajectory is still on disk (a validate job needs it)."""
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
    return _Pending(plan_done, ready, waiting, skipped)


class _Scheduler:
    """Keeps at most ``engine.slots`` jobs in flight and records each as it ends.

    A plan job's end releases its validate jobs to the front of the queue.
    """

    def __init__(self, pending: _Pending, results: ResultsLog, engine: Engine,
                 functions: JobFunctions, out_s: str,
                 on_record: Callable[[dict], None] | None):
        self.plan_done, self.ready, self.waiting = pending.plan_done, pending.ready, \
            pending.waiting
        self.results, self.engine, self.functions = results, engine, functions
        self.out_s, self.on_record = out_s, on_record
        self.ran = 0
        self.in_flight: dict[Future, object] = {}
        self.submitted: set[str] = set()  # keys of jobs submitted

    def record(self, job, status: str, fields: dict) -> None:
        """Append a job's record to the results file."""
        rec = {**job.describe(), "status": status, **fields, "finished_at": _now()}
        self.results.append(rec)
        self.ran += 1
        if self.on_record is not None:
            self.on_record(rec)

    def release(self, plan_key: str) -> None:
        """A plan job finished: queue its validate jobs first, or record them at once as
        failed (no plan) or errors (the plan job raised)."""
        prec = self.plan_done[plan_key]
        for v in reversed(self.waiting.pop(plan_key, [])):
            if prec.get("status") == "ok" and prec.get("outcome") == "planned":
                self.ready.appendleft(v)
            elif prec.get("status") == "ok":
                self.record(v, "ok", {"outcome": "failed", "cause": FailureCause.NO_PLAN.value,
                                      "why": prec.get("why", "no plan"),
                                      "simulated_s": 0.0, "simulated_s_per_rung": None})
            else:
                self.record(v, "error", {"error": f"its plan job {plan_key} failed: "
                                                  f"{prec.get('error', '?')}"})

    def submit(self, job) -> None:
        """Send a job to the engine."""
        args = (self.functions.plan, job, self.out_s) if isinstance(job, PlanJob) else \
            (self.functions.validate, job, self.plan_done[job.plan.key], self.out_s)
        fut = self.engine.submit(timed_call, *args)
        self.in_flight[fut] = job
        self.submitted.add(job.key)

    def finish(self, job, status: str, fields: dict) -> None:
        """Record a job that ended; a plan job's end releases its validate jobs."""
        self.record(job, status, fields)
        if isinstance(job, PlanJob):
            self.plan_done[job.key] = self.results.latest[job.key]
            self.release(job.key)

    def fill(self, max_jobs: int | None) -> None:
        """Submit ready jobs up to the slots."""
        while len(self.in_flight) < self.engine.slots and self.ready and \
                (max_jobs is None or len(self.submitted) < max_jobs):
            self.submit(self.ready.popleft())

    def collect(self, done: set[Future]) -> None:
        """Record the jobs of finished futures."""
        for fut in done:
            job = self.in_flight.pop(fut)
            try:
                outcome = fut.result()
            except BrokenProcessPool:
                log.warning("%s: its worker process died", job.key)
                self.finish(job, "error", {"error": "BrokenProcessPool: the worker process "
                                           "died while running this job"})
                continue
            except Exception as exc:  # a job error: record it, go on
                msg, tb = _error_text(exc)
                log.warning("%s failed: %s", job.key, msg)
                self.finish(job, "error", {"error": msg, "traceback": tb})
                continue
            self.finish(job, "ok", outcome)

    def run(self, max_jobs: int | None) -> None:
        """Submit and collect until nothing is left in flight; on any exception (Ctrl-C
        included) cancel what has not started."""
        try:
            while True:
                self.fill(max_jobs)
                if not self.in_flight:
                    break
                done, _ = wait(list(self.in_flight), return_when=FIRST_COMPLETED)
                self.collect(done)
        except BaseException:
            for fut in self.in_flight:
                fut.cancel()
            raise
