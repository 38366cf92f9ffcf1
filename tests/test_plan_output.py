"""planner.output and planner.arm_schedule: the trajectory and sidecar of a plan (round
trip, mode schedule, determinism)."""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

sys.path.insert(0, str(Path(__file__).parent))

from synthetic_plan import synthetic_plan  # noqa: E402

from ladders.loader import parse_ladder_yaml  # noqa: E402
from planner import arm_schedule, output  # noqa: E402
from planner.arm_schedule import PWM_RAIL_DISTANCE_M, arm_mode_runs  # noqa: E402
from planner.contacts import Hold  # noqa: E402
from planner.output import FEEDFORWARD_EVERY_LINES, write_plan  # noqa: E402
from planner.search import SearchResult  # noqa: E402
from robot.joints import ARM_JOINTS  # noqa: E402
from robot.plan_sidecar import (  # noqa: E402
    SidecarError,
    hand_holding_lines,
    read_sidecar,
    sidecar_path,
)
from robot.trajectory_file import read_trajectory  # noqa: E402


@pytest.fixture(scope="module")
def plan():
    return synthetic_plan()


@pytest.fixture(scope="module")
def written(plan, tmp_path_factory):
    planner, result, q0 = plan
    path = tmp_path_factory.mktemp("out") / "syn.traj"
    out = write_plan(result, planner, path, 200.0, {"search_s": 1.5}, q_start=q0)
    return out


def test_sidecar_round_trip(plan, written):
    planner, result, _ = plan
    sc = read_sidecar(written.sidecar_path)
    assert written.sidecar_path == sidecar_path(written.traj_path)
    traj = read_trajectory(written.traj_path, sc.rate_hz, sc.robot)
    assert sc.line_count == len(traj) == written.timed.line_count
    assert sc.robot == "drc-hubo" and sc.rate_hz == 200.0 and sc.seed == planner.seed
    assert parse_ladder_yaml(yaml.safe_dump(sc.ladder)) == planner.spec
    # Segments tile the file in order.
    assert sc.segments[0].first_line == 1 and sc.segments[-1].last_line == sc.line_count
    for a, b in zip(sc.segments, sc.segments[1:], strict=False):
        assert b.first_line == a.last_line + 1
    assert [(s.primitive, s.phase, s.rung) for s in sc.segments] == [
        ("straighten", "body", 0), ("straighten", "dwell", 0), ("straighten", "grasp", 1),
        ("straighten", "body", 1), ("straighten", "dwell", 1)]
    feet = {h.limb: h for h in result.final_stance.holds}
    for seg in sc.segments:
        assert set(seg.holds) == {"left_foot", "right_foot"}
        for limb, rec in seg.holds.items():
            assert rec.target == "floor"
            np.testing.assert_allclose(rec.position_m, feet[limb].T_world_frame[:3, 3])
    assert set(sc.final_holds) == {"left_foot", "right_foot"}
    # Read back equals written (JSON keeps floats exactly).
    assert sc.segments == written.sidecar.segments
    assert {k: [tuple(r) for r in v] for k, v in sc.arm_modes.items()} == \
        written.sidecar.arm_modes


def test_sidecar_metrics_and_provenance(written):
    sc = read_sidecar(written.sidecar_path)
    m = sc.metrics
    assert m["min_stability_margin_m"] == pytest.approx(0.04)
    assert m["max_torque_ratio"] == pytest.approx(0.5)
    assert 0.0 < m["min_clearance_m"] < 0.5
    assert m["primitives"]["straighten"] == {"time_s": pytest.approx(0.3), "samples": 8,
                                             "backtracks": 1}
    assert [s["label"] for s in m["steps"]] == ["straighten@rung0", "straighten@rung1"]
    assert m["duration_s"] == pytest.approx((sc.line_count - 1) / 200.0)
    assert {"search_s", "timing_s", "output_s"} <= set(sc.timings_s)
    assert sc.planner_version == output.planner_version() != ""


def test_hands_in_the_air_are_in_position_mode(written):
    sc = read_sidecar(written.sidecar_path)
    assert sc.arm_modes == {"left": [(1, sc.line_count, "position")],
                            "right": [(1, sc.line_count, "position")]}


