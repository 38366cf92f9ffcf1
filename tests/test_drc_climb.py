"""The issue-4 climb, end to end: `plan-ladder drc --seed 6` climbs the whole bundled
DRC ladder in MuJoCo under `validate-plan --strategy mixed` (about 4 minutes).

Seed 6 is the one of seeds 1–8 whose plan climbs (the README gives the others' ends);
the test keeps that climb from breaking unnoticed.
"""

from __future__ import annotations

import json

from execute.validate.cli import main as validate_main
from ladders.loader import load_ladder
from planner.cli import main as plan_main
from robot.plan_sidecar import read_sidecar, sidecar_path

DRC_CLIMBING_SEED = 6


def test_a_drc_plan_climbs_the_whole_ladder_under_mixed(tmp_path):
    plan = tmp_path / "drc.traj"
    assert plan_main(["drc", "--seed", str(DRC_CLIMBING_SEED), "-o", str(plan)]) == 0
    top = f"rung_{load_ladder('drc').num_rungs - 1}"
    final = read_sidecar(sidecar_path(plan)).final_holds
    assert {final[f].target for f in ("left_foot", "right_foot")} == {top}
    result = tmp_path / "result.json"
    assert validate_main([str(plan), "--strategy", "mixed", "--json", str(result)]) == 0
    r = json.loads(result.read_text())
    assert r["verdict"] == "climbed"
    assert set(r["final_holds"].values()) == {"ok"}
    assert set(r["final_holds"]) == {"left_foot", "right_foot", "left_hand", "right_hand"}
    assert r["board_trips"] == []
