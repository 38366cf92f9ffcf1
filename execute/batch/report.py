"""Summaries of a batch: success rates with Wilson intervals, failure causes and timing
distributions, per ladder (or sweep cell) × strategy; as rich tables, CSV and Markdown.

Counting rules:

- a validate record with status ``ok`` is one trial: a success when the robot climbed,
  a failure otherwise, including ``no_plan`` (the planner found no climb for that
  ladder and seed, so that strategy got nothing to play);
- records with status ``error`` (the job raised or its worker died) are not trials:
  they say nothing about the robot. They are counted in their own column, and so are
  jobs without a record yet (``missing``, an unfinished run);
- simulated seconds per rung are taken over climbs only (a failed run stops early);
  planning time over plans found.
"""

from __future__ import annotations

import csv
import io
import math
from collections import Counter
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from execute.batch.jobs import record_label
from execute.batch.stats import Distribution, SuccessRate, summarize
from ladders.spec import LadderSpec

__all__ = ["PlanRow", "ReplanRow", "Summary", "SummaryRow", "print_summary", "summarize_records",
           "write_csv", "write_markdown"]


@dataclass(frozen=True)
class SummaryRow:
    """One ladder (or sweep cell) × strategy.

    Attributes:
        ladder: ladder key.
        strategy: arm strategy.
        sweep: swept parameter values of the cell (empty without a sweep).
        slope_deg, rung_spacing_m: the ladder's slope [deg] and rung spacing [m].
        rate: climbs out of trials, with its 95 % Wilson interval.
        errors: jobs that errored (not trials).
        missing: jobs of the batch with no record yet.
        causes: failure cause → count.
        sim_s_per_rung: simulated seconds per rung over climbs [s].
    """

    ladder: str
    strategy: str
    sweep: dict[str, Any]
    slope_deg: float
    rung_spacing_m: float
    rate: SuccessRate
    errors: int
    missing: int
    causes: dict[str, int]
    sim_s_per_rung: Distribution


@dataclass(frozen=True)
class PlanRow:
    """Planning per ladder: plans found out of seeds, planning time [s], why not."""

    ladder: str
    planned: SuccessRate
    errors: int
    plan_s: Distribution
    no_plan: dict[str, int]


@dataclass(frozen=True)
class ReplanRow:
    """Re-plans after the first touch, per ladder × run label (closed runs with
    ``--replan-beyond``): how many runs planned again, how many of those found a plan and
    climbed, and the re-plan's planning time [s]."""

    ladder: str
    strategy: str
    runs: int
    replanned: int
    no_plan: int
    climbed: int
    planning_s: Distribution


@dataclass
class Summary:
    rows: list[SummaryRow]
    plans: list[PlanRow]
    sweep_fields: list[str] = field(default_factory=list)
    replans: list[ReplanRow] = field(default_factory=list)

    def causes(self) -> Counter:
        """Failure causes over every row."""
        total: Counter = Counter()
        for r in self.rows:
            total.update(r.causes)
        return total


def _no_plan_reason(record: dict) -> str:
    """Where a plan job found no plan (its ``where`` field: ``climbRung at rung 2``,
    ``time limit``, ``timing``); ``?`` for a record written before the field existed."""
    return record.get("where") or "?"


