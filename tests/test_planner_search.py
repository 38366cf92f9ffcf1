"""The planner's search: IK projection, contact-space interpolation, determinism, failures."""

from dataclasses import replace

import numpy as np
import pytest

from ladders.loader import load_ladder
from planner.configuration.ik import IKConfig, solve_ik
from planner.contacts import Hold, Stance
from planner.holds import HELD_WRIST_MARGIN_RAD, WRIST_PITCH_JOINT
from planner.paths.interpolation import InterpolationError, contact_space_interpolate
from planner.search import ClimbPlanner, PlannerConfig, PlanningFailed, StepStats
from primitives.library import climb_sequence
from robot.vocabulary import RejectCause


@pytest.fixture(scope="module")
def planner():
    return ClimbPlanner(load_ladder("drc"), seed=1)


@pytest.fixture(scope="module")
def standing(planner):
    return planner.start_configuration()


def _crouch(planner, q, stance, depth_m):
    """A configuration with the pelvis lowered by ``depth_m``, feet kept on the floor."""
    target = q[:3] - [0.0, 0.0, depth_m]
    r = solve_ik(planner.kin, q, stance.holds, torso_R=planner.torso_R, pelvis_target_m=target,
                 pelvis_weight=1.0)
    assert r.converged
    return r.q


def test_start_configuration_stands_on_the_floor(planner, standing):
    q, stance = standing
    for hold in stance.holds:
        T = planner.kin.frame_pose(q, hold.frame)
        np.testing.assert_allclose(T, hold.T_world_frame, atol=1e-4)
    verdict = planner.checker.check(q, stance, {h.limb: h.target for h in stance.holds})
    assert verdict.ok and verdict.com_margin_m > 0.02


def test_projection_keeps_contact_frames_on_their_holds(planner, standing):
    q, stance = standing
    qb = _crouch(planner, q, stance, 0.12)
    path = contact_space_interpolate(planner.kin, planner.checker, q, qb, stance.holds, stance,
                                     {h.limb: h.target for h in stance.holds})
    assert len(path) > 5
    for qi in path:
        for hold in stance.holds:
            p = planner.kin.frame_pose(qi, hold.frame)[:3, 3]
            assert np.linalg.norm(p - hold.T_world_frame[:3, 3]) < 2e-4
    # The plain joint-space midpoint would not keep them: the projection is doing work.
    mid = planner.kin.interpolate(q, qb, 0.5)
    drift = max(np.linalg.norm(planner.kin.frame_pose(mid, h.frame)[:3, 3]
                               - h.T_world_frame[:3, 3]) for h in stance.holds)
    assert drift > 1e-3


def test_a_hand_target_at_the_hand_s_own_pose_is_solved(planner, standing):
    """placo's axis-align task is singular at exactly zero error (NaN in the QP): a hand
    way-point taken from the hand's current pose, as when it backs off its rail, must
    still solve. On the ship ladder it failed every sample of a step (seeds 12 and 13)."""
    q, stance = standing
    hand = Hold("left_hand", "rail_left", np.eye(4), np.zeros((2, 3)), np.zeros((2, 3)), 0.4)
    here = replace(hand, T_world_frame=planner.kin.frame_pose(q, hand.frame))
    r = solve_ik(planner.kin, q, stance.holds, (here,), torso_R=planner.torso_R)
    assert r.converged and r.position_error_m < 1e-4



def test_ik_hold_errors_are_the_distance_and_the_turn_from_the_hold(planner, standing):
    """The IK's per-iteration hold check (scalar arithmetic) against its definition: the
    frame's distance from the target, and its turn from it: a hand's grip axis only, a
    foot's whole orientation (the angle of R_frameᵀ R_target)."""
    from scipy.spatial.transform import Rotation

    from planner.configuration.ik import _hold_checks, _hold_error

    q, stance = standing
    kin = planner.kin
    kin.set_q(q)
    rng = np.random.default_rng(7)
    for limb in ("left_hand", "right_foot"):
        T_now = kin.frame_pose(q, Hold(limb, "x", np.eye(4), np.zeros((1, 3)),
                                       np.zeros((1, 3))).frame)
        for _ in range(5):
            T = np.eye(4)
            T[:3, :3] = Rotation.from_rotvec(rng.normal(0, 0.3, 3)).as_matrix() @ T_now[:3, :3]
            T[:3, 3] = T_now[:3, 3] + rng.normal(0, 0.05, 3)
            hold = Hold(limb, "x", T, np.zeros((1, 3)), np.zeros((1, 3)))
            (check,) = _hold_checks((hold,), (), IKConfig())
            dp, da = _hold_error(kin, check)
            assert dp == pytest.approx(np.linalg.norm(T_now[:3, 3] - T[:3, 3]), abs=1e-12)
            if hold.is_hand:
                turn = np.arccos(np.clip(T_now[:3, 0] @ T[:3, 0], -1, 1))
            else:
                turn = Rotation.from_matrix(T_now[:3, :3].T @ T[:3, :3]).magnitude()
            assert da == pytest.approx(turn, abs=1e-7)
    with pytest.raises(ValueError):
        Hold("left_elbow", "x", np.eye(4), np.zeros((1, 3)), np.zeros((1, 3)))


