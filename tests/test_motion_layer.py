"""The motion layer: sensed state only, gravity compensation, grasp checks, re-reach, stop."""

from __future__ import annotations

import ast
import dataclasses
import json
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent / "fixtures"))

from make_fixture import cached_reach_fixture  # noqa: E402

from daemon.control_modes import RefMode  # noqa: E402
from daemon.joint_control import JointController  # noqa: E402
from daemon.pwm import default_drc_gains, feedforward_duty_pct  # noqa: E402
from daemon.sim.board_model import BoardModel, PlacementError  # noqa: E402
from daemon.structs import STATE_DTYPE, new_sample  # noqa: E402
from execute.motion.config import MotionConfig, MotionConfigError  # noqa: E402
from execute.motion.estimator import StateEstimator  # noqa: E402
from execute.motion.grasp_check import GraspReading, read_grasp  # noqa: E402
from execute.motion.ladder_estimate import LadderEstimate, RailObservation  # noqa: E402
from execute.motion.robot_model import MotionRobotModel  # noqa: E402
from execute.motion.sensed_state import SensedState  # noqa: E402
from execute.validate.cli import main as validate_main  # noqa: E402
from execute.validate.simulate import SimulationOptions, simulate  # noqa: E402
from ladders.loader import load_ladder  # noqa: E402
from robot.joints import ARM_JOINTS, FINGER_JOINTS, JOINT_INDEX, NUM_JOINTS  # noqa: E402
from robot.kinematic_tree import FINGER_CLOSED_RAD  # noqa: E402
from robot.params import robot_params  # noqa: E402
from robot.plan_sidecar import read_sidecar, sidecar_path  # noqa: E402
from robot.trajectory_file import read_trajectory  # noqa: E402

MOTION_DIR = Path(__file__).parent.parent / "execute" / "motion"


@pytest.fixture(scope="module")
def reach(tmp_path_factory):
    path = cached_reach_fixture(tmp_path_factory.getbasetemp())
    sc = read_sidecar(sidecar_path(path))
    return path, read_trajectory(path, sc.rate_hz), sc, load_ladder("drc")


def test_the_layer_reads_no_simulator_state():
    """Nothing in the motion layer can reach MuJoCo, the board model or the grip latch:
    its modules import neither, and its only input is the daemon's state struct."""
    banned = ("mujoco", "daemon.sim", "daemon.board", "grasp_latch")
    for path in MOTION_DIR.glob("*.py"):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            names = []
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                names = [node.module or ""]
            for name in names:
                assert not any(name.startswith(b) or b in name for b in banned), (path, name)


def test_the_estimator_runs_on_the_state_struct_alone():
    """A hand-made state sample (no simulator anywhere): the robot standing in its zero
    pose, each foot carrying half its weight, fingers closed on a 25 mm rail."""
    model = MotionRobotModel()
    sample = new_sample(STATE_DTYPE)
    sample["time_s"] = 1.0
    fingers = [JOINT_INDEX[f] for f in FINGER_JOINTS["left"]]
    sample["pos"][fingers] = 0.09
    sample["imu"][0]["az"] = 9.81
    for k in (0, 1):
        sample["ft"][k]["fz"] = 0.5 * model.mass_kg * 9.81
    soles = {"left": np.array([0.0, 0.0885, 0.0]), "right": np.array([0.0, -0.0885, 0.0])}
    est = StateEstimator(model, soles).update(SensedState.from_sample(sample))
    assert est.standing == {"left": True, "right": True}
    assert np.allclose(est.sole_m["left"], soles["left"], atol=1e-6)
    assert est.T_world_pelvis[2, 3] == pytest.approx(robot_params().pelvis_height_m, abs=0.02)
    assert est.finger_curl_rad["left"] == pytest.approx(0.09)
    assert np.allclose(est.R_tilt, np.eye(3))
    s = SensedState.from_sample(sample)
    assert read_grasp("left", s.pos_rad, s.vel_rad_s, 0.025) is GraspReading.ON_RAIL
    sample["pos"][fingers] = FINGER_CLOSED_RAD
    s = SensedState.from_sample(sample)
    assert read_grasp("left", s.pos_rad, s.vel_rad_s, 0.025) is GraspReading.EMPTY
    sample["pos"][fingers] = 0.0  # fingers that never closed do not hold a rail
    s = SensedState.from_sample(sample)
    assert read_grasp("left", s.pos_rad, s.vel_rad_s, 0.025) is GraspReading.CLOSING
    with pytest.raises(TypeError):
        SensedState.from_sample(np.zeros(3))


def _standing_sample(model: MotionRobotModel, time_s: float, gyro_z_rad_s: float) -> SensedState:
    """Both feet carrying half the weight in the zero pose, the body IMU's gyro reading
    ``gyro_z_rad_s`` about the pelvis's z."""
    sample = new_sample(STATE_DTYPE)
    sample["time_s"] = time_s
    sample["imu"][0]["az"] = 9.81
    sample["imu"][0]["wz"] = gyro_z_rad_s
    for k in (0, 1):
        sample["ft"][k]["fz"] = 0.5 * model.mass_kg * 9.81
    return SensedState.from_sample(sample)


def _heading_rad(T: np.ndarray) -> float:
    return float(np.arctan2(T[1, 0], T[0, 0]))


STANDING_SOLES = {"left": np.array([0.0, 0.0885, 0.0]), "right": np.array([0.0, -0.0885, 0.0])}


def test_the_estimator_sees_a_stance_that_turns_on_its_feet():
    """Leg odometry cannot see a body that turns with its standing feet (the encoders do
    not move); the gyro does, and the feet are anchored again at its heading."""
    model = MotionRobotModel()
    est = StateEstimator(model, STANDING_SOLES)
    rate = 0.02  # [rad/s] for 3 s: 3.4°, as the body turned on `ship` while a hand reached
    for k in range(601):
        e = est.update(_standing_sample(model, k * 0.005, rate if k else 0.0))
    assert _heading_rad(e.T_world_pelvis) == pytest.approx(0.06, abs=0.006)
    assert est.foot_turns > 0
    # two standing feet turn about the point between them, which stays where they landed
    mid = 0.5 * (e.sole_m["left"] + e.sole_m["right"])
    assert np.allclose(mid, 0.0, atol=1e-3)
    across = e.sole_m["left"] - e.sole_m["right"]
    assert float(np.arctan2(-across[0], across[1])) == pytest.approx(0.06, abs=0.006)


