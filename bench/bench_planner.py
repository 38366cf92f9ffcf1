"""Benchmark: planning time and success of the climb search (issue 3 targets).

- median planning time per rung ≤ 5 s (search time of the steps that climb one rung:
  both hands up, both feet up, straighten; the mount counts as rung 0);
- a whole DRC ladder ≤ 60 s on one core (seed 1);
- planner success over seeds ≥ 95 % (quick: seeds 1–3 on ``drc``; ``full=True`` or
  ``HUBO_BENCH_FULL=1``: seeds 1–20 on every bundled ladder);
- full only: at least 20 of the 40 random ladders of `RANDOM_LADDERS` (slope 55–75°,
  spacing 0.25–0.35 m, rails 0.6–1.0 m apart) planned, seed 1, with compliant gripping
  arms (the default) and with rigid ones, each capped at `TIME_LIMIT_S`.

Each plan is capped at `TIME_LIMIT_S` (quick) or `FULL_TIME_LIMIT_S` (full); a capped
run counts as a failure. Run with ``.venv/bin/python bench/bench_planner.py``.
"""

from __future__ import annotations

import logging
import os
import statistics
import time
from pathlib import Path

from planner.statics.arm_capacity import DEFAULT_ARM_STRATEGY

TARGET_PER_RUNG_S = 5.0
TARGET_LADDER_S = 60.0
TARGET_SUCCESS = 0.95
TARGET_RANDOM_LADDERS = 20
RANDOM_LADDERS = Path(__file__).with_name("random_ladders.yaml")
#: Per-plan time cap [s]: twice the whole-ladder target, so a slow success still counts.
TIME_LIMIT_S = 120.0
FULL_TIME_LIMIT_S = 600.0
QUICK = {"drc": (1, 2, 3)}
FULL_SEEDS = tuple(range(1, 21))

log = logging.getLogger(__name__)


def _plan_once(ladder, seed: int, time_limit_s: float,
               arm_strategy: str = DEFAULT_ARM_STRATEGY) -> dict:
    """One full-ladder plan of a bundled ladder's name or a `LadderSpec`, logged: success,
    wall time [s], search seconds per rung."""
    from ladders.loader import load_ladder
    from planner.search import ClimbPlanner, PlannerConfig, PlanningFailed
    from robot.errors import HuboLadderError

    t0 = time.perf_counter()
    spec = load_ladder(ladder) if isinstance(ladder, str) else ladder
    planner = ClimbPlanner(spec, config=PlannerConfig(time_limit_s=time_limit_s,
                                                      arm_strategy=arm_strategy), seed=seed)
    try:
        result = planner.plan()
    except (PlanningFailed, HuboLadderError) as exc:
        why = f"{exc.step.label}: {exc.reason}" if isinstance(exc, PlanningFailed) else str(exc)
        log.info("%s seed %d (%s arms): FAILED in %.1f s %s", spec.name, seed, arm_strategy,
                 time.perf_counter() - t0, why)
        return {"ok": False, "wall_s": time.perf_counter() - t0, "why": why, "per_rung_s": {}}
    per_rung: dict[int, float] = {}
    for st in result.step_stats:
        rung = int(st.label.rsplit("rung", 1)[1])
        per_rung[rung] = per_rung.get(rung, 0.0) + st.seconds
    log.info("%s seed %d (%s arms): ok in %.1f s", spec.name, seed, arm_strategy,
             time.perf_counter() - t0)
    return {"ok": True, "wall_s": time.perf_counter() - t0, "why": "",
            "per_rung_s": per_rung, "search_s": result.total_s}


def run(full: bool | None = None) -> list[dict]:
    """Plan each (ladder, seed) and report the three figures against their targets.

    Args:
        full: seeds 1–20 on every bundled ladder; default from ``HUBO_BENCH_FULL``.
    """
    from ladders.loader import BUNDLED_LADDERS

    if full is None:
        full = bool(os.environ.get("HUBO_BENCH_FULL"))
    plan = {name: FULL_SEEDS for name in BUNDLED_LADDERS} if full else QUICK
    limit = FULL_TIME_LIMIT_S if full else TIME_LIMIT_S
    runs = {(ladder, seed): _plan_once(ladder, seed, limit)
            for ladder, seeds in plan.items() for seed in seeds}
    mode = "full" if full else "quick"
    out = []
    per_rung = [s for r in runs.values() for s in r["per_rung_s"].values()]
    med = statistics.median(per_rung) if per_rung else None
    out.append({"name": f"planner_median_time_per_rung_{mode}", "value":
                None if med is None else round(med, 2), "unit": "s",
                "target": f"<= {TARGET_PER_RUNG_S:g}",
                "ok": med is not None and med <= TARGET_PER_RUNG_S})
    drc1 = runs.get(("drc", 1))
    whole = round(drc1["search_s"], 1) if drc1 and drc1["ok"] else None
    out.append({"name": "planner_whole_drc_ladder_seed1", "value": whole, "unit": "s",
                "target": f"<= {TARGET_LADDER_S:g}",
                "ok": whole is not None and whole <= TARGET_LADDER_S})
    for ladder in plan:
        mine = [r for (lad, _), r in runs.items() if lad == ladder]
        rate = sum(r["ok"] for r in mine) / len(mine)
        first_failure = next((r["why"] for r in mine if not r["ok"]), "")
        out.append({"name": f"planner_success_{ladder}_{len(mine)}_seeds", "value":
                    round(rate, 3), "unit": "fraction", "target": f">= {TARGET_SUCCESS:g}",
                    "ok": rate >= TARGET_SUCCESS,
                    **({"note": first_failure[:200]} if first_failure else {})})
    if full:
        out += _random_ladders()
    return out


def _random_ladders() -> list[dict]:
    """How many of the random ladders plan, per arm strategy."""
    from execute.batch.sweep import load_sweep
    from planner.statics.arm_capacity import ARM_STRATEGIES

    cells = load_sweep(RANDOM_LADDERS)
    out = []
    for strategy in ARM_STRATEGIES:
        planned = sum(_plan_once(c.spec, 1, TIME_LIMIT_S, strategy)["ok"] for c in cells)
        out.append({"name": f"planner_random_ladders_planned_{strategy}_arms",
                    "value": f"{planned}/{len(cells)}", "unit": "ladders",
                    "target": f">= {TARGET_RANDOM_LADDERS}",
                    "ok": planned >= TARGET_RANDOM_LADDERS})
    return out


if __name__ == "__main__":
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    for row in run():
        print(row)