def test_a_hard_hold_beyond_one_bounded_step_widens_the_step(planner, standing):
    """The midpoint of a long move (a lift-off far from the stance it leaves) can be
    centimetres off its holds; one speed-bounded step cannot meet a hard hold that far
    off, and the QP was infeasible: every compliant-arm mount sample of a random 60°
    ladder failed so. The step bound now widens for that step."""
    q, stance = standing
    off = q.copy()
    off[planner.kin.q_index["LKN"]] += 0.8  # the left foot far off its hold
    base = IKConfig()
    fixed = solve_ik(planner.kin, off, stance.holds,
                     config=replace(base, max_step_dt_s=base.step_dt_s))
    widened = solve_ik(planner.kin, off, stance.holds, config=base)
    assert not fixed.converged and fixed.iterations == 1
    assert widened.converged and widened.position_error_m < base.position_tol_m
@pytest.mark.parametrize("resolution", [0.01, 0.04])
def test_interpolation_meets_the_resolution(planner, standing, resolution):
    q, stance = standing
    qb = _crouch(planner, q, stance, 0.12)
    contacts = {h.limb: h.target for h in stance.holds}
    path = contact_space_interpolate(planner.kin, planner.checker, q, qb, stance.holds, stance,
                                     contacts, resolution_rad=resolution)
    steps = [planner.kin.joint_distance(a, b) for a, b in zip([q] + path[:-1], path,
                                                               strict=True)]
    assert max(steps) <= resolution
    assert np.array_equal(path[-1], qb)
    coarse = contact_space_interpolate(planner.kin, planner.checker, q, qb, stance.holds,
                                       stance, contacts, resolution_rad=4 * resolution)
    assert len(coarse) < len(path)


def test_recursion_depth_is_bounded(planner, standing):
    q, stance = standing
    qb = _crouch(planner, q, stance, 0.12)
    with pytest.raises(InterpolationError, match="resolution not reached"):
        contact_space_interpolate(planner.kin, planner.checker, q, qb, stance.holds, stance,
                                  {h.limb: h.target for h in stance.holds}, max_depth=2)


def test_interpolation_refuses_an_unstable_midpoint():
    planner = ClimbPlanner(replace(load_ladder("drc"), placement_x_m=3.0), seed=1)  # clear
    q, stance = planner.start_configuration()
    qb = _crouch(planner, q, stance, 0.05)
    one_foot = Stance(stance.holds[:1])  # stability judged on one foot: the CoM is outside
    with pytest.raises(InterpolationError, match="outside the support region|torque"):
        contact_space_interpolate(planner.kin, planner.checker, q, qb, stance.holds, one_foot,
                                  {h.limb: h.target for h in stance.holds})


def test_interpolation_pulls_a_midpoint_s_com_back_into_the_support_region():
    """Two stable ends can have an unstable joint-space midpoint: raising both arms
    forward-up from hanging swings them through horizontal, in front of the body. With
    rigid arms, every DRC sample of the left hand's first move failed so (the CoM 0.2–1 cm
    out) until the projection also pulled the CoM into the region."""
    planner = ClimbPlanner(replace(load_ladder("drc"), placement_x_m=3.0), seed=1)  # clear
    q, stance = planner.start_configuration()
    kin, contacts = planner.kin, {h.limb: h.target for h in stance.holds}
    leaning = solve_ik(kin, q, stance.holds, torso_R=planner.torso_R,
                       pelvis_target_m=q[:3] + [0.05, 0.0, 0.0], pelvis_weight=1.0)
    assert leaning.converged
    arms_down = leaning.q.copy()
    for side in "LR":
        arms_down[kin.q_index[f"{side}SP"]], arms_down[kin.q_index[f"{side}EB"]] = 0.0, -0.2
    arms_up = arms_down.copy()
    for side in "LR":
        arms_up[kin.q_index[f"{side}SP"]] = -3.0
    for end in (arms_down, arms_up):
        assert planner.checker.check(end, stance, contacts).ok
    straight = planner.checker.check(kin.interpolate(arms_down, arms_up, 0.5), stance, contacts)
    assert straight.com_margin_m < 0
    path = contact_space_interpolate(kin, planner.checker, arms_down, arms_up, stance.holds,
                                     stance, contacts)
    assert all(planner.checker.check(qi, stance, contacts).ok for qi in path)