def test_the_estimator_learns_the_gyros_bias_from_feet_that_stand_still():
    """A gyro that reads 20°/h at rest: the heading stays with the standing feet, within
    the turn that anchors a foot again, and the bias is learnt."""
    model = MotionRobotModel()
    est = StateEstimator(model, STANDING_SOLES)
    bias = 1e-4  # [rad/s]
    headings = [_heading_rad(est.update(_standing_sample(model, k * 0.05, bias)).T_world_pelvis)
                for k in range(4001)]  # 200 s at 20 Hz
    assert max(abs(h) for h in headings) < est.config.foot_turn_rad
    assert est.foot_turns == 0
    assert est.gyro_bias_rad_s == pytest.approx(bias, rel=0.1)


def test_a_hand_counts_as_holding_while_its_fingers_stand_around_the_rail():
    """The wrist roll's relief follows the fingers, not the plan's phase: a hand still
    closed on its rail holds it while it starts to open, and one closed on nothing or
    open does not."""
    from execute.motion.grasp_check import closed_around_rail

    pos = np.zeros(NUM_JOINTS)
    fingers = [JOINT_INDEX[f] for f in FINGER_JOINTS["right"]]
    for curl, holds in ((0.09, True), (0.07, True), (0.0, False), (FINGER_CLOSED_RAD, False)):
        pos[fingers] = curl
        assert closed_around_rail("right", pos, 0.025) is holds, curl
    assert not closed_around_rail("left", pos, 0.025)


def test_the_ladder_estimate_recovers_shift_and_yaw():
    est = LadderEstimate(max_shift_m=0.1, max_yaw_rad=0.3)
    up = np.array([0.5, 0.0, np.sqrt(3) / 2])
    true_shift, yaw, centre = np.array([0.02, -0.01, 0.0]), 0.03, np.zeros(3)
    for rail, y in (("rail_left", 0.675), ("rail_right", -0.675)):
        for height in (1.0, 1.3):
            p = np.array([0.2 + 0.5 * height, y, height])
            moved = p + true_shift + yaw * np.cross([0, 0, 1], p - centre)
            est.add(RailObservation(f"{rail}{height}", p, moved, up))
    p = np.array([0.9, 0.675, 1.6])
    want = true_shift + yaw * np.cross([0, 0, 1], p - centre)
    got = est.correction_m(p)
    across = np.eye(3) - np.outer(up, up)  # along the rail, nothing is observable
    assert np.linalg.norm(across @ (got - want)) < 0.003
    assert est.yaw_rad == pytest.approx(yaw, abs=0.005)


def test_the_ladder_placed_as_the_hands_found_it_has_its_rails_through_their_grasps():
    """Two grasps from the floor on a ladder misplaced by 3 cm, -2 cm and 2.3°: the spec
    `LadderEstimate.placed` returns (for a new plan) has each rail's axis through the
    palm that held it, and its placement within a few millimetres and a tenth of a
    degree of the real one."""
    from ladders.geometry import LadderGeometry

    planned = load_ladder("drc")
    real = PlacementError(0.03, -0.02, 0.04).apply(planned)
    g_plan, g_real = LadderGeometry(planned), LadderGeometry(real)
    T = g_real.T_world_ladder @ np.linalg.inv(g_plan.T_world_ladder)
    est = LadderEstimate(max_shift_m=0.1, max_yaw_rad=0.3)
    for side in ("left", "right"):
        a, b = g_plan.rail_axis(side)
        hold = a + 0.35 * (b - a)  # a grasp about a metre up the rail
        palm = T[:3, :3] @ hold + T[:3, 3]  # where that hold really is
        est.add(RailObservation(f"rail_{side}", hold, palm, (b - a) / np.linalg.norm(b - a)))
    placed = est.placed(planned)
    assert placed.placement_x_m == pytest.approx(real.placement_x_m, abs=0.004)
    assert placed.placement_y_m == pytest.approx(real.placement_y_m, abs=0.004)
    assert placed.placement_yaw_rad == pytest.approx(real.placement_yaw_rad, abs=0.002)
    g_new = LadderGeometry(placed)
    for side in ("left", "right"):
        a, b = g_real.rail_axis(side)
        for p in (a, b):  # the new plan's rail ends lie on the real rails' axes
            q0, q1 = g_new.rail_axis(side)
            d = (q1 - q0) / np.linalg.norm(q1 - q0)
            off = (p - q0) - ((p - q0) @ d) * d
            assert np.linalg.norm(off) < 0.006


def test_observations_on_the_ladder_move_the_shift_not_the_yaw():
    """Hands seen at different times on the ladder, with the body's heading drifting
    between them, must not read as the ladder turning: the floor's yaw is kept."""
    est = LadderEstimate(max_shift_m=0.1, max_yaw_rad=0.3)
    up = np.array([0.5, 0.0, np.sqrt(3) / 2])
    holds = {"rail_left": np.array([0.7, 0.675, 1.0]), "rail_right": np.array([0.7, -0.675, 1.0])}
    for rail, p in holds.items():
        est.add(RailObservation(rail, p, p, up))  # on the floor: where planned
    for rail, dx in (("rail_left", -0.03), ("rail_right", -0.01)):
        p = holds[rail]
        est.add(RailObservation(rail, p, p + [dx, 0.0, 0.0], up), fits_yaw=False)
    assert est.yaw_rad == pytest.approx(0.0, abs=1e-6)
    across = np.eye(3) - np.outer(up, up)
    assert np.allclose(across @ est.shift_m, across @ [-0.02, 0.0, 0.0], atol=1e-3)


