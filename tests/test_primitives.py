"""Primitives as data: the climbing sequence and seed holds that adapt to any ladder."""

from dataclasses import replace

import numpy as np
import pytest

from ladders.geometry import LadderGeometry
from ladders.loader import load_ladder
from planner.holds import (
    FOOT_COP_MARGIN_M,
    FOOT_FRICTION_SHARE,
    SHIN_ROOM_M,
    TREAD_UNDER_SOLE_M,
    make_hold,
    palm_rotation,
    rail_point,
    shin_room_along_m,
)
from primitives import RailSeed, RungSeed, climb_sequence
from primitives.hold_seeds import FOOT_ALONG_M, MOUNT_ALONG_RAIL_M
from primitives.library import CLIMB_TORSO_ALONG_M, MOUNT_TORSO_ALONG_M
from robot.params import DRC_HUBO


def test_sequence_mounts_then_repeats_the_thesis_cycle():
    steps = climb_sequence(2)
    names = [s.primitive.name for s in steps]
    assert names[:4] == ["placeHands", "placeLFoot", "placeRFoot", "straighten"]
    cycle = ["moveLHand", "moveRHand", "moveLFoot", "moveRFoot", "straighten"]
    assert names[4:] == cycle * 2
    feet = [s.new_holds[0].rung for s in steps if isinstance(s.new_holds[:1] and
                                                             s.new_holds[0], RungSeed)]
    assert feet == [0, 0, 1, 1, 2, 2]
    with pytest.raises(ValueError):
        climb_sequence(-1)


@pytest.mark.parametrize("name", ["drc", "ship", "stair"])
def test_foot_holds_rest_on_their_rung(name):
    spec = load_ladder(name)
    geom = LadderGeometry(spec)
    for rung in (0, spec.num_rungs - 1):
        hold = make_hold(RungSeed("left_foot", rung, 0.11), geom, DRC_HUBO)
        along_m = min(FOOT_ALONG_M, shin_room_along_m(geom, DRC_HUBO))
        top = geom.rung_top_point(rung, lateral_m=0.11, along_m=along_m)
        np.testing.assert_allclose(hold.T_world_frame[:3, 3], top, atol=1e-12)
        # A foot is planned to a share of the ladder's friction.
        assert np.all(hold.normals[:, 2] == 1.0)
        assert hold.friction == pytest.approx(FOOT_FRICTION_SHARE * spec.friction)
        whole = make_hold(RungSeed("left_foot", rung, 0.11), geom, DRC_HUBO,
                          friction_share=1.0)
        assert whole.friction == spec.friction
        # Contact corners lie on the tread, the centre-of-pressure margin inside its
        # edges and the sole's sides.
        local = geom.to_ladder(hold.points_m)
        along = local[:, 0] - spec.rung_run_m(rung)
        assert np.all(np.abs(along) <= spec.rung_depth_m / 2 - FOOT_COP_MARGIN_M + 1e-9)
        aside = np.abs(local[:, 1] - geom.to_ladder(hold.T_world_frame[:3, 3])[1])
        np.testing.assert_allclose(aside, DRC_HUBO.foot_width_m / 2 - FOOT_COP_MARGIN_M)


def test_a_foot_on_close_box_treads_stands_back_for_its_shin():
    """A foot's seed keeps its shin `SHIN_ROOM_M` behind the back edge of the tread
    above, while `TREAD_UNDER_SOLE_M` of the sole stays on its own tread: on `ship`
    (rungs 0.254 m apart) the feet stand back, as far as the tread allows; on `drc` and
    `stair` they stay at the ball-of-foot seed; on round rungs the ball stays on the rung."""
    def placed(spec):
        geom = LadderGeometry(spec)
        hold = make_hold(RungSeed("left_foot", 1, 0.11), geom, DRC_HUBO)
        along = geom.to_ladder(hold.T_world_frame[:3, 3])[0] - spec.rung_run_m(1)
        back_edge_above = spec.rung_run_m(2) - spec.rung_run_m(1) - spec.rung_depth_m / 2
        on_tread = min(along + DRC_HUBO.foot_length_m / 2, spec.rung_depth_m / 2) \
            + spec.rung_depth_m / 2
        return along, back_edge_above - along, on_tread

    for name in ("drc", "stair"):
        along, room, _ = placed(load_ladder(name))
        assert along == pytest.approx(FOOT_ALONG_M) and room >= SHIN_ROOM_M
    ship = load_ladder("ship")
    along, room, on_tread = placed(ship)
    assert along < FOOT_ALONG_M - 0.03  # 3.9 cm further back
    assert room > SHIN_ROOM_M - 0.01 and on_tread == pytest.approx(TREAD_UNDER_SOLE_M)
    wider = replace(ship, rung_spacing_m=0.30)  # room enough before the tread runs out
    along, room, on_tread = placed(wider)
    assert room == pytest.approx(SHIN_ROOM_M) and on_tread > TREAD_UNDER_SOLE_M
    assert FOOT_ALONG_M - 0.03 < along < FOOT_ALONG_M
    round_rungs = replace(ship, rung_shape="cylinder", rung_depth_m=0.04)
    assert placed(round_rungs)[0] == pytest.approx(FOOT_ALONG_M)


