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

import numpy as np
import pytest

from execute.motion.retract import RETRACT_OPEN_S
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


#: limb → its F/T sensor's slot in the state sample (``daemon.structs.FT_NAMES``)
_FT_SLOT = {"right_foot": 0, "left_foot": 1, "right_hand": 2, "left_hand": 3}


class _KinematicRobot:
    """The mount's motion layer on a robot that is only encoders and sensors: the joints
    are where the layer sent them, fingers stop on the rail, the body IMU reads gravity, a
    held foot carries 300 N and a foot in the air reads its own weight. `sample` makes
    the tick's state, which a test may change before `step` plays it."""

    def __init__(self, mount):
        from execute.motion.layer import MotionLayer
        from execute.play.player import PlayerOptions, TrajectoryPlayer
        from robot.joints import FINGER_JOINTS, JOINT_INDEX
        from robot.kinematic_tree import finger_contact_curl_rad

        self.sc = read_sidecar(sidecar_path(mount))
        self.traj = read_trajectory(mount, self.sc.rate_hz)
        ladder = load_ladder("drc")
        self.layer = MotionLayer(TrajectoryPlayer(self.traj,
                                                  PlayerOptions(rate_hz=int(self.sc.rate_hz))),
                                 self.traj, self.sc, ladder)
        self._fingers = [JOINT_INDEX[f] for side in FINGER_JOINTS for f in FINGER_JOINTS[side]]
        self._curl = finger_contact_curl_rad(ladder.rail_radius_m)
        self.ref, self.t = self.traj[0].copy(), 0.0

    def sample(self):
        from daemon.structs import STATE_DTYPE, new_sample

        seg = self.sc.segments[int(self.layer._segment_of_line[self.layer._line])]
        sample = new_sample(STATE_DTYPE)
        sample["time_s"] = self.t
        sample["pos"][:] = self.ref
        sample["pos"][self._fingers] = np.minimum(self.ref[self._fingers], self._curl)
        sample["imu"][0]["az"] = 9.81
        for k, side in ((0, "right"), (1, "left")):
            sample["ft"][k]["fz"] = 300.0 if f"{side}_foot" in seg.holds else -12.0
        return sample

    def step(self, sample) -> None:
        self.ref = self.layer.step(self.t, sample).ref_rad
        self.t += 0.005


def _play_on_kinematic_robot(mount, press_n, press_from, press_ticks, limb="left_foot"):
    """The mount on `_KinematicRobot`, whose ``limb`` F/T reads ``press_n`` for
    ``press_ticks`` ticks once its first move (the left foot's step onto rung 0; the hands'
    reach to the rails) is ``press_from`` of the way through. Returns (layer, per-tick
    (line, the limb's reference frame relative to the plan's, in the pelvis frame [m])),
    up to the end of that move."""
    robot = _KinematicRobot(mount)
    layer, traj = robot.layer, robot.traj
    step = next(seg for seg in robot.sc.segments if seg.phase == "limb"
                and limb in seg.moving_limbs)
    press_line = step.first_line - 1 + round(press_from * (step.last_line - step.first_line))
    frame = layer.model.chains[limb].frame
    pressed, trace = 0, []
    while layer._line < step.last_line - 1 and layer.stop is None and robot.t < 400.0:
        sample = robot.sample()
        if layer._line >= press_line and pressed < press_ticks:
            sample["ft"][_FT_SLOT[limb]]["fz"] = press_n
            pressed += 1
        robot.step(sample)
        line = layer._line
        off = (layer.model.frame_in_pelvis(robot.ref, frame)[:3, 3]
               - layer.model.frame_in_pelvis(traj[line], frame)[:3, 3])
        trace.append((line, off))
    return layer, trace


def _backed_off_once(layer, trace, kind: str, limb: str):
    """Check that ``limb`` backed off once (event ``kind``) while the plan waited, and
    return (line, the limb's offset from the plan) once it has."""
    strikes = [e for e in layer.events if e.kind.value == kind]
    assert len(strikes) == 1 and strikes[0].limb == limb, layer.events
    assert layer.stop is None
    k = next(i for i, (line, _off) in enumerate(trace) if line + 1 >= strikes[0].line)
    backoff_ticks = round(layer.config.strike_backoff_s / 0.005)
    lines = [line for line, _off in trace[k: k + backoff_ticks]]
    assert max(lines) - min(lines) <= 1  # the move waited while the limb backed off
    return trace[k + backoff_ticks]


