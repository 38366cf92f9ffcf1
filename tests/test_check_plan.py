"""check-plan: a good plan passes; a moved hold or a joint past its limit fails naming the
line; bad input exits 2."""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))

from synthetic_plan import write_synthetic_plan  # noqa: E402

from planner.verify.check import (  # noqa: E402
    CHECKS,
    CheckResult,
    allowed_contacts,
    check_held_wrists,
)
from planner.verify.cli import main  # noqa: E402
from robot.joints import JOINT_INDEX  # noqa: E402
from robot.limits import joint_limits  # noqa: E402
from robot.plan_sidecar import HoldRecord, Segment, sidecar_path  # noqa: E402


@pytest.fixture(scope="module")
def good(tmp_path_factory) -> Path:
    return write_synthetic_plan(tmp_path_factory.mktemp("plan") / "good.traj")


def _copy(src: Path, dst: Path) -> Path:
    shutil.copy(src, dst)
    shutil.copy(sidecar_path(src), sidecar_path(dst))
    return dst


def test_good_plan_passes(good, capsys):
    assert main([str(good), "--ladder", "drc"]) == 0
    out = capsys.readouterr().out
    for check in CHECKS:
        assert check in out
    assert "FAIL" not in out


def test_moved_hold_fails_naming_the_line(good, tmp_path, capsys):
    bad = _copy(good, tmp_path / "moved.traj")
    side = sidecar_path(bad)
    d = json.loads(side.read_text())
    seg = d["segments"][3]  # the rise: right foot said to stand 5 cm further forward
    seg["holds"]["right_foot"]["position_m"][0] += 0.05
    side.write_text(json.dumps(d))
    assert main([str(bad), "--ladder", "drc", "--every", "50"]) == 1
    err = capsys.readouterr().err
    line = int(err.split("holds fails at line ")[1].split(":")[0])
    assert line == seg["first_line"]  # every line of it is as far off: the first is named
    assert "right_foot 5.00 cm from its hold on floor" in err


def test_a_held_wrist_near_zero_pitch_fails_naming_the_line():
    """While a foot is in the air, a hand holding a rail keeps its wrist pitch the plan's
    margin from zero; a hand in the air, or holding with both feet down, may pass zero; a
    plan made without a margin has nothing to meet."""
    rail = HoldRecord("rail_right", (0.3, -0.3, 1.0))
    left, right = HoldRecord("floor", (0.0, 0.1, 0.0)), HoldRecord("floor", (0.0, -0.1, 0.0))
    feet = {"left_foot": left, "right_foot": right}
    segs = [Segment("placeHands", "limb", 0, 1, 10, feet, ("right_hand",)),
            Segment("placeLFoot", "body", 0, 11, 20, {**feet, "right_hand": rail}),
            Segment("placeLFoot", "limb", 0, 21, 30, {"right_foot": right, "right_hand": rail},
                    ("left_foot",))]
    traj = np.zeros((30, 40))
    traj[:, JOINT_INDEX["RWP"]] = -0.3
    traj[4, JOINT_INDEX["RWP"]] = 0.0  # in the air: allowed
    traj[14, JOINT_INDEX["RWP"]] = 0.0  # held, both feet down: allowed
    traj[24, JOINT_INDEX["RWP"]] = -0.1  # held, a foot in the air: inside a 0.15 rad margin
    result = CheckResult("held wrists")
    check_held_wrists(result, traj, segs, 0.15)
    assert not result.ok and result.failing_lines == 1 and result.worst_line == 25
    assert "RWP = -0.1000 rad" in result.detail
    unbounded = CheckResult("held wrists")
    check_held_wrists(unbounded, traj, segs, 0.0)
    assert unbounded.ok and unbounded.value == pytest.approx(0.1)
    assert "planned without a margin" in unbounded.detail


def _knee_past_its_limit(good, path):
    """A copy of ``good`` whose line 100 puts RKN 0.2 rad past its upper limit."""
    bad = _copy(good, path)
    lines = bad.read_text().splitlines()
    cols = lines[99].split()
    k = JOINT_INDEX["RKN"]
    cols[k] = repr(float(joint_limits().upper_rad[k]) + 0.2)
    lines[99] = " ".join(cols)
    bad.write_text("\n".join(lines) + "\n")
    return bad


