"""The results file of a batch: JSON lines, one record per finished job, appended as
each job completes (flushed and fsynced, so a killed run loses at most the jobs in
flight).

A record is the job's identity (`execute.batch.jobs.PlanJob.describe`), ``status``
(``ok``: the job ran and has an outcome, which may be a failed climb or no plan;
``error``: the job raised or its worker died, ``error`` says how) and the outcome fields,
plus ``wall_s`` and ``finished_at``. On resume the latest record per job key wins; a job
is *finished* when that record has status ``ok`` and the job's fingerprint (so a run
with other settings in the same directory redoes the job). Errored jobs are retried.
A truncated last line (a crash mid-write) is ignored.
"""

from __future__ import annotations

import json
import logging
import os
from pathlib import Path

__all__ = ["NONDETERMINISTIC_FIELDS", "ResultsLog", "comparable"]

log = logging.getLogger(__name__)

#: Fields that depend on the machine, the moment or the engine, not on the job's inputs.
NONDETERMINISTIC_FIELDS = ("wall_s", "finished_at", "worker", "plan_s", "search_s",
                           "real_time_factor", "traceback")


def comparable(record: dict) -> dict:
    """A record without its timing and provenance fields (for comparing two runs)."""
    out = {k: v for k, v in record.items() if k not in NONDETERMINISTIC_FIELDS}
    if isinstance(out.get("result"), dict):
        res = dict(out["result"])
        if isinstance(res.get("metrics"), dict):
            res["metrics"] = {k: v for k, v in res["metrics"].items()
                              if k not in NONDETERMINISTIC_FIELDS}
        out["result"] = res
    return out


class ResultsLog:
    """Append-only JSON-lines results of one output directory.

    Args:
        path: the results file (created with its directory when missing).
    """

    def __init__(self, path: str | os.PathLike[str]):
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.latest: dict[str, dict] = {}
        if self.path.exists():
            for rec in self.read(self.path):
                self.latest[rec["key"]] = rec

    @staticmethod
    def read(path: str | os.PathLike[str]) -> list[dict]:
        """Every well-formed record in file order (a torn or foreign line is skipped)."""
        out = []
        with open(path, encoding="utf-8") as fh:
            for n, line in enumerate(fh, 1):
                if not line.strip():
                    continue
                try:
                    rec = json.loads(line)
                except json.JSONDecodeError:
                    log.warning("%s:%d: unreadable record skipped (interrupted write?)", path, n)
                    continue
                if isinstance(rec, dict) and "key" in rec:
                    out.append(rec)
        return out

    def finished(self, key: str, fingerprint: str) -> dict | None:
        """The job's ``ok`` record when it has one for these inputs, else None."""
        rec = self.latest.get(key)
        if rec and rec.get("status") == "ok" and rec.get("fingerprint") == fingerprint:
            return rec
        return None

    def append(self, record: dict) -> None:
        """Append one record durably (write, flush, fsync)."""
        line = json.dumps(record, sort_keys=True, default=_jsonable) + "\n"
        with open(self.path, "a", encoding="utf-8") as fh:
            if fh.tell() > 0 and not self._ends_with_newline():
                fh.write("\n")  # after a torn line, start a fresh one
            fh.write(line)
            fh.flush()
            os.fsync(fh.fileno())
        self.latest[record["key"]] = record

    def _ends_with_newline(self) -> bool:
        with open(self.path, "rb") as fh:
            fh.seek(-1, os.SEEK_END)
            return fh.read(1) == b"\n"


def _jsonable(obj):
    try:
        import numpy as np

        if isinstance(obj, np.generic):
            return obj.item()
        if isinstance(obj, np.ndarray):
            return obj.tolist()
    except ImportError:  # pragma: no cover
        pass
    return str(obj)
