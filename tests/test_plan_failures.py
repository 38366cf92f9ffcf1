"""No-plan messages in user terms (`planner.failure_report`, issue 24): the furthest step
reached, its limb and hold, how far off in cm and degrees, the ladder parameters; the
solver's internals only with ``-v``."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ladders.loader import ladder_to_yaml, load_ladder
from planner.cli import main
from planner.configuration.ik import HoldMiss
from planner.configuration.validity import Verdict
from planner.failure_report import SampleFailure, explain_no_plan
from planner.search import ClimbPlanner, PlannerConfig, PlanningFailed, _StepRejected
from primitives.library import climb_sequence
from robot.vocabulary import RejectCause, StepFailure

#: What the solver's text looks like; it must stay out of the default message.
IK_TEXT = "IKResult("


def _missed(limb: str, target: str, position_m: float, angle_deg: float,
            stage: str = "way-point 2/3") -> SampleFailure:
    """A sample whose IK left ``limb`` ``position_m`` and ``angle_deg`` off its hold."""
    detail = f"{stage}: ik IKResult(NOT converged in 80 it, {position_m * 1000:.2f} mm)"
    return SampleFailure(StepFailure.WAYPOINT.value, stage,
                         Verdict(False, detail, np.nan, np.nan, cause=RejectCause.IK,
                                 ik_misses=(HoldMiss(limb, target, position_m,
                                                     math.radians(angle_deg)),)),
                         detail=detail)


def _over_torque(joint: str, ratio: float) -> SampleFailure:
    return SampleFailure(StepFailure.NO_LIFT_OFF.value, "lift-off",
                         Verdict(False, f"torque {ratio:.2f}× limit at {joint}", 0.01, ratio,
                                 cause=RejectCause.TORQUE, torque_joint=joint))


def test_message_names_the_deepest_step_its_limb_hold_and_miss_in_cm():
    steps = climb_sequence(2)
    mount, left_foot = steps[0], steps[1]
    assert (mount.primitive.name, left_foot.primitive.name) == ("placeHands", "placeLFoot")
    failures = ([_missed("left_foot", "rung_0", 0.051, 3.0)] * 3
                + [_missed("left_foot", "rung_0", 0.042, 2.5)] + [_over_torque("RKN", 1.31)])
    text = explain_no_plan(left_foot, failures, load_ladder("drc"), "every sample failed",
                           stopped_at=mount)
    first = text.splitlines()[0]
    assert first.startswith("no plan: placeLFoot at rung 0 (left foot onto rung 0), the "
                            "furthest step reached")
    assert "backtracked to placeHands at rung 0" in first
    assert "4 × at way-point 2 of 3: the left foot could not reach its way-point towards " \
           "rung 0, at best 4.2 cm and 2.5° off" in text  # the closest of the four
    assert "slope 60°, first rung 0.305 m high" in text
    assert "1 × lifting off: RKN (right knee) needs at best 1.31× its torque limit" in text
    assert IK_TEXT not in text


def test_the_search_reports_the_deepest_step_after_backtracking(monkeypatch):
    """placeHands succeeds once, then never again; placeLFoot always misses rung 0: the
    search backtracks to placeHands and stops there, and the message blames placeLFoot."""
    spec = load_ladder("drc")
    planner = ClimbPlanner(spec, config=PlannerConfig(samples_per_step=5, max_backtracks=3))
    mounted = []

    def try_step(step, q, stance, radius_m, stats, attempt=0):
        if step.primitive.name == "placeHands" and not mounted:
            mounted.append(step)
            return [], q, stance
        miss = _missed("left_foot", "rung_0", 0.03, 1.0)
        if step.primitive.name == "placeHands":
            miss = _over_torque("LWP", 1.5)
        raise _StepRejected(StepFailure(miss.cause), miss.detail, miss.stage, miss.verdict)

    monkeypatch.setattr(planner, "try_step", try_step)
    with pytest.raises(PlanningFailed) as err:
        planner.plan(top_rung=1)
    assert err.value.step.primitive.name == "placeHands"  # where it stopped
    text = err.value.progress.explain(spec, err.value.stop)
    assert text.startswith("no plan: placeLFoot at rung 0 (left foot onto rung 0), the "
                           "furthest step reached")
    assert "the left foot could not reach its way-point towards rung 0, at best 3.0 cm" in text
    assert "LWP" not in text  # placeHands' own failures are not the reasons given


def _steep_ladder(tmp_path):
    """A 75° ladder with cylinder rungs 0.28 m apart and rails 0.62 m apart: placeHands
    fails in seconds (issue 24)."""
    text = ladder_to_yaml(load_ladder("drc")).replace("name: drc", "name: steep")
    for old, new in (("slope_deg: 60.0", "slope_deg: 75.0"),
                     ("rung_spacing_m: 0.305", "rung_spacing_m: 0.28"),
                     ("rung_shape: box", "rung_shape: cylinder"),
                     ("rung_depth_m: 0.102", "rung_depth_m: 0.032"),
                     ("spacing_m: 1.35", "spacing_m: 0.62")):
        assert old in text
        text = text.replace(old, new)
    path = tmp_path / "steep.yaml"
    path.write_text(text)
    return path


def test_cli_no_plan_is_in_user_terms_and_internals_need_v(tmp_path, capsys):
    ladder = _steep_ladder(tmp_path)
    argv = [str(ladder), "--samples", "8", "--time-limit", "60", "-o",
            str(tmp_path / "steep.traj")]
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert "no plan: placeHands at rung 0 (left hand onto the left rail, right hand onto the " \
           "right rail): every sample failed" in err
    assert "hand could not reach" in err and " cm and " in err
    assert "rails 0.62 m apart" in err
    assert IK_TEXT not in err
    assert main(argv + ["-v"]) == 1
    assert IK_TEXT in capsys.readouterr().err


def test_batch_eval_s_no_plan_is_plan_ladder_s_message(tmp_path):
    """A batch's no-plan record explains the failure as plan-ladder does; the search's
    own text is kept apart, under ``search_reason``."""
    from execute.batch.jobs import PlanJob, plan_job

    spec = load_ladder(str(_steep_ladder(tmp_path)))
    outcome = plan_job(PlanJob("steep", spec, 1, time_limit_s=60.0), str(tmp_path))
    assert outcome["outcome"] == "no_plan" and outcome["where"] == "placeHands at rung 0"
    assert outcome["why"].startswith("no plan: placeHands at rung 0 (left hand onto the left "
                                     "rail, right hand onto the right rail)")
    assert "rails 0.62 m apart" in outcome["why"] and IK_TEXT not in outcome["why"]
    assert IK_TEXT in outcome["search_reason"]