def test_a_foot_pressed_from_above_on_its_way_backs_off_and_steps_on(mount):
    """A swinging foot whose F/T reads a push from above (its toe rising under a rung)
    stops, backs away from the ladder, rises from there and still lands on its hold."""
    layer, trace = _play_on_kinematic_robot(mount, -80.0, 0.4, 10)
    _line, away = _backed_off_once(layer, trace, "foot strike", "left_foot")
    # pelvis frame: x towards the ladder, z up
    assert away[0] == pytest.approx(-layer.config.strike_backoff_m, abs=0.01)
    assert away[2] < -0.005
    assert np.linalg.norm(trace[-1][1]) < 0.005  # the step still ends on its hold


def test_a_hand_the_ladder_pushes_on_its_way_backs_off_and_reaches_its_hold(mount):
    """A reaching hand whose wrist F/T reads a push along the forearm (its palm plate on
    the rail) stops, gives way along the push, and still reaches its hold."""
    layer, trace = _play_on_kinematic_robot(mount, 40.0, 0.4, 10, limb="right_hand")
    line, moved = _backed_off_once(layer, trace, "hand strike", "right_hand")
    assert np.linalg.norm(moved) == pytest.approx(layer.config.strike_backoff_m, abs=0.01)
    # along the push: the forearm's axis, from the palm towards the wrist
    along = layer.model.frame_in_pelvis(layer.trajectory_rad[line],
                                        layer.model.chains["right_hand"].frame)[:3, 2]
    assert moved @ along > 0.8 * np.linalg.norm(moved)
    assert np.linalg.norm(trace[-1][1]) < 0.005  # the reach still ends on its hold


def test_a_foot_still_pressed_after_its_back_offs_stops_the_climb(mount):
    layer, trace = _play_on_kinematic_robot(mount, -80.0, 0.4, 100_000)
    strikes = [e for e in layer.events if e.kind.value == "foot strike"]
    assert len(strikes) == layer.config.strike_tries
    assert strikes[1].size_m == pytest.approx(2 * layer.config.strike_backoff_m)
    assert layer.stop is not None and layer.stop.cause.value == "foothold_unverified"
    assert "pressed from above" in layer.stop.reason


def test_a_stance_that_turns_while_the_hands_reach_is_seen_and_the_hands_aimed(mount):
    """The kinematic robot's stance turns 3° about the vertical while its hands reach for
    the rails (its gyro reads the turn; no encoder moves): the estimate sees it from the
    gyro, and each hand is aimed at its hold before it closes, by about the turn's
    displacement of the palm."""
    robot = _KinematicRobot(mount)
    sc, layer = robot.sc, robot.layer
    reach = sc.segments[0]
    assert reach.phase == "limb" and set(reach.moving_limbs) == {"left_hand", "right_hand"}
    assert all({"left_foot", "right_foot"} <= set(seg.holds) for seg in sc.segments[:3])
    turn_rad, turn_s = np.radians(3.0), 3.0
    turned = 0.0
    grasps = [seg.last_line for seg in sc.segments[1:3]]
    while layer._line < grasps[-1] - 1 and layer.stop is None and robot.t < 200.0:
        sample = robot.sample()
        if layer._line >= reach.first_line + (reach.last_line - reach.first_line) // 2 \
                and turned < turn_rad:
            sample["imu"][0]["wz"] = turn_rad / turn_s
            turned += turn_rad / turn_s * 0.005
        robot.step(sample)
    heading = np.arctan2(layer.estimate.T_world_pelvis[1, 0], layer.estimate.T_world_pelvis[0, 0])
    assert heading == pytest.approx(turn_rad, abs=np.radians(0.3))
    aims = {e.limb: e for e in layer.events if e.kind.value == "aim"}
    assert set(aims) == {"left_hand", "right_hand"}, layer.events
    both = sc.segments[3].holds  # the dwell after the grasps: both hands on their rails
    for side in ("left", "right"):
        # the turn carried the planned palm round the soles' midpoint by the turn's angle
        palm = np.asarray(both[f"{side}_hand"].position_m)
        lever = np.linalg.norm(palm[:2])
        assert aims[f"{side}_hand"].size_m == pytest.approx(lever * turn_rad, rel=0.35)
    assert layer.stop is None