def test_a_missed_grasp_searches_where_the_holding_hands_found_the_rails(reach):
    """Leg odometry cannot see a stance foot creep on its rung: the estimate moves with
    it and the rails seem to move the other way. The hands still holding their verified
    grasps measure that at each segment. The reaches keep the floor's estimate; a hand
    that closed on nothing first tries where the rails now seem to be. A hand that let go
    no longer counts."""
    from execute.motion.estimator import BodyEstimate
    from execute.motion.layer import MotionLayer, _Regrasp
    from execute.play.player import PlayerOptions, TrajectoryPlayer

    _path, traj, sc, ladder = reach
    grasp = next(k for k, seg in enumerate(sc.segments) if seg.phase == "grasp")
    hold_seg = sc.segments[grasp + 1]
    released = dataclasses.replace(hold_seg, holds={
        limb: h for limb, h in hold_seg.holds.items() if limb != "left_hand"})
    sc = dataclasses.replace(sc, segments=sc.segments + (released,))
    layer = MotionLayer(TrajectoryPlayer(traj, PlayerOptions(rate_hz=int(sc.rate_hz))),
                        traj, sc, ladder)
    planned = {side: np.asarray(hold_seg.holds[f"{side}_hand"].position_m)
               for side in ("left", "right")}

    def sense(offset_m):
        layer.estimate = BodyEstimate(0.0, np.eye(4), np.eye(3), {"left": True, "right": True},
                                      {s: planned[s] + offset_m for s in planned}, {},
                                      {"left": 0.09, "right": 0.09})

    layer.player.step(0.0, traj[0])
    layer.player.pause(0.0)  # the player waits while a grasp is verified
    sense(np.zeros(3))
    for side in ("left", "right"):
        layer._grasp_verified(_Regrasp(side, grasp, f"rail_{side}", planned[side], "verify", 0.0),
                              0.0, 0.0)
    creep = np.array([-0.03, 0.0, 0.0])  # the feet crept 3 cm towards the ladder
    sense(creep)
    layer._enter_segment(grasp + 1)
    rail_up = layer._rail_direction("rail_left")
    across = np.eye(3) - np.outer(rail_up, rail_up)
    assert np.allclose(across @ layer.rails.shift_m, across @ creep, atol=2e-3)
    assert np.allclose(layer.ladder.shift_m, 0.0, atol=1e-3)  # the reaches' estimate
    first = layer._candidates(_Regrasp("left", grasp, "rail_left", planned["left"], "verify", 0.0))
    assert np.allclose(across @ first[0], across @ creep, atol=2e-3)
    sense(np.zeros(3))  # the left hand let go: only the right one measures
    layer._enter_segment(len(sc.segments) - 1)
    assert set(layer._held_rails) == {"right"}


@pytest.mark.parametrize("limb,joints,change_rad", [
    ("left_foot", ("LHP", "LKN", "LAP"), (-0.5, 1.0, -0.5)),  # a crouch, the sole flat
    ("left_hand", ("LSP", "LSR", "LEB"), (-0.3, -0.4, 0.5)),  # the body rising past it
])
def test_a_holding_limbs_correction_stays_where_it_holds(reach, limb, joints, change_rad):
    """A limb's correction, once it holds, is kept as the displacement its references
    gave it there (a shift, and a turn: the ladder's yaw), realised at each later pose;
    not as the joint offset, which at another pose moves and turns the end frame
    elsewhere."""
    from execute.motion.estimator import BodyEstimate
    from execute.motion.layer import MotionLayer, _Blend
    from execute.play.player import PlayerOptions, TrajectoryPlayer

    _path, traj, sc, ladder = reach
    seg = sc.segments[-1]
    assert limb in seg.holds and limb not in seg.moving_limbs
    traj = traj.copy()
    end = seg.last_line - 1
    traj[end, [JOINT_INDEX[n] for n in joints]] += change_rad
    layer = MotionLayer(TrajectoryPlayer(traj, PlayerOptions(rate_hz=int(sc.rate_hz))),
                        traj, sc, ladder)
    layer.estimate = BodyEstimate(0.0, np.eye(4), np.eye(3), {"left": True, "right": True},
                                  {}, {}, {"left": 0.0, "right": 0.0})
    layer._line = start = seg.first_line - 1
    shift = np.array([0.02, -0.01, 0.01])
    yaw = np.radians(2.0)
    turn = np.array([[np.cos(yaw), -np.sin(yaw), 0.0], [np.sin(yaw), np.cos(yaw), 0.0],
                     [0.0, 0.0, 1.0]])
    dq0, _ = layer._limb_shift_dq(limb, start, shift, turn)
    layer._offsets[limb] = _Blend(dq0, dq0, float(start), float(start))
    layer._follow_holds(seg)
    dq = layer._offsets[limb].end
    frame = layer.model.chains[limb].frame
    T_end = layer.model.frame_in_pelvis(traj[end], frame)
    T_got = layer.model.frame_in_pelvis(traj[end] + dq, frame)
    assert np.allclose(T_got[:3, 3] - T_end[:3, 3], shift, atol=5e-4)
    assert np.allclose(T_got[:3, :3] @ T_end[:3, :3].T, turn, atol=5e-3)
    kept = layer.model.frame_in_pelvis(traj[end] + dq0, frame)  # the offset, kept
    assert not (np.allclose(kept[:3, 3] - T_end[:3, 3], shift, atol=5e-4)
                and np.allclose(kept[:3, :3] @ T_end[:3, :3].T, turn, atol=5e-3))


def test_once_off_the_floor_the_body_takes_the_ladders_placement(reach):
    """While a foot stands on the floor a hold on the ladder is reached where the ladder
    estimate puts it; once no foot does, the body takes the ladder's placement and the
    same hold needs no correction of its own."""
    from execute.motion.layer import MotionLayer
    from execute.play.player import PlayerOptions, TrajectoryPlayer

    _path, traj, sc, ladder = reach
    layer = MotionLayer(TrajectoryPlayer(traj, PlayerOptions(rate_hz=int(sc.rate_hz))),
                        traj, sc, ladder)
    hold = np.asarray(sc.segments[-1].holds["left_hand"].position_m)
    layer.ladder.add(RailObservation("rail_left", hold, hold + [-0.03, 0.0, 0.0],
                                     layer._rail_direction("rail_left")))
    on_floor = layer._ladder_shift(hold)
    assert np.linalg.norm(on_floor) > 0.02
    layer._body_on_ladder = True
    assert np.allclose(layer._ladder_shift(hold), 0.0)
    assert np.allclose(layer._body_shift_m(hold), on_floor)


