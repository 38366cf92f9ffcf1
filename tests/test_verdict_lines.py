"""validate-plan's printed verdict (issue 20 item 8): a few short lines, the full text in the
JSON; rungs counted only when climbed."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest

sys.path.insert(0, str(Path(__file__).parent / "fixtures"))

from make_fixture import cached_reach_fixture  # noqa: E402

from execute.validate.cli import CAUSE_CHARS, main, verdict_lines  # noqa: E402
from execute.validate.metrics import rungs_climbed  # noqa: E402
from execute.validate.verdict import Failure, Verdict  # noqa: E402
from robot.plan_sidecar import HoldRecord, Segment  # noqa: E402
from robot.vocabulary import FailureCause  # noqa: E402


def _segment(first: int, last: int, rung: int, feet: dict[str, str]) -> Segment:
    holds = {limb: HoldRecord(target, (0.0, 0.0, 0.0)) for limb, target in feet.items()}
    return Segment("climbRung", "limb", rung, first, last, holds, ())


SEGMENTS = (_segment(1, 100, 0, {"left_foot": "floor", "right_foot": "floor"}),
            _segment(101, 200, 0, {"left_foot": "rung_0", "right_foot": "floor"}),
            _segment(201, 300, 1, {"left_foot": "rung_0", "right_foot": "rung_1"}))


def test_rungs_climbed_counts_segments_played_to_their_end():
    assert rungs_climbed(SEGMENTS, 150) == 0  # stopped on the way to the first rung
    assert rungs_climbed(SEGMENTS, 200) == 1
    assert rungs_climbed(SEGMENTS, 299) == 1
    assert rungs_climbed(SEGMENTS, 300) == 2


def _fake(verdict: Verdict, rungs: int = 0):
    sidecar = SimpleNamespace(ladder={"geometry": {"num_rungs": 9}}, line_count=300,
                              segment_at=lambda line: SEGMENTS[(line - 1) // 100])
    metrics = SimpleNamespace(rungs_climbed=rungs, peak_torque_ratio=1.0, peak_torque_joint="LKN",
                              max_hand_turn_per_grasp_deg={"left": 26.0, "right": 49.0},
                              min_com_margin_m=0.031, min_com_margin_line=91,
                              lines_played=300)
    return SimpleNamespace(verdict=verdict, simulated_s=103.0), metrics, sidecar


def test_a_failure_prints_cause_time_line_and_what_to_try():
    why = ("board JMC6 tripped at t = 86.68 s: LKN held |τ| ≥ 59.4 N·m (99% of its 60 N·m "
           "limit) for 0.50 s (peak 59.9 N·m)" + "; more" * 500)
    failure = Failure(FailureCause.BOARD_TRIP, 86.68, 250, why, {})
    lines = verdict_lines(*_fake(Verdict(False, failure, {})))
    assert lines[0] == "verdict: failed (board_trip)"
    assert lines[1].startswith("cause:   board JMC6 tripped") and lines[1].endswith("…")
    assert lines[2] == "when:    t = 86.68 s, line 250 of 300 (climbRung@rung1, limb phase)"
    assert lines[3].startswith("next:    ") and "--max-torque-ratio" in lines[3]
    assert "climbed 0 of 9 rungs" in lines[4] and "49° per grasp" in lines[4]
    assert len(lines) == 5 and all(len(line) <= CAUSE_CHARS + 20 for line in lines[:3])


def test_a_failure_cause_is_the_vocabulary_and_its_json_the_plain_string():
    failure = Failure("grasp_lost", 1.0, 2, "why")
    assert failure.cause is FailureCause.GRASP_LOST
    assert json.dumps({"cause": failure.cause.value}) == '{"cause": "grasp_lost"}'
    with pytest.raises(ValueError, match="slipped"):
        Failure("slipped", 1.0, 2, "why")


def test_a_climb_prints_holds_and_time(tmp_path_factory, tmp_path, capsys):
    lines = verdict_lines(*_fake(Verdict(True, None, {"left_foot": "ok", "right_foot": "ok"}),
                                 rungs=2))
    assert lines[:3] == ["verdict: climbed", "holds:   every final hold in contact (2 of 2)",
                         "time:    103.0 s simulated, 300 lines"]
    assert "min CoM margin 3.1 cm at line 91" in lines[3]
    # the command: short lines on stdout, the whole explanation in the JSON
    plan = cached_reach_fixture(tmp_path_factory.getbasetemp())
    assert main([str(plan), "--open-loop", "--json", str(tmp_path / "r.json")]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0] == "verdict: climbed" and max(len(line) for line in out) < 220
    result = json.loads((tmp_path / "r.json").read_text())
    assert result["why"].startswith("every final hold in contact")
    m = result["metrics"]
    assert m["rungs_climbed"] == 0 and m["simulated_s_per_rung"] is None  # the fixture's
    # holds are the floor and the rails: it climbs no rung
    assert set(m["max_hand_turn_per_grasp_deg"]) == {"left", "right"}