def test_a_misplaced_ladder_is_measured_by_the_first_grasps_and_planned_for_again(
        mount, monkeypatch):
    """The ladder stands 3 cm further, 2 cm to the left and turned 2.3° from the
    plan's. With ``replan_beyond_m``, the layer stops after the two first grasps, before
    any weight moves onto the ladder, with the ladder's placement as the hands measured
    it; the hands open and retrace the plan to its start; the run goes on with the plan
    for the ladder as measured. The planner's search (minutes on this machine) is
    replaced here by the same lines played against the measured ladder: what is pinned is
    the measurement, the retreat and the hand-over, not a new plan's climb (measured by
    `batch-eval`, docs/results.md)."""
    import execute.validate.simulate as sim
    from daemon.sim.board_model import PlacementError
    from execute.motion.config import MotionConfig

    sc = read_sidecar(sidecar_path(mount))
    traj = read_trajectory(mount, sc.rate_hz)
    drc = load_ladder("drc")
    error = PlacementError(0.03, 0.02, 0.04)
    measured = {}

    def same_lines_for_the_measured_ladder(robot, sidecar, ladder, motion):
        measured["stop"] = motion.stop
        measured["events"] = motion.report()["events"]
        placed = motion.measured_ladder
        return (traj, sidecar, placed), {"shift_m": motion.stop.details["shift_m"],
                                         "yaw_rad": motion.stop.details["yaw_rad"],
                                         "worst_hold_m": motion.stop.details["worst_hold_m"],
                                         "planning_s": 0.0, "no_plan": None}

    monkeypatch.setattr(sim, "_replan_after_touch", same_lines_for_the_measured_ladder)
    run = simulate(traj, sc, drc, SimulationOptions(
        record_qpos=False, placement=error, motion=MotionConfig(replan_beyond_m=0.02)))
    stop = measured["stop"]
    assert stop.cause.value == "ladder_misplaced" and stop.details["worst_hold_m"] > 0.02
    verified = [e for e in measured["events"] if e["kind"] == "grasp verified"]
    assert len(verified) == 2 and stop.time_s >= verified[-1]["time_s"]
    # no foot had left the floor: the stop came in the first step, placeHands
    assert sc.segment_at(stop.line).primitive == "placeHands"
    # the new run's misplacement is what the hands could not see: a few millimetres
    residual = run.options.placement
    assert np.hypot(residual.dx_m, residual.dy_m) < 0.008
    assert abs(residual.dyaw_rad) < np.radians(0.5)
    assert run.ladder.placement_yaw_rad == pytest.approx(0.04, abs=np.radians(0.5))
    # the stop tells an operator the placement to plan for: the one planned for here
    assert stop.details["placement"]["yaw_rad"] == pytest.approx(run.ladder.placement_yaw_rad,
                                                                abs=1e-4)
    # the second run starts after the retreat, both hands open, and grasps again
    assert run.log.time_s[0] > stop.time_s + RETRACT_OPEN_S
    assert not run.log.latched[0].any()
    assert run.motion["counts"].get("grasp verified", 0) >= 2
    assert run.replan is not None and run.replan["placement_error_before"]["dx_m"] == 0.03


def test_a_misplaced_ladder_with_no_new_plan_ends_on_the_stop_with_the_weight_on_the_floor(
        mount, monkeypatch):
    """When the planner finds no plan for the ladder as the hands measured it, the run
    ends on the layer's stop (``ladder_misplaced``, the planner's reason in the record),
    the robot back at its start with open hands: nothing was loaded onto the ladder."""
    import planner.search as search
    from daemon.sim.board_model import PlacementError
    from execute.motion.config import MotionConfig
    from primitives.library import climb_sequence

    def no_plan(self, top_rung=None, **_kwargs):
        raise search.PlanningFailed(climb_sequence(0)[0], "no hold within reach (test)")

    monkeypatch.setattr(search.ClimbPlanner, "plan", no_plan)
    sc = read_sidecar(sidecar_path(mount))
    traj = read_trajectory(mount, sc.rate_hz)
    run = simulate(traj, sc, load_ladder("drc"), SimulationOptions(
        record_qpos=False, placement=PlacementError(0.03, 0.02, 0.04),
        motion=MotionConfig(replan_beyond_m=0.02)))
    failure = run.verdict.failure
    assert failure is not None and failure.cause.value == "ladder_misplaced"
    assert "no hold within reach (test)" in run.replan["no_plan"]
    assert not run.board.latches["left"].latched and not run.board.latches["right"].latched
    soles_z = [run.board.data.site(f"{s}_sole").xpos[2] for s in "LR"]
    assert max(soles_z) < 0.01  # both feet still on the floor