def _layer_on_the_held_rails(reach, config: MotionConfig):
    """A layer on the reach's last line with both hands holding grasps made from the floor
    and the ladder alone carrying the body, at the plan's attitude; and
    ``sensed_with_body_at(offset_m, left_seat_m)``: the encoders with both hands on their
    holds (the left one seated ``left_seat_m`` from it) and the body ``offset_m`` away."""
    from execute.motion.estimator import BodyEstimate
    from execute.motion.layer import MotionLayer
    from execute.play.player import PlayerOptions, TrajectoryPlayer

    _path, traj, sc, ladder = reach
    seg = sc.segments[-1]
    assert {"left_hand", "right_hand", "left_foot"} <= set(seg.holds)
    layer = MotionLayer(TrajectoryPlayer(traj, PlayerOptions(rate_hz=int(sc.rate_hz))),
                        traj, sc, ladder, config=config)
    layer._line = line = seg.first_line - 1
    T_world_pelvis = np.eye(4)  # the body at the plan's attitude
    T_world_pelvis[:3, :3] = layer._planned_pelvis_rotation()
    layer.estimate = BodyEstimate(0.0, T_world_pelvis, T_world_pelvis[:3, :3],
                                  {"left": True, "right": True}, {}, {},
                                  {"left": 0.09, "right": 0.09})
    layer._body_on_ladder = True
    layer._held_rails = {side: (f"rail_{side}", np.asarray(seg.holds[f"{side}_hand"].position_m))
                         for side in ("left", "right")}
    for side in ("left", "right"):  # grasps made from the floor
        layer._seat_grasp(side, f"rail_{side}", on_floor=True)

    def sensed_with_body_at(offset_m, left_seat_m=(0.0, 0.0, 0.0)):
        q = traj[line].copy()
        for side, seat in (("left", np.asarray(left_seat_m)), ("right", np.zeros(3))):
            q += layer._limb_shift_dq(f"{side}_hand", line, seat - offset_m, np.eye(3))[0]
        return q

    return layer, seg, sensed_with_body_at


def test_on_the_ladder_the_body_is_trimmed_back_to_the_held_rails(reach):
    """Once the ladder alone carries the robot, the holding hands' encoders measure how
    far the body stands towards the ladder from the plan's posture relative to the rails
    (a creeping foot, arms pulling on their grips). Every holding limb, a stance foot
    with no correction of its own included, then moves the body back, horizontally,
    within the bound; an error the body has already taken out leaves the trim where it
    is. A grasp made on the ladder reads the error against the hands already holding."""
    from execute.motion.events import MotionEventKind
    from execute.motion.layer import BODY_TRIM_GAIN

    _path, traj, _sc, _ladder = reach
    layer, seg, sensed_with_body_at = _layer_on_the_held_rails(
        reach, MotionConfig(max_body_trim_m=0.03))
    layer._follow_holds(seg)  # the holds as they are taken: nothing to realise yet
    assert "left_foot" not in layer._offsets
    line = layer._line

    towards_ladder = layer.geometry.R_world_ladder[:, 0]  # horizontal
    layer._pos_rad = sensed_with_body_at(0.02 * towards_ladder)  # pulled 2 cm towards it
    layer._trim_body()
    assert layer._body_trim_m == pytest.approx(-0.02 * BODY_TRIM_GAIN, abs=1e-3)
    layer._trim_body()  # the body did not move: the trim integrates
    assert layer._body_trim_m == pytest.approx(-0.04 * BODY_TRIM_GAIN, abs=1e-3)
    assert layer.events[-1].kind is MotionEventKind.BODY_TRIM
    layer._follow_holds(seg)
    end = seg.last_line - 1
    frame = layer.model.chains["left_foot"].frame
    moved = (layer.model.frame_in_pelvis(traj[end] + layer._offsets["left_foot"].end, frame)
             - layer.model.frame_in_pelvis(traj[end], frame))[:3, 3]
    # the foot pushes it back (horizontally: the fixture's standing leg is near straight,
    # so the foot cannot also move down relative to the pelvis)
    assert np.allclose(moved, -layer._body_trim_m * towards_ladder, atol=1e-3)

    trim = layer._body_trim_m
    layer._pos_rad = traj[line].copy()  # the body back where the plan has it
    layer._trim_body()
    assert layer._body_trim_m == trim
    # the left hand grasps again on the ladder, seated 1.5 cm off its hold across the
    # rail, while the body stands 1 cm from the plan's posture: the body error stays 1 cm
    layer._pos_rad = sensed_with_body_at(0.01 * towards_ladder,
                                         0.015 * layer.geometry.rung_line_normal)
    layer._seat_grasp("left", "rail_left", on_floor=False)
    assert layer._body_error_m()[0] == pytest.approx(0.01, abs=1e-3)
    assert abs(layer._hand_readings_m({"left": "rail_left"})["left"][0] - 0.01) > 0.01
    layer._pos_rad = sensed_with_body_at(0.08 * towards_ladder)  # beyond the bound
    layer._trim_body()
    assert abs(layer._body_trim_m) == pytest.approx(layer.config.max_body_trim_m)


def test_on_the_ladder_a_foot_is_aimed_against_the_body_offset_the_hands_read(reach):
    """With the foot aim on and the ladder alone carrying the robot, a foot's reach is
    aimed against the body's offset from the plan's posture relative to the held rails,
    horizontally and within the bound; the body itself is not trimmed. Off by default,
    on the floor, or within the reading's deadband: no aim."""
    from execute.motion.layer import FOOT_AIM_DEADBAND_M

    layer, _seg, sensed_with_body_at = _layer_on_the_held_rails(
        reach, MotionConfig(max_foot_aim_m=0.03))
    towards_ladder = layer.geometry.R_world_ladder[:, 0]  # horizontal
    along_rungs = layer.geometry.R_world_ladder[:, 1]
    layer._pos_rad = sensed_with_body_at(0.02 * towards_ladder)  # 2 cm towards it
    assert np.allclose(layer._foot_aim_m(), -0.02 * towards_ladder, atol=1e-3)
    offset = 0.01 * towards_ladder - 0.015 * along_rungs  # and 1.5 cm to its right
    layer._pos_rad = sensed_with_body_at(offset)
    assert np.allclose(layer._foot_aim_m(), -offset, atol=1e-3)
    layer._trim_body()
    assert layer._body_trim_m == 0.0  # the body stays
    layer._pos_rad = sensed_with_body_at(-0.08 * towards_ladder)  # beyond the bound
    assert np.allclose(layer._foot_aim_m(), 0.03 * towards_ladder, atol=1e-6)
    layer._pos_rad = sensed_with_body_at(0.5 * FOOT_AIM_DEADBAND_M * towards_ladder)
    assert not layer._foot_aim_m().any()
    layer._pos_rad = sensed_with_body_at(0.02 * towards_ladder)
    layer._body_on_ladder = False  # a foot on the floor: the plan's posture over it
    assert not layer._foot_aim_m().any()
    off, _seg, sensed_off = _layer_on_the_held_rails(reach, MotionConfig())
    off._pos_rad = sensed_off(0.02 * towards_ladder)
    assert not off._foot_aim_m().any()


