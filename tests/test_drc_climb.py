"""End to end on the bundled DRC ladder: `plan-ladder drc --seed 2 --top-rung 0` (the
mount: hands on the rails, both feet onto rung 0, straighten) climbs in MuJoCo under
`validate-plan --strategy mixed`, closed loop: both grasps verified from the finger
encoders before the plan loads them, no board trip, every final hold in contact (about
1–2 minutes). On a ladder whose rungs stand lower than planned, the motion layer's
guarded landing reaches each foot down until its F/T sensor shows it standing, or stops
before the weight moves onto a foot that found nothing.

The whole ladder's rate over seeds is measured by `batch-eval`, not here
(docs/results.md): a test pins behaviour, a rate needs many runs. Seed 2, because its
mount keeps a margin: the leg relief's lift peaks at 68 N of its 80 N (seeds 1 and 3 use
all of it, their left knee stays at its limit, and seed 1's verdict flipped when the
rails' ends moved by 1e-16 m, 2026-11-28).
"""

from __future__ import annotations

import dataclasses
import json

import pytest

from execute.validate.cli import main as validate_main
from execute.validate.simulate import SimulationOptions, simulate
from ladders.loader import load_ladder
from planner.cli import main as plan_main
from robot.plan_sidecar import read_sidecar, sidecar_path
from robot.trajectory_file import read_trajectory


@pytest.fixture(scope="module")
def mount(tmp_path_factory):
    plan = tmp_path_factory.mktemp("mount") / "mount.traj.gz"
    assert plan_main(["drc", "--seed", "2", "--top-rung", "0", "-o", str(plan)]) == 0
    return plan


def test_the_drc_mount_climbs_closed_loop(mount, tmp_path):
    final = read_sidecar(sidecar_path(mount)).final_holds
    assert {final[f].target for f in ("left_foot", "right_foot")} == {"rung_0"}
    result = tmp_path / "result.json"
    assert validate_main([str(mount), "--strategy", "mixed", "--json", str(result)]) == 0
    r = json.loads(result.read_text())
    assert r["verdict"] == "climbed" and r["loop"] == "closed"
    assert set(r["final_holds"].values()) == {"ok"}
    assert set(r["final_holds"]) == {"left_foot", "right_foot", "left_hand", "right_hand"}
    assert r["board_trips"] == []
    assert r["motion"]["counts"]["grasp verified"] == 2
    assert "stop" not in r["motion"]["counts"]


def _on_lower_rungs(mount, drop_m: float):
    """The mount played closed loop on the DRC ladder with its rungs ``drop_m`` lower
    (along the rung line; the rails stay where they were)."""
    sc = read_sidecar(sidecar_path(mount))
    traj = read_trajectory(mount, sc.rate_hz)
    drc = load_ladder("drc")
    lower = dataclasses.replace(drc, first_rung_height_m=drc.first_rung_height_m - drop_m)
    return sc, simulate(traj, sc, lower, SimulationOptions(record_qpos=False))


def test_a_foot_short_of_a_lower_rung_reaches_down_to_it(mount):
    sc, run = _on_lower_rungs(mount, 0.02)
    landings = [e for e in run.motion["events"] if e["kind"] == "foot landing"]
    reached = [e for e in landings if "reaches down" in e["cause"]]
    stood = [e for e in landings if "stands on rung_0" in e["cause"]
             and "of reaching down" in e["cause"]]
    assert reached and stood, landings
    # it went down about as far as the rung was lowered, not the whole reach
    assert 0.005 < stood[0]["size_m"] < 0.03
    # the plan went on only once the foot stood: its step's last line waited for it
    step = next(seg for seg in sc.segments if seg.phase == "limb"
                and reached[0]["limb"] in seg.moving_limbs
                and seg.first_line <= reached[0]["line"] <= seg.last_line + 1)
    log = run.log
    waiting = (log.time_s >= reached[0]["time_s"]) & (log.time_s < stood[0]["time_s"])
    assert waiting.any() and (log.line_index[waiting] <= step.last_line - 1).all()
    assert run.motion["stop"] is None


def test_a_foot_that_finds_no_rung_stops_the_climb_before_loading_it(mount):
    sc, run = _on_lower_rungs(mount, 0.06)
    f = run.verdict.failure
    assert f is not None and f.cause == "foothold_unverified", run.verdict
    assert "found no rung" in f.why and "not moved onto it" in f.why
    stop = run.motion["stop"]
    step = next(seg for seg in sc.segments if seg.phase == "limb"
                and stop["limb"] in seg.moving_limbs)
    assert run.log.line_index.max() <= step.last_line - 1