def test_arm_mode_runs():
    pwm = np.array([0, 0, 1, 1, 1, 0, 1], dtype=bool)
    assert arm_mode_runs(pwm) == [(1, 2, "position"), (3, 5, "pwm"), (6, 6, "position"),
                                  (7, 7, "pwm")]
    assert arm_mode_runs(np.ones(4, dtype=bool)) == [(1, 4, "pwm")]
    assert arm_mode_runs(np.zeros(0, dtype=bool)) == []


def test_palm_distances_match_the_rail_geometry(plan):
    planner, result, q0 = plan
    d = arm_schedule.palm_rail_distances(arm_schedule.palm_poses(np.array([q0]), planner.kin),
                                   planner.geom)
    palm = planner.kin.frame_pose(q0, "L_palm")[:3, 3]
    expect = np.linalg.norm(palm - planner.geom.closest_rail_point("left", palm))
    assert d["left"][0] == pytest.approx(expect)
    assert d["left"][0] > PWM_RAIL_DISTANCE_M  # standing on the floor, hands down


def test_held_palm_turn_counts_from_each_grasp(plan):
    planner, _, q0 = plan
    kin = planner.kin
    configs = np.tile(q0, (8, 1))
    wrist = kin.q_index["LWR"]
    configs[:, wrist] += [0.0, 0.1, 0.2, 0.35, 0.5, 0.5, 0.6, 0.9]
    held = np.array([0, 1, 1, 1, 0, 1, 1, 0], dtype=bool)  # two holds: lines 2–4, 6–7
    turn = arm_schedule.held_palm_turn_rad(arm_schedule.palm_poses(configs, kin),
                                     {"left": held, "right": held & False})
    np.testing.assert_allclose(turn["left"], [0, 0, 0.1, 0.25, 0, 0, 0.1, 0], atol=1e-9)
    assert not turn["right"].any()


def _closing_on_the_rails(result, monkeypatch) -> SearchResult:
    """The left palm closes in on its rail over the plan and the right hand holds its
    rail in the grasp segment."""
    def fake(palms, geom):
        n = len(palms["left"])
        return {"left": np.linspace(0.10, 0.0, n), "right": np.full(n, 0.2)}

    monkeypatch.setattr(arm_schedule, "palm_rail_distances", fake)
    grasp = result.segments[1]
    T = np.eye(4)
    rail = Hold("right_hand", "rail_right", T, np.zeros((2, 3)), np.tile([0, 0, 1.0], (2, 1)))
    segments = list(result.segments)
    segments[1] = dataclasses.replace(grasp, holds=grasp.holds + (rail,))
    return SearchResult(segments, result.final_stance, result.step_stats, result.total_s)


def test_mode_schedule_from_palm_distance_and_grasps(plan, tmp_path, monkeypatch):
    planner, result, q0 = plan
    res = _closing_on_the_rails(result, monkeypatch)
    out = write_plan(res, planner, tmp_path / "m.traj", 200.0, q_start=q0, clearance_every=0)
    sc = read_sidecar(out.sidecar_path)
    n = sc.line_count
    first_pwm = int(np.argmax(np.linspace(0.10, 0.0, n) <= PWM_RAIL_DISTANCE_M)) + 1
    assert sc.arm_modes["left"] == [(1, first_pwm - 1, "position"), (first_pwm, n, "pwm")]
    g = next(s for s in sc.segments if s.phase == "grasp")
    assert g.holds["right_hand"].target == "rail_right"
    assert sc.arm_modes["right"] == [(1, g.first_line - 1, "position"),
                                     (g.first_line, g.last_line, "pwm"),
                                     (g.last_line + 1, n, "position")]
    assert sc.metrics["min_clearance_m"] is None
    # the sidecar reports how far each held palm turns on its rail (its fingers only
    # close here, so neither turns)
    holding = {arm: hand_holding_lines(sc.segments, n, arm) for arm in ("left", "right")}
    turn = arm_schedule.held_palm_turn_rad(arm_schedule.palm_poses(out.timed.configs, planner.kin),
                                     holding)
    assert sc.metrics["max_held_palm_turn_rad"] == {arm: t.max() for arm, t in turn.items()}


