"""Plans of an earlier batch, taken into a new one (``batch-eval --plans-from DIR``).

A plan is a pure function of its job's inputs (`execute.batch.jobs.PlanJob.fingerprint`:
ladder, seed, robot, time limit, top rung, rate), so a batch that validates the same
plans again (under other perturbations, strategies or a changed controller) need not
plan them again: a DRC plan costs minutes. A plan job of the new batch whose key and
fingerprint have a finished record in ``DIR/results.jsonl`` takes that record, and its
trajectory and sidecar are linked (symbolic links, absolute) into the new output
directory under the same names. The record keeps ``reused_from``: the directory it came
from. A plan the earlier batch found none for is taken too (no plan is an outcome).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

from execute.batch.jobs import PlanJob
from execute.batch.results import ResultsLog
from robot.plan_sidecar import sidecar_path

__all__ = ["reuse_plans"]


def _link(source: Path, target: Path) -> None:
    target.parent.mkdir(parents=True, exist_ok=True)
    if target.is_symlink() or target.exists():
        target.unlink()
    os.symlink(source.resolve(), target)


def reuse_plans(plans: Sequence[PlanJob], source_dir: Path, out_dir: Path,
                results_file: str) -> int:
    """Take into ``out_dir`` every plan of ``plans`` that ``source_dir``'s batch (its
    ``results_file``, which must exist) finished with the same inputs and that
    ``out_dir`` has not; returns how many were taken."""
    if source_dir.resolve() == out_dir.resolve():
        return 0
    source = ResultsLog(source_dir / results_file)
    out = ResultsLog(out_dir / results_file)
    taken = 0
    for job in plans:
        if out.finished(job.key, job.fingerprint) is not None:
            continue
        rec = source.finished(job.key, job.fingerprint)
        if rec is None:
            continue
        if rec.get("outcome") == "planned":
            traj = source_dir / rec["traj"]
            if not traj.is_file():
                continue  # the earlier batch's file is gone: plan again
            _link(traj, out_dir / rec["traj"])
            if sidecar_path(traj).is_file():
                _link(sidecar_path(traj), sidecar_path(out_dir / rec["traj"]))
        out.append({**rec, "reused_from": str(source_dir.resolve())})
        taken += 1
    return taken