def test_first_step_is_deterministic_for_a_seed():
    results = []
    for _ in range(2):
        p = ClimbPlanner(load_ladder("drc"), seed=7)
        q, stance = p.start_configuration()
        segs, q_end, _ = p.try_step(climb_sequence(0)[0], q, stance, 0.02, StepStats("x"))
        results.append(np.vstack([c for s in segs for c in s.configs]))
    assert np.array_equal(results[0], results[1])


def test_placed_hands_meet_their_rail_holds(planner, standing):
    q, stance = standing
    segs, q_end, new_stance = planner.try_step(climb_sequence(0)[0], q, stance, 0.0,
                                               StepStats("x"))
    assert {h.limb for h in new_stance.holds} == {"left_foot", "right_foot", "left_hand",
                                                  "right_hand"}
    for hold in new_stance.holds:
        p = planner.kin.frame_pose(q_end, hold.frame)[:3, 3]
        assert np.linalg.norm(p - hold.T_world_frame[:3, 3]) < 1e-3
        if hold.is_hand:  # on the rail's axis
            axis_point = planner.geom.closest_rail_point(hold.target.split("_")[1], p)
            assert np.linalg.norm(axis_point - p) < 1e-3
    assert [s.phase for s in segs][-2:] == ["grasp", "grasp"]


def test_held_wrists_stay_out_of_the_singular_band_while_a_foot_swings():
    """With a held-wrist margin, while a foot is in the air the hands on the rails keep
    their wrist pitches at least the margin from zero, where the wrist's yaw and roll
    axes line up; the checker refuses a held wrist inside the band then, and only then."""
    margin = 0.15
    planner = ClimbPlanner(load_ladder("drc"), seed=1,
                           config=PlannerConfig(held_wrist_margin_rad=margin))
    q, stance = planner.start_configuration()
    steps = climb_sequence(0)
    _, q, stance = planner.try_step(steps[0], q, stance, 0.0, StepStats("x"))
    segs, q_end, new_stance = planner.try_step(steps[1], q, stance, 0.0, StepStats("x"))
    swing = [s for s in segs if s.phase == "limb"]
    assert swing and all(s.moving_limbs == ("left_foot",) for s in swing)
    for seg in swing:
        for c in seg.configs:
            for joint in WRIST_PITCH_JOINT.values():
                assert abs(c[planner.kin.q_index[joint]]) >= margin - 1e-9
    one_foot = Stance(tuple(h for h in new_stance.holds if h.limb != "left_foot"))
    contacts = {h.limb: h.target for h in one_foot.holds}
    straight = swing[-1].configs[-1].copy()
    straight[planner.kin.q_index["RWP"]] = 0.5 * margin
    refused = planner.checker.check(straight, one_foot, contacts)
    assert refused.cause is RejectCause.WRIST_SINGULARITY and "right_hand" in refused.reason
    assert planner.checker.singular_held_wrist(straight, new_stance) is None  # both feet down
    assert HELD_WRIST_MARGIN_RAD == 0  # off by default: the default planner has no band
    assert ClimbPlanner(load_ladder("drc"), seed=1).checker.singular_held_wrist(
        straight, one_foot) is None


def test_a_joint_bound_narrows_one_solve_and_the_limits_come_back(planner, standing):
    q, stance = standing
    i = planner.kin.q_index["LWP"]

    def limits():
        model = planner.kin.wrapper.model
        return float(model.lowerPositionLimit[i]), float(model.upperPositionLimit[i])

    before = limits()
    r = solve_ik(planner.kin, q, stance.holds, posture_rad={"LWP": 0.0},
                 joint_bounds_rad={"LWP": (0.3, np.inf)})
    assert r.converged and r.q[i] >= 0.3 - 1e-6
    free = solve_ik(planner.kin, q, stance.holds, posture_rad={"LWP": 0.0})
    assert abs(free.q[i]) < 0.3
    assert limits() == before