def test_a_plan_for_rigid_arms_keeps_them_in_position_mode(plan, tmp_path, monkeypatch):
    """Its holding torques are beyond what a compliant arm gives."""
    planner, result, q0 = plan
    res = _closing_on_the_rails(result, monkeypatch)
    monkeypatch.setattr(planner, "config", dataclasses.replace(planner.config,
                                                               arm_strategy="position"))
    out = write_plan(res, planner, tmp_path / "r.traj", 200.0, q_start=q0, clearance_every=0)
    sc = read_sidecar(out.sidecar_path)
    assert sc.metrics["arm_strategy"] == "position"
    assert sc.metrics["position_torque_share"] == planner.config.position_torque_share
    assert sc.arm_modes == {arm: [(1, sc.line_count, "position")] for arm in ("left", "right")}


def test_same_input_same_bytes(plan, written, tmp_path):
    planner, result, q0 = plan
    again = write_plan(result, planner, tmp_path / "again.traj", 200.0, q_start=q0,
                       clearance_every=0)
    assert again.traj_path.read_bytes() == written.traj_path.read_bytes()
    slower = write_plan(result, planner, tmp_path / "slow.traj", 100.0, q_start=q0,
                        clearance_every=0)
    assert slower.traj_path.read_bytes() != written.traj_path.read_bytes()


def test_start_configuration_defaults_to_the_planners(plan, written, tmp_path):
    planner, result, q0 = plan
    out = write_plan(result, planner, tmp_path / "d.traj", 200.0, clearance_every=0)
    assert out.traj_path.read_bytes() == written.traj_path.read_bytes()


def test_arm_feedforward_is_each_free_arms_gravity_torque(plan, written):
    """With only the feet on the floor no contact force reaches an arm, so the torque LP's
    arm torques must be the arms' gravity torques (pinocchio's g(q), independently)."""
    import pinocchio as pin

    planner, _, _ = plan
    sc = read_sidecar(written.sidecar_path)
    ff = sc.arm_feedforward
    assert ff.every_lines == FEEDFORWARD_EVERY_LINES
    assert len(ff.torque_nm) == ff.rows_for(sc.line_count)
    assert set(ff.joints) == set(ARM_JOINTS["left"]) | set(ARM_JOINTS["right"])
    np.testing.assert_allclose(ff.torque_nm, written.sidecar.arm_feedforward.torque_nm,
                               atol=5e-4)  # the file keeps 1 mN·m
    model, data = planner.kin.model, planner.kin.data
    v_index = [model.joints[model.getJointId(n)].idx_v for n in ff.joints]
    for k in (0, len(ff.torque_nm) // 2, len(ff.torque_nm) - 1):
        q = written.timed.configs[min(k * ff.every_lines, sc.line_count - 1)]
        gravity = pin.computeGeneralizedGravity(model, data, q)[v_index]
        np.testing.assert_allclose(ff.torque_nm[k], gravity, atol=1e-3)
    assert np.abs(ff.torque_nm).max() > 1.0  # arms hanging forward do weigh


def test_sidecar_feedforward_is_validated(written, tmp_path):
    import json

    d = json.loads(written.sidecar_path.read_text())
    d["arm_feedforward"]["torque_nm"] = d["arm_feedforward"]["torque_nm"][:-1]
    bad = tmp_path / "bad.plan.json"
    bad.write_text(json.dumps(d))
    with pytest.raises(SidecarError, match=r"arm_feedforward.torque_nm: expected \d+ rows"):
        read_sidecar(bad)
    d["arm_feedforward"]["joints"][0] = "RKN"
    bad.write_text(json.dumps(d))
    with pytest.raises(SidecarError, match="arm_feedforward.joints: expected distinct arm"):
        read_sidecar(bad)
    del d["arm_feedforward"]
    bad.write_text(json.dumps(d))
    assert read_sidecar(bad).arm_feedforward is None  # older sidecars: no feed-forward
