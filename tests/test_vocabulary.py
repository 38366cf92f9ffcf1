"""The vocabulary enums and the error root: one definition each, structured fields."""

import ast
import json
from pathlib import Path

import pytest

from robot.errors import HuboLadderError, InputError
from robot.vocabulary import (
    ArmMode,
    HoldTarget,
    HoldTargetError,
    HoldTargetKind,
    Limb,
    Side,
)

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("robot", "ladders", "primitives", "planner", "execute", "daemon")
BUILTIN_ERRORS = {"Exception", "RuntimeError", "ValueError", "KeyError", "TypeError", "OSError",
                  "LookupError", "ArithmeticError"}


def test_members_are_their_on_disk_strings():
    assert Limb.LEFT_HAND == "left_hand" and json.dumps([Limb.RIGHT_FOOT]) == '["right_foot"]'
    assert f"{ArmMode.PWM}" == "pwm" and Limb("left_foot") is Limb.LEFT_FOOT
    assert {"left": 1}[Side.LEFT] == 1


def test_limb_sides_and_kinds():
    assert [limb.side for limb in Limb] == [Side.LEFT, Side.RIGHT, Side.LEFT, Side.RIGHT]
    assert [limb.is_hand for limb in Limb] == [True, True, False, False]
    assert Limb.hand("right") is Limb.RIGHT_HAND and Limb.foot(Side.LEFT) is Limb.LEFT_FOOT


@pytest.mark.parametrize("text,kind,rung,side", [("floor", HoldTargetKind.FLOOR, None, None),
                                                 ("rung_0", HoldTargetKind.RUNG, 0, None),
                                                 ("rung_12", HoldTargetKind.RUNG, 12, None),
                                                 ("rail_left", HoldTargetKind.RAIL, None, "left")])
def test_hold_targets_parse_and_print_back(text, kind, rung, side):
    target = HoldTarget.parse(text)
    assert (target.kind, target.rung, target.side) == (kind, rung, side)
    assert str(target) == text


@pytest.mark.parametrize("text", ["rung_", "rung_x", "rung_03", "rail_up", "Floor", ""])
def test_a_bad_hold_target_is_an_input_error_that_lists_the_forms(text):
    with pytest.raises(HoldTargetError, match="'floor', 'rung_<i>' or 'rail_left'") as info:
        HoldTarget.parse(text)
    assert isinstance(info.value, InputError) and info.value.text == text


def test_every_project_error_derives_from_the_root():
    """No class of the six packages subclasses a built-in exception without the root."""
    outside = []
    for pkg in PACKAGES:
        for path in (ROOT / pkg).rglob("*.py"):
            for node in ast.walk(ast.parse(path.read_text())):
                if not isinstance(node, ast.ClassDef):
                    continue
                bases = {b.id for b in node.bases if isinstance(b, ast.Name)}
                if bases & BUILTIN_ERRORS and not bases - BUILTIN_ERRORS:
                    outside.append(f"{path.relative_to(ROOT)}:{node.name}")
    assert outside == ["robot/errors.py:HuboLadderError"]


def test_planner_errors_carry_fields():
    from planner.configuration.validity import Verdict
    from planner.paths.interpolation import InterpolationError
    from planner.time_limit import TimeLimitExceeded
    from robot.vocabulary import InterpolationFailure, RejectCause

    refused = Verdict(False, "collision a–b", 0.01, 0.5, cause=RejectCause.COLLISION)
    exc = InterpolationError(InterpolationFailure.MIDPOINT_INFEASIBLE,
                             "midpoint infeasible: collision a–b", 3, refused)
    assert isinstance(exc, HuboLadderError) and exc.depth == 3
    assert exc.cause is InterpolationFailure.MIDPOINT_INFEASIBLE
    assert exc.verdict_cause is RejectCause.COLLISION
    assert str(exc) == "midpoint infeasible: collision a–b (recursion depth 3)"
    limit = TimeLimitExceeded(2.5)
    assert isinstance(limit, HuboLadderError) and limit.limit_s == 2.5 and "2.5 s" in str(limit)