@pytest.mark.parametrize("field,value", [("max_reach_correction_m", 0.2),
                                         ("grasp_retries", -1),
                                         ("max_reach_correction_rad", 1.0),
                                         ("landing_reach_m", 0.10),
                                         ("landing_load_n", 0.0),
                                         ("strike_load_n", 5.0),
                                         ("strike_backoff_m", 0.08),
                                         ("max_body_trim_m", 0.08),
                                         ("max_foot_aim_m", 0.08),
                                         ("grip_bending_onset", 0.45)])
def test_unsafe_settings_are_refused(field, value):
    with pytest.raises(MotionConfigError) as exc:
        MotionConfig(**{field: value})
    assert exc.value.field == field and field in str(exc.value)


def test_cli_refuses_a_reach_bound_beyond_the_safe_range(reach, capsys):
    path = reach[0]
    assert validate_main([str(path), "--max-reach-correction", "0.5"]) == 2
    err = capsys.readouterr().err
    assert "max_reach_correction_m" in err and "[0, 0.1]" in err


def _arm_drift_rad(compensated: bool) -> float:
    """A PWM left arm, elbow bent forward (every joint's gravity torque within its PWM
    clamp), in mode COMPLIANT (reference on the encoders, the
    thesis's default gravity-compensation mode), with or without the model's gravity
    torques as feed-forward; how far it moves in 2 s [rad]."""
    board = BoardModel(dataclasses.replace(load_ladder("drc"), placement_x_m=3.0))
    q = np.zeros(NUM_JOINTS)
    arm = [JOINT_INDEX[n] for n in ARM_JOINTS["left"]]
    q[JOINT_INDEX["LSP"]], q[JOINT_INDEX["LSR"]], q[JOINT_INDEX["LEB"]] = -0.2, 0.3, -0.6
    board.reset(q)
    model = MotionRobotModel()
    ctl, gains = JointController(), default_drc_gains()
    comply = np.zeros(NUM_JOINTS, dtype=bool)
    comply[arm] = True
    mode = np.full(NUM_JOINTS, int(RefMode.FILTER), dtype=np.int8)
    mode[arm] = RefMode.COMPLIANT
    mode[JOINT_INDEX["LWR"]] = RefMode.FILTER  # the wrist roll cannot comply: held rigid
    start = board.joint_pos()[arm]
    for _ in range(400):
        pos = board.joint_pos()
        ff = None
        if compensated:
            torque = np.zeros(NUM_JOINTS)
            torque[arm] = model.gravity_torques(pos, np.eye(3))[arm]
            ff = feedforward_duty_pct(torque, board.config.battery_v, None, board.motors)
        board.apply(ctl.tick(q, mode, comply, pos, board.joint_vel(), gains, ff))
        board.step()
    return float(np.max(np.abs(board.joint_pos()[arm] - start)))


def test_gravity_compensation_holds_a_pwm_arm_still():
    held, sagged = _arm_drift_rad(True), _arm_drift_rad(False)
    assert held < 0.02
    assert sagged > 0.1


def test_a_misplaced_ladder_is_re_grasped_from_sensors(reach):
    """The ladder 4.5 cm further than planned: open loop the first grasp misses; closed
    loop the fingers read empty, the hand re-reaches and both hands hold."""
    _path, traj, sc, ladder = reach
    placement = PlacementError(0.045, 0.0, 0.0)
    opened = simulate(traj, sc, ladder, SimulationOptions(
        placement=placement, record_qpos=False, closed_loop=False))
    assert opened.verdict.failure.cause == "grasp_not_latched"
    closed = simulate(traj, sc, ladder, SimulationOptions(placement=placement,
                                                          record_qpos=False))
    assert closed.verdict.climbed, closed.verdict
    kinds = [e["kind"] for e in closed.motion["events"]]
    assert "grasp missed" in kinds and kinds.count("grasp verified") == 2
    assert "re-reach" in kinds or "reach correction" in kinds
    # the estimate found the ladder further away: across the rails, towards the ladder
    assert closed.motion["ladder_shift_m"][0] > 0.01
    # a hand that closed on nothing is in the air: its mixed arm re-reaches stiff, in
    # position mode from its first miss until its grasp is verified
    events = closed.motion["events"]
    missed = next(e for e in events if e["kind"] == "grasp missed")
    assert any(e["kind"] == "stiff reach" and e["limb"] == missed["limb"]
               and "closed on nothing" in e["cause"] for e in events)
    verified = next(e for e in events if e["kind"] == "grasp verified"
                    and e["limb"] == missed["limb"] and e["time_s"] > missed["time_s"])
    arm = [JOINT_INDEX[j] for j in ARM_JOINTS[missed["limb"].split("_")[0]]]
    log = closed.log
    re_reach = (log.time_s > missed["time_s"] + 0.01) & (log.time_s < verified["time_s"] - 0.01)
    assert re_reach.any() and not log.pwm[re_reach][:, arm].any()


def test_a_grasp_measures_its_rail_once_the_palm_stands_still_in_the_grip(reach):
    """The ladder 1.2 cm to the side of the plan's, within the grip's capture: the fingers
    stop on the rails before the grip has drawn the palms onto them. The grasps are
    verified once the palms stand still, and the ladder estimate then has the shift to
    within 3 mm (read when the fingers stopped, a palm was 5 mm further)."""
    _path, traj, sc, ladder = reach
    run = simulate(traj, sc, ladder, SimulationOptions(
        placement=PlacementError(0.0, 0.012, 0.0), record_qpos=False))
    assert run.verdict.climbed, run.verdict
    verified = [e for e in run.motion["events"] if e["kind"] == "grasp verified"]
    assert len(verified) == 2
    assert all("still in the grip" in e["cause"] for e in verified)
    shift_m = run.motion["ladder_shift_m"]
    assert abs(shift_m[1] - 0.012) < 0.003 and abs(shift_m[0]) < 0.003