def summarize_records(records: Iterable[dict], ladders: Mapping[str, LadderSpec],
                      strategies: Iterable[str], expected: Mapping[tuple[str, str], int],
                      expected_plans: Mapping[str, int]) -> Summary:
    """Aggregate the records of one batch.

    Args:
        records: the latest record of each job of the batch.
        ladders: ladder key → spec (table order).
        strategies: run labels (`execute.batch.jobs.run_label`, "mixed closed") in table
            order.
        expected: (ladder, run label) → number of validate jobs in the batch.
        expected_plans: ladder → number of plan jobs.
    """
    strategies = list(strategies)
    val: dict[tuple[str, str], list[dict]] = {}
    plans: dict[str, list[dict]] = {}
    sweeps: dict[str, dict] = {}
    for r in records:
        sweeps.setdefault(r["ladder"], r.get("sweep") or {})
        if r["kind"] == "plan":
            plans.setdefault(r["ladder"], []).append(r)
        else:
            val.setdefault((r["ladder"], record_label(r)), []).append(r)
    rows = []
    for key, spec in ladders.items():
        for s in strategies:
            recs = val.get((key, s), [])
            ok = [r for r in recs if r.get("status") == "ok"]
            climbed = [r for r in ok if r.get("outcome") == "climbed"]
            causes = Counter(r.get("cause") or "unknown" for r in ok
                             if r.get("outcome") != "climbed")
            rows.append(SummaryRow(
                key, s, sweeps.get(key, {}), spec.slope_deg, spec.rung_spacing_m,
                SuccessRate(len(climbed), len(ok)), len(recs) - len(ok),
                expected.get((key, s), 0) - len(recs), dict(causes.most_common()),
                summarize(r.get("simulated_s_per_rung") for r in climbed)))
    prow = []
    for key in ladders:
        recs = plans.get(key, [])
        ok = [r for r in recs if r.get("status") == "ok"]
        found = [r for r in ok if r.get("outcome") == "planned"]
        why = Counter(_no_plan_reason(r) for r in ok
                      if r.get("outcome") != "planned")
        prow.append(PlanRow(key, SuccessRate(len(found), len(ok)), len(recs) - len(ok),
                            summarize(r.get("plan_s") for r in found),
                            dict(why.most_common())))
    fields_ = sorted({k for sw in sweeps.values() for k in sw})
    return Summary(rows, prow, fields_, _replan_rows(val))


def _replan_rows(val: Mapping[tuple[str, str], list[dict]]) -> list[ReplanRow]:
    """A row per ladder × label whose runs could plan again (`ReplanRow`)."""
    out = []
    for (key, label), recs in val.items():
        ok = [r for r in recs if r.get("status") == "ok" and r.get("replan_beyond_m")]
        if not ok:
            continue
        done = [r for r in ok if (r.get("result") or {}).get("replan")]
        none = [r for r in done if r["result"]["replan"].get("no_plan")]
        out.append(ReplanRow(key, label, len(ok), len(done), len(none),
                             sum(r.get("outcome") == "climbed" for r in done),
                             summarize(r["result"]["replan"].get("planning_s") for r in done)))
    return out


def _replan_table(summary: Summary) -> tuple[list[str], list[list[str]]]:
    head = ["ladder", "strategy", "runs", "re-planned", "no new plan", "climbed after it",
            "planning [s] min/med/p90"]
    body = []
    for r in summary.replans:
        d = r.planning_s
        dist = "–" if not d.n else f"{d.min:.0f} / {d.median:.0f} / {d.p90:.0f}"
        body.append([r.ladder, r.strategy, str(r.runs), str(r.replanned), str(r.no_plan),
                     str(r.climbed), dist])
    return head, body


def _pct(x: float) -> str:
    return "–" if math.isnan(x) else f"{x:.0%}"


def _causes(c: dict[str, int]) -> str:
    return ", ".join(f"{k} {v}" for k, v in c.items()) or "–"


def _sweep_value(v: Any) -> str:
    return f"{v:g}" if isinstance(v, float) else str(v)


def _table_rows(summary: Summary) -> tuple[list[str], list[list[str]]]:
    head = ["ladder", *summary.sweep_fields, "strategy", "climbed", "runs", "rate",
            "95% CI", "errors", "missing", "failure causes", "sim s/rung min/med/p90"]
    body = []
    for r in summary.rows:
        lo, hi = r.rate.interval
        d = r.sim_s_per_rung
        dist = "–" if not d.n else f"{d.min:.1f} / {d.median:.1f} / {d.p90:.1f}"
        body.append([r.ladder, *[_sweep_value(r.sweep.get(f, "")) for f in summary.sweep_fields],
                     r.strategy, str(r.rate.successes), str(r.rate.n), _pct(r.rate.rate),
                     f"[{lo:.0%}, {hi:.0%}]" if r.rate.n else "–", str(r.errors),
                     str(r.missing), _causes(r.causes), dist])
    return head, body


