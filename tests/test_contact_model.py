"""The one contact model (ladders.contact_model): grip and foot limits, read alike by the
planner's torque LP, check-plan and the MuJoCo grasp latch (issue 22)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pinocchio as pin
import pytest

import ladders.contact_model as cm
from ladders.contact_model import (
    FootPatch,
    GripCapacity,
    GripGeometry,
    hand_limits,
    sole_patch_x,
)
from ladders.geometry import LadderGeometry
from ladders.loader import load_ladder
from planner.contacts import Hold, Stance
from planner.holds import make_hold
from planner.statics.com_region import support_region
from planner.statics.torque_lp import torque_feasibility
from primitives.hold_seeds import RailSeed, RungSeed
from robot.params import DRC_HUBO

#: A reserve on the grip's capacity, for the LP's limits at a share below 1 [-].
GRIP_RESERVE = 0.8

MASS_KG = 10.0
WEIGHT_N = MASS_KG * 9.81


# ------------------------------------------------------------------ the grip's capacity


def test_capacity_is_the_grips_geometry_and_finger_torques():
    cap = GripCapacity.of(GripGeometry(), friction=0.4, rail_radius_m=0.025)
    lever = math.hypot(0.04, 0.045)
    assert cm.HUBO_GRIP.finger_lever_m == pytest.approx(lever, abs=5e-4)
    assert cap.radial_n == pytest.approx(5 * 5.0 / 0.06)
    assert cap.bending_nm == pytest.approx(5.0 / 0.06 * (2 * 0.036 + 2 * 0.018))
    assert cap.squeeze_n == pytest.approx(5 * 1.0 / 0.06)
    assert cap.along_n(0.0) == pytest.approx(0.4 * 2 * cap.squeeze_n)
    with pytest.raises(ValueError, match="squeeze"):
        GripGeometry(finger_squeeze_nm=6.0)


def test_halfspaces_are_inside_the_grips_capacity():
    """Every wrench the LP may choose is one the latch holds: sample the polytope's
    boundary along random directions and read the latch's own utilisation."""
    rng = np.random.default_rng(3)
    axis = np.array([math.cos(math.radians(60)), 0.0, math.sin(math.radians(60))])
    lim = hand_limits(0.4, 0.025, axis, share=GRIP_RESERVE)
    A, b = lim.halfspaces()
    for _ in range(300):
        d = rng.normal(size=6)
        # the largest step along d that stays inside A w <= b
        ad = A @ d
        step = np.min(b[ad > 0] / ad[ad > 0])
        w = step * d
        u = lim.utilisation(w[:3], w[3:])
        assert max(u.values()) <= GRIP_RESERVE + 1e-9
    # and the polygons reach most of the disc: a pure bending moment of 0.9·0.8·B fits
    t = np.array([0.0, 1.0, 0.0]) * 0.9 * GRIP_RESERVE * lim.capacity.bending_nm
    assert np.all(A @ np.concatenate([np.zeros(3), t]) <= b + 1e-9)


# ------------------------------------------------------------------ a toy body on a hold
#
# A 10 kg box standing on a line contact (two points along x at the origin) and holding a
# rail along x whose grip centre lies on that line: forces at the hand make no moment
# about the line, so a CoM ahead of it (y = 0, x = d) must be held by the grip's bending
# moment about y, W·d (a rail along x bends about y).


def toy_model():
    model = pin.Model()
    root = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root")
    model.appendBodyToJoint(root, pin.Inertia.FromBox(MASS_KG, 0.1, 0.1, 0.1),
                            pin.SE3.Identity())
    j = model.addJoint(root, pin.JointModelRY(), pin.SE3.Identity(), "J1")
    model.appendBodyToJoint(j, pin.Inertia.FromSphere(1e-3, 0.01), pin.SE3.Identity())
    for name in ("R_palm", "L_sole"):
        model.addFrame(pin.Frame(name, root, pin.SE3.Identity(), pin.FrameType.OP_FRAME))
    return model


def toy_stance(hand: Hold) -> Stance:
    """A line foot across y at the origin, and ``hand``."""
    line = Hold("left_foot", "line", np.eye(4), np.array([[0.0, 0.05, 0.0], [0.0, -0.05, 0.0]]),
                np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]]), 0.6)
    return Stance((line, hand))


def toy_hand(share: float, grip: GripGeometry | None = None) -> Hold:
    lim = hand_limits(0.4, 0.025, np.array([1.0, 0.0, 0.0]), share=share, grip=grip)
    return Hold("right_hand", "rail", np.eye(4), np.zeros((2, 3)),
                np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]), 0.4, limits=lim)


def toy_check(com_ahead_m: float, hand: Hold, objective: str = "torque"):
    model = toy_model()
    model.inertias[1] = pin.Inertia(MASS_KG, np.array([com_ahead_m, 0.0, 0.3]),
                                    np.eye(3) * 0.01)
    data = model.createData()  # root at the origin: hand and sole frames there
    return torque_feasibility(model, data, pin.neutral(model), toy_stance(hand), {"J1": 100.0},
                              {"left_foot": model.getFrameId("L_sole"),
                               "right_hand": model.getFrameId("R_palm")}, objective=objective)