def test_a_grasp_is_verified_once_its_palm_stands_still_and_measures_the_rail_there(reach):
    """Fingers on the rail while the grip still draws the palm: no grasp is verified
    while the palm moves faster than `SEATED_SPEED_M_S`; once it stands still the grasp is
    verified and its palm, there, measures the ladder. Fingers still moving when the seat
    times out are read afresh, as a grasp being verified."""
    from execute.motion.estimator import BodyEstimate
    from execute.motion.layer import SEAT_WINDOW_S, SEATED_SPEED_M_S, MotionLayer, _Regrasp
    from execute.play.player import PlayerOptions, TrajectoryPlayer
    from robot.kinematic_tree import finger_contact_curl_rad

    _path, traj, sc, ladder = reach
    grasp = next(k for k, seg in enumerate(sc.segments) if seg.phase == "grasp")
    layer = MotionLayer(TrajectoryPlayer(traj, PlayerOptions(rate_hz=int(sc.rate_hz))),
                        traj, sc, ladder)
    planned = {side: np.asarray(sc.segments[grasp + 1].holds[f"{side}_hand"].position_m)
               for side in ("left", "right")}
    on_rail = np.zeros(NUM_JOINTS)
    for side in ("left", "right"):
        on_rail[[JOINT_INDEX[j] for j in FINGER_JOINTS[side]]] = \
            finger_contact_curl_rad(ladder.rail_radius_m)

    def tick(t_s, palm_m, finger_speed_rad_s=0.0):
        layer._now = t_s
        layer.estimate = BodyEstimate(t_s, np.eye(4), np.eye(3), {"left": True, "right": True},
                                      palm_m, {}, {"left": 0.09, "right": 0.09})
        vel = np.zeros(NUM_JOINTS)
        vel[[JOINT_INDEX[j] for j in FINGER_JOINTS["right"]]] = finger_speed_rad_s
        layer._update_regrasp(SensedState(
            t_s, on_rail, vel, np.zeros((4, 3)), np.zeros((3, 6)), on_rail,
            np.zeros(NUM_JOINTS), np.ones(NUM_JOINTS, bool), np.zeros(NUM_JOINTS, bool)))

    layer.player.step(0.0, traj[0])
    layer.player.pause(0.0)
    left = planned["left"] + [0.0, 0.010, 0.0]  # the fingers stopped 1 cm off the rail
    layer._regrasp = _Regrasp("left", grasp, "rail_left", planned["left"], "seat", 0.0,
                              seat_time_s=0.0, seat_palm_m=left)
    drawn = left + [0.0, 0.004, 0.0]  # drawn 4 mm further on over a window
    tick(SEAT_WINDOW_S, {"left": drawn, "right": planned["right"]})
    assert layer._regrasp is not None and layer._regrasp.phase == "seat"
    assert not any(e.kind.value == "grasp verified" for e in layer.events)
    still = drawn + [0.0, 0.5 * SEATED_SPEED_M_S * SEAT_WINDOW_S, 0.0]
    tick(2 * SEAT_WINDOW_S, {"left": still, "right": planned["right"]})
    assert layer._regrasp is None
    verified = [e for e in layer.events if e.kind.value == "grasp verified"]
    assert len(verified) == 1 and "still in the grip" in verified[0].cause
    assert layer.ladder.shift_m[1] == pytest.approx(still[1] - planned["left"][1], abs=1e-3)

    layer.player.pause(1.0)
    layer._regrasp = _Regrasp("right", grasp, "rail_right", planned["right"], "seat", 1.0,
                              seat_time_s=1.0, seat_palm_m=planned["right"])
    timeout_s = layer.config.seat_timeout_s
    tick(1.0 + timeout_s, {"left": still, "right": planned["right"]}, finger_speed_rad_s=1.0)
    assert layer._regrasp.phase == "verify"  # read afresh: the fingers still move
    assert len([e for e in layer.events if e.kind.value == "grasp verified"]) == 1


def test_a_compliant_arm_short_of_its_hold_finishes_the_reach_stiff(reach):
    """Mixed arms: a PWM arm that cannot carry its palm to within the arrival tolerance
    finishes the reach in position mode, as it moved in the air, and complies again once
    its grasp is verified. PWM-only arms never leave PWM."""
    _path, traj, sc, ladder = reach
    strict = MotionConfig(arrival_tolerance_m=0.004, arrival_timeout_s=1.0)
    mixed = simulate(traj, sc, ladder, SimulationOptions(record_qpos=False, motion=strict))
    assert mixed.verdict.climbed, mixed.verdict
    events = mixed.motion["events"]
    stiff = [e for e in events if e["kind"] == "stiff reach"]
    assert stiff and stiff[0]["size_m"] > strict.arrival_tolerance_m
    wait = next(e for e in events if e["kind"] == "arrival wait" and e["limb"] == stiff[0]["limb"])
    assert wait["size_m"] < stiff[0]["size_m"]  # position mode brought the palm closer
    pwm_only = simulate(traj, sc, ladder, SimulationOptions(strategy="pwm", record_qpos=False,
                                                             motion=strict))
    assert not any(e["kind"] == "stiff reach" for e in pwm_only.motion["events"])
    left = [JOINT_INDEX[j] for j in ARM_JOINTS["left"]]
    compliant = pwm_only.log.pwm[-1, left]  # the joints a gripping arm complies with
    assert compliant.sum() >= 5 and (pwm_only.log.pwm[:, left] == compliant).all()
    # on the rail (the plan's last lines), the mixed arm complies again
    assert (mixed.log.pwm[-1, left] == compliant).all()


def test_an_arm_that_leaves_its_rail_compliant_still_counts_as_stiff_in_the_air(reach):
    """A mixed arm complies as it lets go of its rail and again on the last lines before
    it closes; in between it moves in position mode. Such a reach may finish stiff (on
    `ship` the right arm waited 4 s 1.7 cm short of its hold and closed on nothing)."""
    from execute.motion.layer import MotionLayer, _Regrasp
    from execute.play.player import PlayerOptions, TrajectoryPlayer

    _path, traj, sc, ladder = reach
    grasp = next(k for k, seg in enumerate(sc.segments) if seg.phase == "grasp")
    reach_seg = sc.segments[grasp - 1]
    n = len(traj)

    def stiff_in_air(runs):
        player = TrajectoryPlayer(traj, PlayerOptions(rate_hz=int(sc.rate_hz)),
                                  {"left": runs, "right": runs})
        layer = MotionLayer(player, traj, sc, ladder)
        return layer._stiff_in_air(_Regrasp("left", grasp, "rail_left", np.zeros(3), "arrive", 0.0))

    a, b = reach_seg.first_line, reach_seg.last_line
    leaves_compliant = [(1, a + 4, "pwm"), (a + 5, b - 5, "position"), (b - 4, n, "pwm")]
    assert stiff_in_air(leaves_compliant)
    assert not stiff_in_air([(1, n, "pwm")])