def test_rail_holds_follow_the_ladder_placement():
    spec = load_ladder("drc")
    moved = replace(spec, placement_x_m=spec.placement_x_m + 0.1, placement_yaw_rad=0.1)
    for s in (spec, moved):
        geom = LadderGeometry(s)
        hold = make_hold(RailSeed("right_hand", "right", 3), geom, DRC_HUBO)
        assert hold.friction == s.friction  # the grip's model keeps the whole μ
        p = hold.T_world_frame[:3, 3]
        assert np.linalg.norm(geom.closest_rail_point("right", p) - p) < 1e-9
        # The grip axis runs along the rail.
        assert abs(abs(hold.T_world_frame[:3, 0] @ geom.ladder_direction) - 1) < 1e-9


def test_grip_styles_keep_the_grip_axis_on_the_rail():
    geom = LadderGeometry(load_ladder("ship"))
    grip = geom.rail_point_above_rung("left", 2)
    shoulder = grip + np.array([-0.4, -0.15, -0.1])
    for style in ("facing", "shoulder"):
        R = palm_rotation(geom, "left", grip, shoulder, style)
        np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
        assert abs(abs(R[:, 0] @ geom.ladder_direction) - 1) < 1e-12
    R = palm_rotation(geom, "left", grip, shoulder, "shoulder")
    to_shoulder = shoulder - grip
    assert R[:, 2] @ to_shoulder > 0  # the wrist points back towards the shoulder
    with pytest.raises(ValueError):
        palm_rotation(geom, "left", grip, shoulder, "sideways")


@pytest.mark.parametrize("name", ["drc", "ship", "stair"])
def test_mount_holds_leave_the_arms_room_from_the_shoulders_over_rung_0(name):
    """Wide rails keep the low mount hold; close ones (ship) move it up the rail until it is
    an upper arm's length, horizontally, from the shoulder of the torso over rung 0."""
    geom = LadderGeometry(load_ladder(name))
    seed = climb_sequence(0)[0].new_holds[0]
    assert seed.limb == "left_hand" and seed.torso_along_m == MOUNT_TORSO_ALONG_M
    p = make_hold(seed, geom, DRC_HUBO, shoulder_m=np.array([0.0, 0.23, 1.16]),
                  grip_style="shoulder").T_world_frame[:3, 3]
    shoulder = geom.rung_top_point(0, lateral_m=DRC_HUBO.half_shoulder_width_m,
                                   along_m=MOUNT_TORSO_ALONG_M)
    horizontal_m = np.linalg.norm(geom.to_ladder(p)[:2] - geom.to_ladder(shoulder)[:2])
    low = rail_point(geom, "left", 0, MOUNT_ALONG_RAIL_M)
    if name == "ship":
        assert horizontal_m == pytest.approx(DRC_HUBO.upper_arm_m)
        assert (p - low) @ geom.ladder_direction > 0.4
    else:
        np.testing.assert_allclose(p, low, atol=1e-12)
        assert horizontal_m > DRC_HUBO.upper_arm_m


@pytest.mark.parametrize("name", ["drc", "ship", "stair"])
def test_climb_holds_leave_the_arms_room_from_the_torso_over_their_rung(name):
    """The holds above rung k+1 carry the body once it stands over rung k+1: like the mount
    holds, close rails (ship) move them up the rail, away from that torso's shoulders."""
    geom = LadderGeometry(load_ladder(name))
    step = climb_sequence(2)[4]
    seed = step.new_holds[0]
    assert step.primitive.name == "moveLHand" and seed.rung == 1
    assert seed.torso_along_m == CLIMB_TORSO_ALONG_M
    p = make_hold(seed, geom, DRC_HUBO).T_world_frame[:3, 3]
    shoulder = geom.rung_top_point(1, lateral_m=DRC_HUBO.half_shoulder_width_m,
                                   along_m=CLIMB_TORSO_ALONG_M)
    horizontal_m = np.linalg.norm(geom.to_ladder(p)[:2] - geom.to_ladder(shoulder)[:2])
    above = rail_point(geom, "left", 1)
    if name == "ship":
        assert horizontal_m == pytest.approx(DRC_HUBO.upper_arm_m)
        assert (p - above) @ geom.ladder_direction > 0.1
    else:
        np.testing.assert_allclose(p, above, atol=1e-12)