def test_a_wrench_beyond_the_bending_limit_is_refused_by_the_planner():
    bending = GripCapacity.of(GripGeometry(), 0.4, 0.025).bending_nm  # 9 N·m
    inside = 0.6 * bending / WEIGHT_N  # CoM ahead: the grip must bend by 0.6 B
    ok = toy_check(inside, toy_hand(GRIP_RESERVE))
    assert ok.equilibrium
    force, torque = ok.wrenches["right_hand"]
    assert abs(torque[1]) == pytest.approx(0.6 * bending, rel=1e-6)
    # between the reserve and the capacity: refused by the planner, held by the latch
    between = 0.9 * bending / WEIGHT_N
    assert not toy_check(between, toy_hand(GRIP_RESERVE)).equilibrium
    assert toy_check(between, toy_hand(1.0)).equilibrium
    # beyond the capacity: refused by the planner and by check-plan's whole capacity
    beyond = 1.1 * bending / WEIGHT_N
    assert not toy_check(beyond, toy_hand(GRIP_RESERVE)).equilibrium
    assert not toy_check(beyond, toy_hand(1.0)).equilibrium
    # the old point hold (force only) could not hold even the first
    point = Hold("right_hand", "rail", np.eye(4), np.zeros((2, 3)),
                 np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]), 0.4)
    assert not toy_check(inside, point).equilibrium


def test_check_plans_contact_wrench_flags_a_bending_overload():
    """check-plan's contact LP: the least grip utilisation any load share within the
    joint limits needs; over 1 (or none) fails."""
    from planner.verify.check import contact_wrench_utilisation

    bending = GripCapacity.of(GripGeometry(), 0.4, 0.025).bending_nm
    ok = contact_wrench_utilisation(toy_check(0.6 * bending / WEIGHT_N, toy_hand(1.0),
                                              "contact"))
    assert ok.value == pytest.approx(0.6, abs=0.02) and ok.limb == "right_hand"
    assert ok.load == "bending torque"
    bad = contact_wrench_utilisation(toy_check(1.1 * bending / WEIGHT_N, toy_hand(1.0),
                                               "contact"))
    assert bad.value == pytest.approx(1.1, abs=0.02) and bad.load == "bending torque"
    assert "right_hand bending torque 1.10 of its limit" in bad.detail


# ------------------------------------------------------------------ one source of limits


def test_check_plan_and_latch_read_the_same_grip(monkeypatch):
    """Halving the fingers' torque halves the radial and bending limits of check-plan's
    hand holds and of the MuJoCo latch; the planner's hand hold is the thesis's point
    hold (its figures: docs/decisions/contact-model.md)."""
    from daemon.sim.board_model import BoardModel
    from planner.verify.check import contact_hold
    from robot.plan_sidecar import HoldRecord

    spec = load_ladder("drc")
    geom = LadderGeometry(spec)

    def two():
        p = make_hold(RailSeed("right_hand", "right", 2), geom, DRC_HUBO).T_world_frame[:3, 3]
        checker = contact_hold(spec, geom, DRC_HUBO, "right_hand",
                               HoldRecord("rail_right", tuple(p))).limits
        latch = BoardModel(spec).latches["right"].capacity
        return checker, latch

    planned = make_hold(RailSeed("right_hand", "right", 2), geom, DRC_HUBO)
    assert planned.limits is None  # the planner's hand is the thesis's point hold
    c0, l0 = two()
    assert c0.share == 1.0 and c0.capacity == l0
    monkeypatch.setattr(cm, "HUBO_GRIP", replace(cm.HUBO_GRIP, finger_torque_nm=2.5))
    c1, l1 = two()
    assert c1.capacity == l1
    assert l1.bending_nm == pytest.approx(l0.bending_nm / 2)
    assert l1.radial_n == pytest.approx(l0.radial_n / 2)


# ------------------------------------------------------------------ feet


def test_a_foot_on_a_round_rung_gets_a_line_contact():
    box = load_ladder("drc")
    rod = replace(box, rung_shape="cylinder", rung_depth_m=0.04)
    for spec, line in ((box, False), (rod, True)):
        hold = make_hold(RungSeed("left_foot", 1, 0.11), LadderGeometry(spec), DRC_HUBO)
        assert isinstance(hold.limits, FootPatch) and hold.limits.is_line == line
        local = (hold.points_m - hold.T_world_frame[:3, 3]) @ hold.T_world_frame[:3, :3]
        along = np.ptp(local[:, 0])
        if line:  # the centre of pressure has no range along the sole
            assert along < 1e-9
        else:  # the sole ∩ tread overlap, 2 cm inside its edges
            assert 0.05 < along <= box.rung_depth_m - 2 * 0.02 + 1e-9
    assert sole_patch_x("cylinder", 0.02, 0.03, 0.22) == (0.03, 0.03)
    assert sole_patch_x("cylinder", 0.02, 0.2, 0.22) is None
    assert sole_patch_x("box", 0.05, 0.1, 0.22) == pytest.approx((0.05, 0.11))


def test_support_region_uses_the_grip_limits():
    """A hand on a rail holds a CoM beyond the feet only as far as its capacity: the
    region is bounded by the grip, no longer clipped to the LP's box."""
    feet = Stance((Hold("left_foot", "floor", np.eye(4),
                        FootPatch((-0.11, 0.11), 0.07, 0.4).corners(),
                        np.tile([0.0, 0.0, 1.0], (4, 1)), 0.4),))
    T = np.eye(4)
    T[:3, 3] = (0.5, 0.0, 1.0)
    hand = Hold("right_hand", "rail", T, np.tile(T[:3, 3], (2, 1)),
                np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]), 0.4,
                limits=hand_limits(0.4, 0.025, np.array([0.0, 1.0, 0.0])))
    region = support_region(feet.with_hold(hand), 60.0)
    assert not region.is_empty and not region.clipped
    assert region.vertices[:, 0].max() > 0.11  # the hand holds some CoM ahead of the foot