def test_an_unrecoverable_miss_holds_with_no_weight_shift(reach, tmp_path):
    """Rails 11.5 cm beyond the closing palms, out of the search's reach: the layer stops
    at the grasp, the player never moves on to the lines that load the hands, and the
    feet still carry the robot."""
    path, traj, sc, ladder = reach
    run = simulate(traj, sc, ladder, SimulationOptions(
        placement=PlacementError(0.115, 0.0, 0.0), record_qpos=False))
    f = run.verdict.failure
    assert f.cause == "grasp_unverified" and f.details["tries"] >= 1
    grasp = next(s for s in sc.segments if s.phase == "grasp")
    assert run.log.line_index.max() <= grasp.last_line - 1
    assert not run.log.latched.any()
    stop = run.motion["stop"]
    assert stop is not None and "not moved onto it" in stop["reason"]
    # held still after stopping: the pelvis did not move in the last second
    com = run.log.com_m
    last = run.log.time_s > run.log.time_s[-1] - 1.0
    assert np.ptp(com[last], axis=0).max() < 0.005
    code = validate_main([str(path), "--placement-error", "0.115,0,0",
                          "--json", str(tmp_path / "r.json")])
    assert code == 1


def test_validate_plan_reports_the_loop_and_what_the_layer_did(reach, tmp_path, capsys):
    path = reach[0]
    closed, opened = tmp_path / "closed.json", tmp_path / "open.json"
    assert validate_main([str(path), "--json", str(closed)]) == 0
    out = capsys.readouterr().out
    assert "motion layer: " in out and "2 grasp verified" in out
    assert validate_main([str(path), "--open-loop", "--json", str(opened)]) == 0
    c, o = json.loads(closed.read_text()), json.loads(opened.read_text())
    assert (c["loop"], o["loop"]) == ("closed", "open")
    assert o["motion"] is None
    assert c["motion"]["counts"]["grasp verified"] == 2
    assert {e["kind"] for e in c["motion"]["events"]} >= {"grasp verified"}


def test_the_layers_arm_gains_are_inside_the_safety_limits():
    """The compliant arms' clamps go to the safety ceiling (< 8 %), nothing else moves."""
    from daemon.pwm import default_drc_gains
    from execute.motion.gains import motion_pwm_gains
    from robot.pwm_gains import MAX_PWM_LIMIT_PCT

    base, gains = default_drc_gains(), motion_pwm_gains()
    arm = [JOINT_INDEX[n] for side in ARM_JOINTS.values() for n in side]
    clamped = [j for j in arm if base.max_pwm_pct[j] > 0]
    assert np.all(gains.max_pwm_pct < MAX_PWM_LIMIT_PCT)
    assert np.all(gains.max_pwm_pct[clamped] >= base.max_pwm_pct[clamped])
    assert gains.max_pwm_pct[JOINT_INDEX["LWP"]] > 1.9 * base.max_pwm_pct[JOINT_INDEX["LWP"]]
    others = np.setdiff1d(np.arange(NUM_JOINTS), clamped)
    assert np.array_equal(gains.max_pwm_pct[others], base.max_pwm_pct[others])
    assert np.array_equal(gains.kp, base.kp) and np.array_equal(gains.kd, base.kd)
    from daemon.pwm import PwmGainError

    with pytest.raises(PwmGainError):
        motion_pwm_gains(8.5)


def test_a_stiff_arm_that_pushes_on_something_complies_again(reach):
    """A stiff arm whose shoulder current says it pushes at 90 % of its limit complies
    again after 0.2 s; a shorter push (the stiff reach's own start) leaves it stiff."""
    from execute.motion.layer import STIFF_ARM_YIELD_S, MotionLayer
    from execute.play.player import PlayerOptions, TrajectoryPlayer
    from robot.limits import joint_limits
    from robot.motors import motor_table

    _path, traj, sc, ladder = reach
    layer = MotionLayer(TrajectoryPlayer(traj, PlayerOptions(rate_hz=int(sc.rate_hz))),
                        traj, sc, ladder)
    lsp = JOINT_INDEX["LSP"]
    pushing = np.zeros(NUM_JOINTS)
    pushing[lsp] = motor_table().current_a(0.9 * joint_limits().torque_max_nm)[lsp]

    def sensed(cur_a):  # the joint torques the layer reads from the currents each tick
        return layer.motors.torque_nm(cur_a)

    layer._stiff_arms.add("left")
    for _ in range(int(0.1 / 0.005)):
        layer._guard_stiff_arms(sensed(pushing), 0.005)
    layer._guard_stiff_arms(sensed(np.zeros(NUM_JOINTS)), 0.005)
    assert "left" in layer._stiff_arms  # a short push: still stiff
    for _ in range(int(STIFF_ARM_YIELD_S / 0.005) + 1):
        layer._guard_stiff_arms(sensed(pushing), 0.005)
    assert "left" not in layer._stiff_arms
    event = layer.events[-1]
    assert event.kind.value == "stiff reach" and "LSP" in event.cause



def _layer_with_a_compliant_approach(reach):
    """A layer on the reach fixture whose arms comply from 20 lines before their grasp
    (as mixed arms do on a plan's last lines of a reach), its player started and paused;
    and that first compliant line (0-based)."""
    from execute.motion.layer import MotionLayer
    from execute.play.player import PlayerOptions, TrajectoryPlayer

    _path, traj, sc, ladder = reach
    grasp = next(seg for seg in sc.segments if seg.phase == "grasp")
    switch = grasp.first_line - 21
    schedule = {arm: [(1, switch, "position"), (switch + 1, len(traj), "pwm")]
                for arm in ("left", "right")}
    player = TrajectoryPlayer(traj, PlayerOptions(rate_hz=int(sc.rate_hz)), schedule,
                              sc.arm_feedforward)
    layer = MotionLayer(player, traj, sc, ladder)
    player.step(0.0, traj[0])
    player.pause(0.0)  # as `MotionLayer.step` does when a wait is due
    return layer, switch