def test_unreachable_ladder_fails_with_the_primitive_and_rung():
    from dataclasses import replace

    far = replace(load_ladder("drc"), placement_x_m=1.5)  # rails out of the arms' reach
    p = ClimbPlanner(far, config=PlannerConfig(samples_per_step=3, time_limit_s=60), seed=1)
    with pytest.raises(PlanningFailed) as err:
        p.plan(top_rung=0)
    assert err.value.step.primitive.name == "placeHands"
    assert "rung 0" in str(err.value)


def test_a_stage_solved_on_one_rung_is_the_first_guess_on_the_next(planner, standing):
    step = climb_sequence(2)[7]  # moveRFoot onto rung 1
    q, _ = standing
    planner._remember(step, 2, q)
    up = replace(step, rung=step.rung + 1)
    hint = planner._hint(up, 2, attempt=0)
    rung_step = planner.geom.rung_top_point(1) - planner.geom.rung_top_point(0)
    np.testing.assert_allclose(hint[:3], q[:3] + rung_step)
    np.testing.assert_array_equal(hint[3:], q[3:])
    assert planner._hint(up, 2, attempt=1) is None  # later samples explore
    assert planner._hint(step, 2, attempt=0) is None  # not on the rung it was found on
    assert planner._hint(up, 3, attempt=0) is None  # nothing found for that stage


def test_stepping_onto_rung_0_with_compliant_arms_is_found():
    """The hardest step of the DRC mount: the right foot leaves the floor with the left on
    rung 0 (0.305 m up) and PWM-compliant arms; the torque descent must find it."""
    p = ClimbPlanner(load_ladder("drc"), seed=1)
    assert p.config.arm_strategy == "mixed"
    q, stance = p.start_configuration()
    steps = climb_sequence(0)
    for step in steps[:2]:
        _, q, stance = p.try_step(step, q, stance, 0.0, StepStats("x"))
    for attempt in range(10):
        try:
            _, q_end, new_stance = p.try_step(steps[2], q, stance, 0.0, StepStats("x"),
                                              attempt)
            break
        except Exception:  # noqa: BLE001 - a failed sample; the search tries another
            continue
    else:
        pytest.fail("placeRFoot not found in 10 samples")
    verdict = p.checker.check(q_end, new_stance, {h.limb: h.target for h in new_stance.holds})
    assert verdict.ok and verdict.torque_ratio <= 1.0
    assert {h.target for h in new_stance.holds if not h.is_hand} == {"rung_0"}


def test_rigid_arms_climb_the_first_drc_rung():
    """With rigid arms the straightened stance leans on both hands; every sample of the
    left hand's first move then swung the CoM out of the support region at a midpoint
    (or hit the rail), and ``plan-ladder drc --arm-strategy position`` failed there."""
    # without the feet's centre-of-pressure margin: with 2 cm no pose of this move was
    # found in 90 s (session 11)
    p = ClimbPlanner(load_ladder("drc"), seed=1,
                     config=PlannerConfig(arm_strategy="position", time_limit_s=90,
                                          foot_cop_margin_m=0.0))
    result = p.plan(top_rung=1)
    assert {h.target for h in result.final_stance.holds if not h.is_hand} == {"rung_1"}
    assert sum(st.backtracks for st in result.step_stats) == 0


def test_stepping_off_the_floor_seeds_the_pelvis_as_high_as_the_floor_leg_reaches(
        planner, standing):
    q, stance = standing
    place_r_foot = climb_sequence(0)[2]
    assert place_r_foot.primitive.name == "placeRFoot"
    target = planner._pelvis_target(place_r_foot, stance.holds)
    assert target[2] == pytest.approx(q[2] - place_r_foot.primitive.pelvis_below_standing_m)
    # Other steps keep their height above the supporting feet.
    straighten = climb_sequence(0)[3]
    feet_z = np.mean([h.T_world_frame[2, 3] for h in stance.holds])
    assert planner._pelvis_target(straighten, stance.holds)[2] == pytest.approx(
        feet_z + straighten.primitive.pelvis_offset_m[2])


