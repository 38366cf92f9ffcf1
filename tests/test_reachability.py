"""The reachability pre-check: the bundled ladders pass, a ladder out of reach is refused
at once with its reason in user terms (plan-ladder exit 1, a batch's no-plan record)."""

from __future__ import annotations

import dataclasses
import math
import time

import pytest

from execute.batch.jobs import PlanJob, plan_job
from ladders.loader import ladder_to_yaml, load_ladder
from planner.cli import main
from planner.reachability import (
    LadderOutOfReach,
    check_reach,
    reach_shortfalls,
    step_height_reach_m,
)
from planner.search import ClimbPlanner
from robot.params import robot_params


@pytest.mark.parametrize("name", ["drc", "stair", "ship"])
def test_the_bundled_ladders_are_within_the_drc_hubo_s_reach(name):
    assert reach_shortfalls(load_ladder(name), "drc-hubo") == []


def test_rails_too_far_apart_are_refused_with_the_arm_span():
    p = robot_params("drc-hubo")
    widest = 2 * (p.half_shoulder_width_m + p.upper_arm_m + p.forearm_m + p.wrist_to_palm_m)
    wide = dataclasses.replace(load_ladder("drc"), name="wide", rail_spacing_m=2.2)
    (short,) = reach_shortfalls(wide, "drc-hubo")
    assert short.what == "rail_spacing_m" and short.needed == 2.2
    assert short.reachable == pytest.approx(widest)
    assert "rails 2.20 m apart" in short.message and f"{widest:.2f} m apart" in short.message
    just_in = dataclasses.replace(wide, rail_spacing_m=widest - 0.01)
    assert reach_shortfalls(just_in, "drc-hubo") == []


def test_rungs_too_narrow_for_two_feet_are_refused():
    narrow = dataclasses.replace(load_ladder("ship"), rung_width_m=0.25)
    (short,) = reach_shortfalls(narrow, "drc-hubo")
    assert short.what == "rung_width_m" and "two feet side by side" in short.message


def test_step_height_is_bounded_by_the_legs_and_shrinks_with_the_offset_allowed():
    p = robot_params("hubo2plus")
    legs = 2 * (p.thigh_m + p.shin_m)
    free = step_height_reach_m("hubo2plus")
    # one sole can at most stand a whole leg (hip to sole) above the other's hip
    assert p.ankle_to_sole_m < free <= legs + 1e-9
    assert step_height_reach_m("hubo2plus", -0.05, 0.05) <= free
    # a sole behind the other cannot be higher than one straight in front could be
    assert step_height_reach_m("hubo2plus", -5.0, -4.0) == -math.inf


def test_rungs_beyond_the_step_height_are_refused_by_the_spacing():
    tall = dataclasses.replace(load_ladder("drc"), rung_spacing_m=0.98, num_rungs=3)
    reasons = {s.what: s for s in reach_shortfalls(tall, "hubo2plus")}
    assert "rung_spacing_m" in reasons
    assert "rungs 0.98 m apart" in reasons["rung_spacing_m"].message
    assert reasons["rung_spacing_m"].reachable < 0.98


def test_plan_ladder_refuses_an_out_of_reach_ladder_in_under_5_s(tmp_path, capsys):
    spec = tmp_path / "wide.yaml"
    text = ladder_to_yaml(load_ladder("drc")).replace("name: drc", "name: wide")
    assert "spacing_m: 1.35" in text
    spec.write_text(text.replace("spacing_m: 1.35", "spacing_m: 2.2"))
    t0 = time.monotonic()
    assert main([str(spec), "-o", str(tmp_path / "w.traj")]) == 1
    assert time.monotonic() - t0 < 5.0
    err = capsys.readouterr().err
    assert "no plan: ladder 'wide' is out of the DRC-Hubo's reach: rails 2.20 m apart" in err
    assert not (tmp_path / "w.traj").exists()


def test_the_planner_and_a_batch_job_refuse_it_too(tmp_path):
    wide = dataclasses.replace(load_ladder("drc"), name="wide", rail_spacing_m=2.2)
    with pytest.raises(LadderOutOfReach, match="rails 2.20 m apart"):
        ClimbPlanner(wide)
    with pytest.raises(LadderOutOfReach):
        check_reach(wide, "drc-hubo")
    out = plan_job(PlanJob(ladder_key="wide", ladder=wide, seed=1), str(tmp_path))
    assert out["outcome"] == "no_plan" and out["where"] == "reach"
    assert "rails 2.20 m apart" in out["why"]


def test_the_hubo2plus_cannot_span_the_drc_ladder_s_rails():
    (short,) = reach_shortfalls(load_ladder("drc"), "hubo2plus")
    assert short.what == "rail_spacing_m" and short.reachable < 1.35
    assert reach_shortfalls(load_ladder("ship"), "hubo2plus") == []