def _sensed(q_rad, right_wrist_fz_n=0.0):
    sample = new_sample(STATE_DTYPE)
    sample["pos"] = q_rad
    sample["ft"]["fz"][2] = right_wrist_fz_n  # RHFT
    return SensedState.from_sample(sample)


def test_a_stiff_arm_that_lags_waits_in_position_mode_before_it_complies(reach):
    """Mixed arms comply on the last lines of a reach. An arm still behind its reference
    there is held in position mode, the player waiting, until it catches up; one that
    does not within the arrival timeout finishes the reach stiff."""
    _path, traj, _sc, _ladder = reach

    def layer_at_the_switch():
        layer, switch = _layer_with_a_compliant_approach(reach)
        line = switch - 1  # the last stiff line
        assert set(layer._catch_up_at) == {line}
        (side, _k), *_ = layer._catch_up_at[line]
        layer._last_ref = traj[line].copy()
        return layer, line, side

    layer, line, side = layer_at_the_switch()
    shoulder = JOINT_INDEX[f"{side[0].upper()}SP"]
    behind = traj[line].copy()
    behind[shoulder] -= 0.2
    assert layer._catch_up_due(line, _sensed(traj[line])) is None  # on its reference
    layer, line, side = layer_at_the_switch()
    wait = layer._catch_up_due(line, _sensed(behind))
    assert wait is not None and wait.phase == "catch_up"
    layer._regrasp, layer._now = wait, 1.0
    layer._update_regrasp(_sensed(behind))
    assert layer._regrasp is wait  # still waiting
    layer._now = 1.5
    layer._update_regrasp(_sensed(traj[line]))
    assert layer._regrasp is None and side not in layer._stiff_arms
    assert layer.events[-1].kind.value == "arrival wait"
    assert layer._catch_up_due(line, _sensed(behind)) is None  # once per reach
    layer, line, side = layer_at_the_switch()
    layer._regrasp = layer._catch_up_due(line, _sensed(behind))
    layer._now = layer._regrasp.since_s + layer.config.arrival_timeout_s
    layer._update_regrasp(_sensed(behind))
    assert layer._regrasp is None and side in layer._stiff_arms
    assert layer.events[-1].kind.value == "stiff reach"


def test_a_hand_pushed_on_its_compliant_last_stretch_does_not_back_off(reach):
    """A push along the forearm is a strike while the arm moves stiff through the air;
    on the compliant last stretch of the reach it is the hand meeting its rail."""
    from execute.motion.estimator import BodyEstimate

    _path, traj, _sc, _ladder = reach
    layer, switch = _layer_with_a_compliant_approach(reach)
    layer.estimate = BodyEstimate(0.0, np.eye(4), np.eye(3), {"left": True, "right": True},
                                  {}, {}, {"left": 0.0, "right": 0.0})
    push = layer.config.hand_strike_load_n + 5.0
    assert layer._strike_due(switch + 5, _sensed(traj[switch + 5], push)) is None
    strike = layer._strike_due(switch - 20, _sensed(traj[switch - 20], push))
    assert strike is not None and strike.limb == "right_hand"
    assert layer.events[-1].kind.value == "hand strike"


def test_a_missed_first_grasp_searches_every_direction_across_the_rail(reach):
    """With nothing known of the ladder, the re-reaches of a first grasp that closed on
    nothing where it was sent cover, within the latch's reach of the rail axis, every
    offset up to a search step towards or away from the ladder and sideways, diagonals
    included."""
    from daemon.sim.grasp_latch import GripConfig
    from execute.motion.estimator import BodyEstimate
    from execute.motion.layer import MotionLayer, _Regrasp
    from execute.play.player import PlayerOptions, TrajectoryPlayer

    _path, traj, sc, ladder = reach
    layer = MotionLayer(TrajectoryPlayer(traj, PlayerOptions(rate_hz=int(sc.rate_hz))),
                        traj, sc, ladder)
    k = next(k for k, seg in enumerate(sc.segments) if seg.phase == "grasp")
    planned = np.asarray(sc.segments[k + 1].holds["left_hand"].position_m)
    layer.estimate = BodyEstimate(0.0, np.eye(4), np.eye(3), {"left": True, "right": True},
                                  {"left": planned, "right": planned}, {},
                                  {"left": 1.57, "right": 1.57})
    g = _Regrasp("left", k, "rail_left", planned, "verify", 0.0)
    tries = layer._candidates(g)[:layer.config.grasp_retries]
    reached = [np.zeros(3)] + tries  # where it closed first, then each re-reach
    step = layer.config.search_step_m
    towards, lateral = -layer.geometry.rung_line_normal, layer.geometry.lateral_direction
    for a in np.linspace(-step, step, 9):
        for b in np.linspace(-step, step, 9):
            rail = layer._across_rail(g, a * towards + b * lateral)
            nearest = min(np.linalg.norm(layer._across_rail(g, t - rail)) for t in reached)
            assert nearest <= GripConfig().position_tolerance_m, (a, b, nearest)


def test_the_new_plan_after_a_misplaced_ladder_is_the_first_plans_settings():
    """`ReplanSettings.command` is a plan-ladder command line that plan-ladder's own
    parser reads back to the first plan's seed, top rung, rate and planner settings."""
    import shlex

    from execute.motion.replan import ReplanSettings
    from planner.cli import _parser as plan_ladder_parser

    settings = ReplanSettings(seed=4, top_rung=8, rate_hz=200.0,
                              planner={"arm_strategy": "mixed", "position_torque_share": 0.9,
                                       "foot_cop_margin_m": 0.02, "foot_friction_share": 0.7,
                                       "held_wrist_margin_rad": 0.15})
    words = shlex.split(settings.command("measured ladder.yaml", "new.traj"))
    assert words[0] == "plan-ladder"
    args = plan_ladder_parser().parse_args(words[1:])
    assert (args.ladder, args.seed, args.top_rung, args.rate, args.out) == (
        "measured ladder.yaml", 4, 8, 200.0, "new.traj")
    assert (args.arm_strategy, args.position_torque_share, args.foot_cop_margin,
            args.foot_friction_share, args.held_wrist_margin) == ("mixed", 0.9, 0.02, 0.7, 0.15)
    floor = ReplanSettings(seed=1, top_rung=None, rate_hz=25.0)
    assert "--top-rung" not in floor.command("l.yaml", "n.traj")