def test_joint_past_its_limit_fails_naming_the_line(good, tmp_path, capsys):
    bad = _knee_past_its_limit(good, tmp_path / "limit.traj")
    assert main([str(bad), "--every", "50"]) == 1
    err = capsys.readouterr().err
    assert "joint limits fails at line 100: RKN" in err
    assert "velocity fails at line 100" in err


def test_a_malformed_file_names_its_joints_past_their_limits_too(good, tmp_path, capsys):
    """The file is read once without the limits (check-plan reports them itself); a
    malformed one is bad input whose message names every problem, limits included."""
    bad = _knee_past_its_limit(good, tmp_path / "both.traj")
    lines = bad.read_text().splitlines()
    lines[6] = lines[6].replace(" ", " oops ", 1)
    bad.write_text("\n".join(lines) + "\n")
    assert main([str(bad)]) == 2
    err = capsys.readouterr().err
    assert f"{bad}:7:" in err and "'oops' is not a number" in err
    assert f"{bad}:100:" in err and "(RKN)" in err and "outside the joint limits" in err


def test_bad_input_exits_2(good, tmp_path, capsys):
    lone = tmp_path / "lone.traj"
    shutil.copy(good, lone)
    assert main([str(lone)]) == 2
    assert "sidecar" in capsys.readouterr().err
    broken = _copy(good, tmp_path / "broken.traj")
    lines = broken.read_text().splitlines()
    lines[6] = lines[6].replace(" ", " oops ", 1)
    broken.write_text("\n".join(lines) + "\n")
    assert main([str(broken)]) == 2
    assert f"{broken}:7:" in capsys.readouterr().err
    short = _copy(good, tmp_path / "short.traj")
    short.write_text("".join(short.read_text().splitlines(keepends=True)[:-5]))
    assert main([str(short)]) == 2
    assert "line_count" in capsys.readouterr().err
    assert main([str(good), "--ladder", "nosuch"]) == 2
    assert "unknown ladder 'nosuch'" in capsys.readouterr().err
    assert main([str(good), "--every", "0"]) == 2


def test_moving_limbs_may_touch_what_they_leave_then_what_they_reach():
    def seg(holds, moving=()):
        return Segment("moveLFoot", "limb", 0, 1, 1,
                       {lb: HoldRecord(t, (0.0, 0.0, 0.0)) for lb, t in holds.items()},
                       moving)

    segs = [seg({"left_foot": "rung_0", "right_foot": "rung_0"}),
            seg({"right_foot": "rung_0"}, ("left_foot",)),
            seg({"left_foot": "rung_1", "right_foot": "rung_0"})]
    assert allowed_contacts(segs, 1, 0.2) == {"right_foot": "rung_0", "left_foot": "rung_0"}
    assert allowed_contacts(segs, 1, 0.8) == {"right_foot": "rung_0", "left_foot": "rung_1"}
    assert allowed_contacts(segs[:2], 1, 0.8)["left_foot"] == "rung_0"
    assert allowed_contacts(segs, 0, 0.5) == {"left_foot": "rung_0", "right_foot": "rung_0"}


def test_collision_is_reported(good, tmp_path, capsys):
    # Fold the standing (left) leg: the body drops and the right shin goes into the floor.
    bad = _copy(good, tmp_path / "floor.traj")
    q = np.loadtxt(bad)
    for j, v in (("LHP", -1.4), ("LKN", 2.5)):
        q[-1, JOINT_INDEX[j]] = v
    from robot.trajectory_file import format_trajectory

    bad.write_text(format_trajectory(q))
    assert main([str(bad), "--every", "100"]) == 1
    err = capsys.readouterr().err
    assert f"collision fails at line {len(q)}" in err
    assert "floor" in err.split("collision fails")[1].splitlines()[0]
    assert f"stability margin fails at line {len(q)}" in err