def test_narrow_rails_mount_leaves_the_arms_a_lift_off_within_their_torque():
    """Ship ladder (rails 0.79 m apart, 0.17 m outside the shoulders): the hands take the
    rails clear of the shoulders, collision-free, and once the left foot is on rung 0 the
    floor foot can lift with the compliant arms within their torque and the elbows off their
    fold limit (with the hands beside the shoulders it was rarely found)."""
    from planner.configuration.feasible import find_feasible

    p = ClimbPlanner(load_ladder("ship"), seed=1)
    q, stance = p.start_configuration()
    steps = climb_sequence(0)
    for step in steps[:2]:
        _, q, stance = p.try_step(step, q, stance, 0.0, StepStats("x"))
    support = tuple(h for h in stance.holds if h.limb != "right_foot")
    pelvis = p._pelvis_target(steps[2], support)
    target = p._target(steps[2], stance.holds, (), Stance(support),
                       p._contacts(stance.holds), pelvis, q=q)
    q_lift, verdict = find_feasible(p.kin, p.checker, q, target, np.random.default_rng(1),
                                    attempts=12)
    assert q_lift is not None and verdict.torque_ratio <= 1.0
    fold_limit_rad = p.kin.model.lowerPositionLimit[p.kin.q_index["LEB"]]
    for elbow in ("LEB", "REB"):
        assert q_lift[p.kin.q_index[elbow]] > fold_limit_rad + 0.05


@pytest.mark.parametrize("robot", ["drc-hubo", "hubo2plus"])
def test_wrist_pitch_stops_short_of_the_closed_fingers(robot):
    """Bent far enough, the forearm folds onto a closed hand's fingers (on the ship ladder
    the IK rolled the hands about the rails into that bend until no foot could lift): the
    planner bounds each wrist pitch where they still clear it at every wrist roll."""
    import pinocchio as pin

    from planner.configuration.kinematics import HuboKinematics
    from planner.search import WRIST_FOLD_MARGIN_RAD, WRIST_FOLD_SCAN_STEP_RAD
    from robot.joints import FINGER_JOINTS
    from robot.kinematic_tree import FINGER_CLOSED_RAD

    p = ClimbPlanner(load_ladder("ship"), robot=robot)
    kin = p.kin
    q = pin.neutral(kin.model)
    for name in FINGER_JOINTS["left"]:
        q[kin.q_index[name]] = FINGER_CLOSED_RAD
    i, roll = kin.q_index["LWP"], kin.q_index.get("LWR")
    lo, hi = kin.model.lowerPositionLimit[i], kin.model.upperPositionLimit[i]
    assert p.checker._lower[i - 7] == lo and p.checker._upper[i - 7] == hi
    rolls = [0.0] if roll is None else np.linspace(kin.model.lowerPositionLimit[roll],
                                                   kin.model.upperPositionLimit[roll], 9)

    def folded(pitch_rad):
        for r in rolls:
            q[i] = pitch_rad
            if roll is not None:
                q[roll] = r
            if any("L_forearm" in a and "L_finger" in b
                   for a, b in p.collision.colliding_pairs(q)):
                return True
        return False

    joint = HuboKinematics.load(robot).model
    beyond = WRIST_FOLD_MARGIN_RAD + WRIST_FOLD_SCAN_STEP_RAD
    for bound, joint_limit in ((lo, joint.lowerPositionLimit[i]),
                               (hi, joint.upperPositionLimit[i])):
        assert not folded(bound)
        assert bound == joint_limit or folded(bound + np.copysign(beyond, bound))
    assert (lo, hi) != (joint.lowerPositionLimit[i], joint.upperPositionLimit[i])


def _left_arm_pair(planner, q):
    """Two left-arm poses of the standing robot whose straight joint-space line passes the
    forearm through the left rail (found by a seeded search, values rounded)."""
    from robot.joints import LEFT_ARM

    a, b = q.copy(), q.copy()
    idx = [planner.kin.q_index[n] for n in LEFT_ARM]
    a[idx] = [0.85, 0.22, 1.44, -0.73, -0.74, -0.29, -1.08]
    b[idx] = [-1.39, 1.2, 0.79, -0.62, -0.43, 1.84, 1.1]
    return a, b


