"""``hubo-view RESULT.json``: the plan of a ``validate-plan --json`` result, with the
run's outcome on the plan's timeline.

The result JSON holds the verdict, the failure's line and the motion layer's events
(each with its plan line), but not the simulated robot's trajectory: that is what
``validate-plan --record R.rrd`` writes, from the run in memory. So this recording is
the plan's (`execute.view.plan_view`), with the failure and the motion layer's events
at the plan lines they happened on, and it opens at the failure.
"""

from __future__ import annotations

import json
from pathlib import Path

import rerun as rr

from execute.view.plan_layers import PlanLayers
from execute.view.plan_view import Plan, read_plan, record_plan
from execute.view.recording import log_event
from robot.errors import InputError

__all__ = ["read_result", "record_result", "result_plan_path"]


def read_result(path: str | Path) -> dict:
    """The result JSON, checked for what the viewer needs (``plan``, ``verdict``)."""
    p = Path(path)
    try:
        doc = json.loads(p.read_text())
    except OSError as exc:
        raise InputError(f"{p}: cannot read: {exc.strerror}") from None
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"{p}: not a JSON document ({exc})") from None
    if not isinstance(doc, dict) or not isinstance(doc.get("plan"), str) or \
            doc.get("verdict") not in ("climbed", "failed"):
        raise InputError(f"{p}: not a validate-plan result: expected the fields 'plan' (the "
                         "trajectory's path) and 'verdict' ('climbed' or 'failed') that "
                         "validate-plan --json writes")
    return doc


def result_plan_path(result: dict, where: Path) -> Path:
    """The plan a result names: as written (relative to the working folder), else beside
    the result file."""
    named = Path(result["plan"])
    for candidate in (named, where.parent / named, where.parent / named.name):
        if candidate.is_file():
            return candidate
    raise InputError(f"{where}: field 'plan': {named} not found (looked in the working "
                     f"folder and beside {where.name})")


def _plan_time(plan: Plan, line: int) -> float:
    """Plan time of a 1-based line [s]."""
    return (min(max(int(line), 1), plan.sidecar.line_count) - 1) / plan.sidecar.rate_hz


def record_result(rec: rr.RecordingStream, path: str | Path, layers: PlanLayers) -> Plan:
    """Log the plan of the result at ``path`` with the run's outcome; returns the plan."""
    where = Path(path)
    result = read_result(where)
    plan = read_plan(result_plan_path(result, where))
    failed = result["verdict"] == "failed" and isinstance(result.get("line"), int)
    failure_s = _plan_time(plan, result["line"]) if failed else None
    log_event(rec, "events/result", 0.0,
              f"{where.name}: {result['verdict']} ({result.get('strategy')}, "
              f"{result.get('loop')} loop). Events are placed at the plan lines they "
              "happened on; the simulated robot is in the recording that validate-plan "
              "--record writes", rr.TextLogLevel.INFO)
    for e in (result.get("motion") or {}).get("events", []):
        if isinstance(e, dict) and isinstance(e.get("line"), int):
            log_event(rec, "events/motion", _plan_time(plan, e["line"]),
                      f"{e.get('kind')} at t = {e.get('time_s')} s simulated: "
                      f"{e.get('cause', '')}")
    if failure_s is not None:
        log_event(rec, "events/failure", failure_s,
                  f"failed ({result.get('cause')}) at line {result['line']:,}, t = "
                  f"{result.get('time_s')} s simulated: {result.get('why', '')}",
                  rr.TextLogLevel.ERROR)
    record_plan(rec, plan, layers, failure_s)
    return plan