def test_every_line_is_checked_by_default(good, tmp_path, capsys):
    """One line in the middle of the rise folds the standing leg (the right shin goes into
    the floor): the default finds it; ``--every 50``, which skips that line's collision
    and statics, does not. Holds, limits and speed are checked on every line either way."""
    from robot.trajectory_file import format_trajectory

    bad = _copy(good, tmp_path / "one.traj")
    q = np.loadtxt(bad)
    line = 1000  # the rise is lines 806-1174: not on its every-50 grid, not an end
    q[line - 1, JOINT_INDEX["LHP"]], q[line - 1, JOINT_INDEX["LKN"]] = -1.4, 2.5
    bad.write_text(format_trajectory(q))
    assert main([str(bad)]) == 1
    err = capsys.readouterr().err
    assert f"collision fails at line {line}: straighten/body:" in err
    assert f"stability margin fails at line {line}" in err
    assert main([str(bad), "--every", "50"]) == 1
    out, err = capsys.readouterr()
    assert "collision fails" not in err and "stability margin fails" not in err
    assert f"holds fails at line {line}:" in err  # the right foot leaves its hold


def test_a_lone_compliant_hand_is_not_counted_on_for_balance():
    """check-plan's support region of a one-hand stance is the feet's under mixed arms
    (`planner.statics.arm_capacity.balance_stance`), and reaches behind them with a rigid arm."""
    from ladders.geometry import LadderGeometry
    from ladders.loader import load_ladder
    from planner.verify.check import PlanVerifier

    spec = load_ladder("drc")
    p0, p1 = LadderGeometry(spec).rail_axis("right")
    hand = p0 + (p1 - p0) * (1.0 - p0[2]) / (p1[2] - p0[2])  # the rail 1 m up
    feet = {"left_foot": HoldRecord("floor", (0.0, 0.0885, 0.0)),
            "right_foot": HoldRecord("floor", (0.0, -0.0885, 0.0))}
    one_hand = Segment("moveLHand", "limb", 0, 1, 1,
                       {**feet, "right_hand": HoldRecord("rail_right", tuple(hand))},
                       ("left_hand",))
    on_feet = Segment("dwell", "dwell", 0, 1, 1, feet, ())
    region = {s: PlanVerifier(spec, "drc-hubo", s).stance(0, one_hand).region
              for s in ("mixed", "position")}
    feet_region = PlanVerifier(spec, "drc-hubo", "mixed").stance(0, on_feet).region
    np.testing.assert_allclose(region["mixed"].vertices, feet_region.vertices)
    behind = np.array([feet_region.vertices[:, 0].min() - 0.03, 0.0])
    assert region["mixed"].margin(behind) < 0 < region["position"].margin(behind)


def test_failing_lines_are_counted_once(good, tmp_path, capsys):
    """One line past a limit is "1 line"; the spike makes two bad steps: "2 lines"."""
    bad = _knee_past_its_limit(good, tmp_path / "spike.traj")
    assert main([str(bad), "--every", "50"]) == 1
    out = capsys.readouterr().out
    rows = {r.split("│")[1].strip(): r for r in out.splitlines() if r.count("│") > 2}
    assert "FAIL (1 line)" in rows["joint limits"]
    assert "FAIL (2 lines)" in rows["velocity"]


def test_user_text_is_printed_verbatim(good, tmp_path, capsys):
    """Rich would print `:100:` as an emoji and eat `[...]`: every message keeps them."""
    odd = _copy(good, tmp_path / "run:100:[red]x[bold].traj")
    assert main([str(odd), "--ladder", "drc", "--every", "50"]) == 0
    out = capsys.readouterr().out
    assert f"check-plan {odd} (" in out.replace("\n", "")  # the title, unwrapped by width
    lines = odd.read_text().splitlines()
    lines[99] = lines[99].replace(" ", " x", 1)  # a bad token on line 100
    odd.write_text("\n".join(lines) + "\n")
    assert main([str(odd), "--ladder", "drc"]) == 2
    err = capsys.readouterr().err
    assert f"{odd}:100:" in err and "💯" not in err
