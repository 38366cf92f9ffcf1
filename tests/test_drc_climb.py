"""End to end on the bundled DRC ladder: `plan-ladder drc --seed 1 --top-rung 0` (the
mount: hands on the rails, both feet onto rung 0, straighten) climbs in MuJoCo under
`validate-plan --strategy mixed`, closed loop: both grasps verified from the finger
encoders before the plan loads them, no board trip, every final hold in contact (about
1–2 minutes).

The whole ladder's rate over seeds is measured by `batch-eval`, not here
(docs/results.md): a test pins behaviour, a rate needs many runs.
"""

from __future__ import annotations

import json

from execute.validate.cli import main as validate_main
from planner.cli import main as plan_main
from robot.plan_sidecar import read_sidecar, sidecar_path


def test_the_drc_mount_climbs_closed_loop(tmp_path):
    plan = tmp_path / "mount.traj.gz"
    assert plan_main(["drc", "--seed", "1", "--top-rung", "0", "-o", str(plan)]) == 0
    final = read_sidecar(sidecar_path(plan)).final_holds
    assert {final[f].target for f in ("left_foot", "right_foot")} == {"rung_0"}
    result = tmp_path / "result.json"
    assert validate_main([str(plan), "--strategy", "mixed", "--json", str(result)]) == 0
    r = json.loads(result.read_text())
    assert r["verdict"] == "climbed" and r["loop"] == "closed"
    assert set(r["final_holds"].values()) == {"ok"}
    assert set(r["final_holds"]) == {"left_foot", "right_foot", "left_hand", "right_hand"}
    assert r["board_trips"] == []
    assert r["motion"]["counts"]["grasp verified"] == 2
    assert "stop" not in r["motion"]["counts"]
