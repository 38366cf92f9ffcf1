"""validate-plan: exit codes, the three strategies on the fixture, the result JSON."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent / "fixtures"))

from make_fixture import cached_reach_fixture  # noqa: E402

from execute.validate.cli import main  # noqa: E402
from robot.plan_sidecar import sidecar_path  # noqa: E402


@pytest.fixture(scope="module")
def plan(tmp_path_factory) -> Path:
    return cached_reach_fixture(tmp_path_factory.getbasetemp())


@pytest.fixture(scope="module")
def results(plan, tmp_path_factory) -> dict[str, dict]:
    out = tmp_path_factory.mktemp("results")
    res = {}
    for strategy in ("mixed", "position", "pwm"):
        path = out / f"{strategy}.json"
        code = main([str(plan), "--strategy", strategy, "--open-loop", "--json", str(path)])
        res[strategy] = {"code": code, **json.loads(path.read_text())}
    path = out / "pwm-closed.json"
    code = main([str(plan), "--strategy", "pwm", "--json", str(path)])
    res["pwm closed"] = {"code": code, **json.loads(path.read_text())}
    return res


def test_bad_file_exits_2_with_its_line(plan, tmp_path, capsys):
    bad = tmp_path / "bad.traj"
    lines = plan.read_text().splitlines()
    cols = lines[6].split()
    cols[3] = "oops"
    lines[6] = " ".join(cols)
    bad.write_text("\n".join(lines) + "\n")
    shutil.copy(sidecar_path(plan), sidecar_path(bad))
    assert main([str(bad)]) == 2
    err = capsys.readouterr().err
    assert f"{bad}:7:" in err and "RKN" in err


def test_missing_sidecar_and_bad_options_exit_2(plan, tmp_path, capsys):
    lone = tmp_path / "lone.traj"
    shutil.copy(plan, lone)
    assert main([str(lone)]) == 2
    assert "sidecar" in capsys.readouterr().err
    assert main([str(plan), "--placement-error", "1,2"]) == 2
    assert "placement-error" in capsys.readouterr().err
    # a negative misplacement is a value, not an option
    assert main([str(plan), "--placement-error", "-1,2"]) == 2
    assert "'-1,2': expected three numbers" in capsys.readouterr().err
    assert main([str(plan), "--battery", "300"]) == 2
    assert "battery" in capsys.readouterr().err


def test_mixed_climbs_the_fixture(results):
    r = results["mixed"]
    assert r["code"] == 0 and r["verdict"] == "climbed" and r["cause"] is None
    assert set(r["final_holds"].values()) == {"ok"}
    assert any("latched" in e for e in r["grasp_events"])
    assert r["metrics"]["real_time_factor"] > 0
    assert 0 < r["metrics"]["min_com_margin_m"] < 0.15  # CoM inside the feet while standing


def test_strategies_differ_and_say_why(results):
    """Open loop, as the thesis played them."""
    pos, pwm = results["position"], results["pwm"]
    assert results["mixed"]["code"] == 0
    # compliant arms cannot lift themselves to the rails (duty clamp, back-EMF)
    assert pwm["code"] == 1 and pwm["cause"] == "grasp_not_latched"
    assert "closed on nothing" in pwm["why"] and "cm from the rail axis" in pwm["why"]
    assert pwm["details"]["palm_to_axis_m"] > 0.02
    # position and mixed both grasp; the PWM hold phase of mixed tracks worse
    assert pos["code"] == 0
    te = {k: v["metrics"]["tracking_error_rad"] for k, v in results.items() if k in
          ("mixed", "position", "pwm")}
    assert te["mixed"]["left"] > 1.5 * te["position"]["left"]
    for arm in ("left", "right"):
        assert te["pwm"][arm] >= 10 * te["position"][arm]
    assert {r["strategy"] for r in results.values()} == {"mixed", "position", "pwm"}


def test_closed_loop_pwm_grasps_what_open_loop_misses(results):
    """The motion layer's gravity compensation and grasp checks get the PWM-only arms
    onto the rails of the fixture."""
    r = results["pwm closed"]
    assert r["loop"] == "closed" and r["code"] == 0 and r["verdict"] == "climbed"
    assert r["motion"]["counts"]["grasp verified"] == 2


def test_plots_written_or_rendering_reported(plan, tmp_path):
    # a fresh interpreter, so MUJOCO_GL=egl is set before mujoco is imported
    env = {**os.environ, "MUJOCO_GL": "egl"}
    out = tmp_path / "p"
    proc = subprocess.run([sys.executable, "-m", "execute.validate.cli", str(plan),
                           "--strategy", "position", "--plots", str(out)],
                          capture_output=True, text=True, env=env, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert (out / "tracking_left.png").stat().st_size > 1000
    assert (out / "plan_vs_sim.png").stat().st_size > 1000
    if not (out / "snapshots.png").exists():
        assert "no rendering" in proc.stderr
        pytest.skip("EGL rendering unavailable: " + proc.stderr.strip())
    assert (out / "snapshots.png").stat().st_size > 1000


def test_a_failure_is_compared_with_the_plan_at_its_line(results, plan):
    from ladders.loader import load_ladder
    from planner.verify.check import planned_loads
    from robot.plan_sidecar import read_sidecar
    from robot.trajectory_file import read_trajectory

    r = results["pwm"]
    c = r["plan_vs_sim"]
    assert c["line"] == r["line"] and c["time_s"] == pytest.approx(r["time_s"], abs=1e-3)
    assert "against the plan" in r["why"] and c["joints"][0]["joint"] in r["why"]
    departures = [abs(j["simulated_nm"] - j["planned_nm"]) / j["limit_nm"]
                  for j in c["joints"]]
    assert departures == sorted(departures, reverse=True) and departures[0] > 0
    # the planned side is check-plan's LP at the failure's line
    sidecar = read_sidecar(sidecar_path(plan))
    traj = read_trajectory(plan, sidecar.rate_hz, sidecar.robot)
    lp = planned_loads(traj, sidecar, load_ladder("drc"), [r["line"]])[0].torque
    for j in c["joints"]:
        assert j["planned_nm"] == pytest.approx(lp.torque(j["joint"]), abs=0.01)
    # limp arms missed the rails: no simulated grip force where the plan has one
    assert c["hold_forces_n"]["left_hand"]["simulated"] is None
    assert c["hold_forces_n"]["left_hand"]["planned"][2] > 0


def test_plan_and_simulation_carry_the_same_weight(results):
    # at rest at the end, the holds' vertical forces add up to the robot's weight in the
    # LP and in MuJoCo, and the body stands where the plan put it
    from robot.params import robot_params

    weight_n = robot_params("drc-hubo").total_mass_kg * 9.81
    c = results["mixed"]["plan_vs_sim"]
    forces = c["hold_forces_n"].values()
    assert sum(f["planned"][2] for f in forces) == pytest.approx(weight_n, rel=0.005)
    assert sum(f["simulated"][2] for f in forces) == pytest.approx(weight_n, rel=0.02)
    assert max(abs(x) for x in c["pelvis_offset_m"]) < 0.01 and c["pelvis_turn_deg"] < 1