def _plan_rows(summary: Summary) -> tuple[list[str], list[list[str]]]:
    head = ["ladder", "plans found", "seeds", "errors", "plan time [s] min/med/p90",
            "no plan (where)"]
    body = []
    for p in summary.plans:
        d = p.plan_s
        dist = "–" if not d.n else f"{d.min:.1f} / {d.median:.1f} / {d.p90:.1f}"
        body.append([p.ladder, str(p.planned.successes), str(p.planned.n), str(p.errors), dist,
                     _causes(p.no_plan)])
    return head, body


def print_summary(summary: Summary, console) -> None:
    """Print the success table, the planning table and the cause totals (rich)."""
    from rich.markup import escape
    from rich.table import Table

    head, body = _table_rows(summary)
    body = [[escape(c) for c in row] for row in body]
    t = Table(title="success rate per ladder × strategy (95 % Wilson interval)")
    for h in head:
        t.add_column(escape(h), justify="left" if h in ("ladder", "strategy", "failure causes")
                     else "right", overflow="fold")
    for row in body:
        t.add_row(*row)
    console.print(t)
    console.print(_plain_table("planning per ladder", *_plan_rows(summary)))
    if summary.replans:
        console.print(_plain_table("re-plans after the first touch",
                                   *_replan_table(summary)))
    causes = summary.causes()
    if causes:
        console.print("failure causes: " + _causes(dict(causes.most_common())), highlight=False,
                      markup=False)


def _plain_table(title: str, head: list[str], body: list[list[str]]):
    """A rich table of text cells, printed verbatim."""
    from rich.markup import escape
    from rich.table import Table

    t = Table(title=title)
    for h in head:
        t.add_column(escape(h), overflow="fold")
    for row in body:
        t.add_row(*(escape(c) for c in row))
    return t


def write_csv(summary: Summary, path: str | Path) -> Path:
    """One row per ladder × strategy, machine-readable (rates as fractions)."""
    out = io.StringIO()
    w = csv.writer(out)
    w.writerow(["ladder", *summary.sweep_fields, "slope_deg", "rung_spacing_m", "strategy",
                "climbed", "runs", "rate", "ci95_low", "ci95_high", "errors", "missing",
                "failure_causes", "sim_s_per_rung_min", "sim_s_per_rung_median",
                "sim_s_per_rung_p90"])
    for r in summary.rows:
        lo, hi = r.rate.interval
        d = r.sim_s_per_rung
        w.writerow([r.ladder, *[r.sweep.get(f, "") for f in summary.sweep_fields], r.slope_deg,
                    r.rung_spacing_m, r.strategy, r.rate.successes, r.rate.n,
                    "" if not r.rate.n else f"{r.rate.rate:.4f}", f"{lo:.4f}", f"{hi:.4f}",
                    r.errors, r.missing, ";".join(f"{k}:{v}" for k, v in r.causes.items()),
                    *("" if not d.n else f"{x:.3f}" for x in (d.min, d.median, d.p90))])
    p = Path(path)
    p.write_text(out.getvalue(), encoding="utf-8")
    return p


def _md_table(head: list[str], body: list[list[str]]) -> str:
    esc = [[c.replace("|", "\\|") for c in row] for row in body]
    lines = ["| " + " | ".join(head) + " |", "|" + "|".join("---" for _ in head) + "|"]
    lines += ["| " + " | ".join(row) + " |" for row in esc]
    return "\n".join(lines)


def write_markdown(summary: Summary, path: str | Path, title: str = "batch-eval") -> Path:
    """The tables as Markdown (success, planning, failure causes)."""
    parts = [f"# {title}", "", "## Success rate per ladder × strategy (95 % Wilson interval)",
             "", _md_table(*_table_rows(summary)), "", "## Planning per ladder", "",
             _md_table(*_plan_rows(summary)), ""]
    if summary.replans:
        parts += ["## Re-plans after the first touch", "", _md_table(*_replan_table(summary)),
                  ""]
    parts += ["## Failure causes", ""]
    causes = summary.causes()
    parts.append(_md_table(["cause", "count"], [[k, str(v)] for k, v in causes.most_common()])
                 if causes else "none")
    p = Path(path)
    p.write_text("\n".join(parts) + "\n", encoding="utf-8")
    return p