def test_rrt_fallback_goes_around_what_the_straight_line_hits(planner, standing):
    from planner.paths.limb_rrt import plan_limb_path
    from robot.joints import LEFT_ARM

    q, stance = standing
    contacts = {h.limb: h.target for h in stance.holds}
    a, b = _left_arm_pair(planner, q)
    check = planner.checker.check
    assert check(a, stance, contacts).ok and check(b, stance, contacts).ok
    line = [planner.kin.interpolate(a, b, s) for s in np.linspace(0, 1, 60)]
    assert any(not check(x, stance, contacts).ok for x in line)  # the arc would fail

    path = plan_limb_path(planner.kin, planner.checker, a, b, LEFT_ARM, stance, contacts,
                          resolution_rad=0.01)
    assert path is not None
    np.testing.assert_array_equal(path[-1], b)
    steps = [planner.kin.joint_distance(x, y) for x, y in zip([a] + path[:-1], path, strict=True)]
    assert max(steps) <= 0.01 + 1e-9
    idx = [planner.kin.q_index[n] for n in LEFT_ARM]
    rest = np.setdiff1d(np.arange(len(q)), idx)
    for x in path:
        np.testing.assert_array_equal(x[rest], a[rest])  # the body is held
        assert check(x, stance, contacts).ok


_RRT_IN_A_FRESH_PROCESS = '''
import hashlib, sys
import numpy as np
sys.path.insert(0, {tests!r})
from test_planner_search import _left_arm_pair
from ladders.loader import load_ladder
from planner.paths.limb_rrt import plan_limb_path
from planner.search import ClimbPlanner
from robot.joints import LEFT_ARM
p = ClimbPlanner(load_ladder("drc"), seed=1)
q, stance = p.start_configuration()
a, b = _left_arm_pair(p, q)
path = plan_limb_path(p.kin, p.checker, a, b, LEFT_ARM, stance,
                      {{h.limb: h.target for h in stance.holds}})
print(hashlib.sha256(np.array(path).tobytes()).hexdigest())
'''


def test_rrt_fallback_is_deterministic_per_process():
    # OMPL draws from one process-wide generator seeded once with a fixed seed, and the
    # search budget counts validity checks, not seconds: a fresh process (plan-ladder)
    # gives the same path every time.
    import subprocess
    import sys
    from pathlib import Path

    code = _RRT_IN_A_FRESH_PROCESS.format(tests=str(Path(__file__).parent))
    runs = [subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                           check=True).stdout.split()[0] for _ in range(2)]
    assert runs[0] == runs[1]


def test_rrt_fallback_holds_the_body(planner, standing):
    from planner.paths.limb_rrt import plan_limb_path
    from robot.joints import LEFT_ARM

    q, stance = standing
    a, b = _left_arm_pair(planner, q)
    b[planner.kin.q_index["RSP"]] += 0.1  # another limb moves too: not this planner's job
    with pytest.raises(ValueError, match="differ only in the moving joints"):
        plan_limb_path(planner.kin, planner.checker, a, b, LEFT_ARM, stance,
                       {h.limb: h.target for h in stance.holds})


def test_start_lowers_the_arms_where_the_rungs_are_within_reach_of_the_chest(planner):
    from planner.search import START_POSTURES

    def start_shoulder_pitch(p):
        q, stance = p.start_configuration()
        assert p.checker.check(q, stance, {h.limb: h.target for h in stance.holds}).ok
        return q[p.kin.q_index["LSP"]]

    # DRC (60°): forearms forward. A 74° ladder at the same placement: rung 2 is where
    # the forward hands would be, so the robot starts with its arms hanging.
    assert start_shoulder_pitch(planner) == pytest.approx(START_POSTURES[0]["SP"], abs=0.05)
    steep = replace(load_ladder("drc"), slope_deg=74.2, rung_spacing_m=0.322,
                    rail_spacing_m=0.816)
    assert start_shoulder_pitch(ClimbPlanner(steep, seed=1)) == pytest.approx(
        START_POSTURES[1]["SP"], abs=0.05)


def test_rrt_fallback_takes_ends_a_rounding_error_past_a_limit(planner, standing):
    # The planner's own check allows LIMIT_TOL past a limit; OMPL, given bounds that
    # exclude the goal, used to wait for a valid goal forever.
    from planner.paths.limb_rrt import plan_limb_path
    from robot.joints import LEFT_ARM

    q, stance = standing
    contacts = {h.limb: h.target for h in stance.holds}
    b = q.copy()
    i = planner.kin.q_index["LWY"]
    b[i] = planner.kin.model.lowerPositionLimit[i] - 1e-9
    assert planner.checker.check(b, stance, contacts).ok
    path = plan_limb_path(planner.kin, planner.checker, q, b, LEFT_ARM, stance, contacts)
    assert path is not None and np.array_equal(path[-1], b)
