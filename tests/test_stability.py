"""Static stability: friction cones, CoM support region, torque LP (planner.statics)."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from scipy.spatial import ConvexHull

from planner.contacts import Hold, Stance
from planner.statics.com_region import SupportRegion, support_region
from planner.statics.config import StabilityConfig, StabilityError
from planner.statics.contact_wrenches import friction_cone_edges
from planner.statics.stability import check_stability
from planner.statics.torque_lp import torque_feasibility, torque_limits_by_joint
from robot.errors import HuboLadderError
from robot.urdf import robot_urdf

MASS_KG = 45.0
HIP_Y_M = 0.0885
#: DRC-Hubo sole corners in the sole frame [m] (robot/kinematic_tree.py).
SOLE_CORNERS_M = np.array([(0.11, 0.07, 0.0), (0.11, -0.07, 0.0),
                           (-0.11, -0.07, 0.0), (-0.11, 0.07, 0.0)])
#: The part of a sole resting on a 4 cm deep rung [m].
RUNG_CORNERS_M = np.array([(0.02, 0.07, 0.0), (0.02, -0.07, 0.0),
                           (-0.02, -0.07, 0.0), (-0.02, 0.07, 0.0)])
RIGHT_ARM = ("RSP", "RSR", "RSY", "REB", "RWY", "RWP", "RWR")


def pose(xyz, rot=None) -> np.ndarray:
    T = np.eye(4)
    if rot is not None:
        T[:3, :3] = rot
    T[:3, 3] = xyz
    return T


def hold(limb, T, local_pts, local_normals, mu=0.4, target="test") -> Hold:
    """A hold whose points and normals are given in the limb frame T."""
    pts = np.asarray(local_pts, float) @ T[:3, :3].T + T[:3, 3]
    nrm = np.asarray(local_normals, float).reshape(-1, 3) @ T[:3, :3].T
    nrm = np.broadcast_to(nrm, pts.shape).copy()
    return Hold(limb, target, T, pts, nrm, mu)


def flat_feet(z=0.0, corners=SOLE_CORNERS_M, mu=0.4) -> Stance:
    return Stance((hold("left_foot", pose((0, HIP_Y_M, z)), corners, [0, 0, 1], mu),
                   hold("right_foot", pose((0, -HIP_Y_M, z)), corners, [0, 0, 1], mu)))


def rot_y(a) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def grasp_points():
    """A full grasp around a rail along y: contacts that can resist any wrench."""
    pts, nrm = [], []
    for sy in (-0.05, 0.05):
        for sx in (-0.03, 0.03):
            for nz in (1.0, -1.0):
                pts.append((sx, sy, 0.0))
                nrm.append((0.0, 0.0, nz))
        for sz in (-0.03, 0.03):
            for nx in (1.0, -1.0):
                pts.append((0.0, sy, sz))
                nrm.append((nx, 0.0, 0.0))
    return np.array(pts), np.array(nrm)


# --------------------------------------------------------------------------------------
# Friction cones


def test_cone_edges_are_unit_and_on_the_cone():
    n = np.array([[0, 0, 1.0], [1, 0, 0], [0.3, -0.4, 0.5]])
    e = friction_cone_edges(n, np.array([0.4, 1.0, 0.1]), k=8)
    assert e.shape == (3, 8, 3)
    np.testing.assert_allclose(np.linalg.norm(e, axis=2), 1.0)
    unit = n / np.linalg.norm(n, axis=1, keepdims=True)
    angles = np.arccos(np.einsum("nki,ni->nk", e, unit))
    np.testing.assert_allclose(angles, np.arctan([0.4, 1.0, 0.1])[:, None] * np.ones((1, 8)))
    # edges spread evenly around the normal: they sum along it
    s = e.sum(axis=1)
    np.testing.assert_allclose(np.cross(s, unit), 0.0, atol=1e-12)


def test_cone_needs_three_edges():
    with pytest.raises(ValueError, match="k >= 3"):
        friction_cone_edges(np.array([[0, 0, 1.0]]), 0.4, k=2)


# --------------------------------------------------------------------------------------
# Support region


def test_two_flat_feet_region_is_hull_of_sole_corners():
    stance = flat_feet()
    region = support_region(stance, MASS_KG)
    pts = stance.points_normals()[0][:, :2]
    hull = ConvexHull(pts)
    assert region.area_m2 == pytest.approx(hull.volume, rel=1e-3)
    assert len(region.vertices) == len(hull.vertices)
    for v in region.vertices:  # every vertex is a hull vertex
        assert np.min(np.linalg.norm(pts[hull.vertices] - v, axis=1)) < 1e-4
    assert not region.clipped and not region.is_empty
    x, y = region.vertices.T  # counter-clockwise: positive signed area
    assert 0.5 * (x @ np.roll(y, -1) - np.roll(x, -1) @ y) > 0


def test_region_does_not_depend_on_mass():
    a = support_region(flat_feet(), 45.0).vertices
    b = support_region(flat_feet(), 90.0, g=3.7).vertices
    np.testing.assert_allclose(a, b, atol=1e-6)


def test_margin_matches_hand_computed_distances():
    region = support_region(flat_feet(), MASS_KG)  # x ∈ ±0.11, y ∈ ±0.1585
    assert region.margin([0.0, 0.0]) == pytest.approx(0.11, abs=1e-5)
    assert region.margin([0.05, 0.10]) == pytest.approx(0.0585, abs=1e-5)
    assert region.margin([0.0, 0.0, 0.73]) == pytest.approx(0.11, abs=1e-5)  # z ignored
    assert region.margin([0.20, 0.0]) == pytest.approx(-0.09, abs=1e-5)
    assert region.margin([0.20, 0.20]) == pytest.approx(-math.hypot(0.09, 0.0415), abs=1e-5)
    assert region.contains([0.0, 0.0]) and not region.contains([0.2, 0.0])
    assert not region.contains([0.0, 0.0], min_margin_m=0.12)
    batch = region.margin(np.array([[0.0, 0.0], [0.2, 0.0]]))
    np.testing.assert_allclose(batch, [0.11, -0.09], atol=1e-5)
    np.testing.assert_array_equal(region.contains(np.array([[0.0, 0.0], [0.2, 0.0]])),
                                  [True, False])


def test_clockwise_vertices_for_placo():
    region = support_region(flat_feet(), MASS_KG)
    cw = region.clockwise_vertices()
    x, y = cw.T
    assert 0.5 * (x @ np.roll(y, -1) - np.roll(x, -1) @ y) < 0
    np.testing.assert_allclose(cw, region.vertices[::-1])


def test_hand_pulling_on_rail_extends_region_backwards():
    feet = flat_feet(z=0.3, corners=RUNG_CORNERS_M)
    feet_only = support_region(feet, MASS_KG)
    assert feet_only.vertices[:, 0].min() == pytest.approx(-0.02, abs=1e-4)
    # The fingers pull the hand towards the ladder (+x), 1.2 m up.
    rail = hold("right_hand", pose((0.05, -0.2, 1.2)), [[0, 0, 0]], [1.0, 0, 0])
    with_hand = support_region(feet.with_hold(rail), MASS_KG)
    assert with_hand.vertices[:, 0].min() < -0.2  # far behind the rung
    assert with_hand.vertices[:, 0].max() == pytest.approx(0.02, abs=1e-3)  # not forwards
    com_behind = np.array([-0.15, 0.0])
    assert feet_only.margin(com_behind) < 0 < with_hand.margin(com_behind)
    assert with_hand.gap_m2 <= max(1e-4, 0.01 * with_hand.area_m2)


def inclined_feet(tilt_rad, mu, facing) -> Stance:
    """Feet on two inclined planes at x = ∓0.2 m; normals tilted in the x-z plane."""
    left = rot_y(-tilt_rad if facing else tilt_rad)
    right = rot_y(tilt_rad)
    corners = SOLE_CORNERS_M * [0.3, 1, 1]
    return Stance((hold("left_foot", pose((-0.2, HIP_Y_M, 0.0), left), corners, [0, 0, 1], mu),
                   hold("right_foot", pose((0.2, -HIP_Y_M, 0.0), right), corners, [0, 0, 1],
                        mu)))


def test_steep_contacts_need_friction():
    # Both normals tilted 60° the same way: vertical support needs μ ≥ tan 60° ≈ 1.73.
    assert support_region(inclined_feet(math.radians(60), 0.1, False), MASS_KG).is_empty
    assert support_region(inclined_feet(math.radians(60), 1.0, False), MASS_KG).is_empty
    assert not support_region(inclined_feet(math.radians(60), 2.0, False), MASS_KG).is_empty
    # Tilted 30°: μ = 0.1 < tan 30° fails, μ = 1.0 holds.
    assert support_region(inclined_feet(math.radians(30), 0.1, False), MASS_KG).is_empty
    region = support_region(inclined_feet(math.radians(30), 1.0, False), MASS_KG)
    assert not region.is_empty and region.area_m2 > 0
    # A V groove (normals facing each other) holds with little friction.
    assert not support_region(inclined_feet(math.radians(60), 0.1, True), MASS_KG).is_empty


def test_empty_region_margin_is_minus_inf():
    down = Stance((hold("left_foot", pose((0, HIP_Y_M, 0)), SOLE_CORNERS_M, [0, 0, -1.0]),))
    region = support_region(down, MASS_KG)
    assert region.is_empty and region.area_m2 == 0
    assert region.margin([0.0, 0.0]) == -math.inf
    assert not region.contains([0.0, 0.0])
    assert "empty" in repr(region)


def test_single_point_contact_is_a_degenerate_region():
    point = Stance((hold("left_foot", pose((0.1, 0.2, 0)), [[0, 0, 0]], [0, 0, 1.0]),))
    region = support_region(point, MASS_KG)
    assert len(region.vertices) == 1
    np.testing.assert_allclose(region.vertices[0], [0.1, 0.2], atol=1e-6)
    assert region.margin([0.1, 0.2]) == pytest.approx(0.0, abs=1e-6)
    assert region.margin([0.1, 0.5]) == pytest.approx(-0.3, abs=1e-6)


def test_line_contact_is_a_segment():
    line = Stance((hold("left_foot", pose((0, 0, 0)), [[0, -0.1, 0], [0, 0.1, 0]], [0, 0, 1.0]),))
    region = support_region(line, MASS_KG)
    assert len(region.vertices) == 2 and region.area_m2 == 0
    assert region.margin([0.0, 0.05]) == pytest.approx(0.0, abs=1e-6)
    assert region.margin([0.03, 0.05]) == pytest.approx(-0.03, abs=1e-6)


def test_full_grasp_region_is_clipped_to_the_box():
    pts, nrm = grasp_points()
    region = support_region(Stance((hold("right_hand", pose((0.5, 0, 1.2)), pts, nrm),)),
                            MASS_KG)
    assert region.clipped
    assert region.area_m2 == pytest.approx(10.0 * 10.0, rel=1e-6)
    assert "clipped" in repr(region)


def test_region_rejects_bad_mass():
    with pytest.raises(ValueError, match="positive"):
        support_region(flat_feet(), 0.0)


def test_region_with_lp_cap_stops_and_stays_inner():
    rail = hold("right_hand", pose((0.05, -0.2, 1.2)), [[0, 0, 0]], [1.0, 0, 0])
    stance = flat_feet(z=0.3, corners=RUNG_CORNERS_M).with_hold(rail)
    coarse = support_region(stance, MASS_KG, config=StabilityConfig(max_lps=6))
    fine = support_region(stance, MASS_KG, config=StabilityConfig(area_rel_tol=0.0,
                                                                  area_tol_m2=1e-6))
    assert coarse.lp_count <= 7 and coarse.area_m2 <= fine.area_m2 + 1e-9
    assert np.all(fine.margin(coarse.vertices) >= -1e-6)  # inner stays inside


def test_support_region_is_a_region_class():
    assert isinstance(support_region(flat_feet(), MASS_KG), SupportRegion)
    assert issubclass(StabilityError, HuboLadderError)


# --------------------------------------------------------------------------------------
# Torque LP


@pytest.fixture(scope="module")
def hubo():
    model = pin.buildModelFromXML(robot_urdf("drc-hubo"), pin.JointModelFreeFlyer())
    return model, model.createData(), torque_limits_by_joint("drc-hubo")


def standing_q(model) -> np.ndarray:
    q = pin.neutral(model)
    q[2] = 0.968  # soles on the floor (z = 0) in the zero pose
    return q


def set_joint(model, q, name, value) -> np.ndarray:
    q = q.copy()
    q[model.joints[model.getJointId(name)].idx_q] = value
    return q


def frame_pose(model, data, q, frame) -> np.ndarray:
    pin.framesForwardKinematics(model, data, q)
    return data.oMf[model.getFrameId(frame)].homogeneous.copy()


def robot_feet(model, data, q) -> Stance:
    return Stance(tuple(
        hold(limb, frame_pose(model, data, q, frame), SOLE_CORNERS_M, [0, 0, 1.0], target="floor")
        for limb, frame in (("left_foot", "L_sole"), ("right_foot", "R_sole"))))


def rnea_residual(model, data, q, stance, check):
    """Inverse dynamics with the LP's contact forces as external forces (independent)."""
    fext = [pin.Force.Zero() for _ in range(model.njoints)]
    pin.framesForwardKinematics(model, data, q)
    for h in stance.holds:
        fid = model.getFrameId(h.frame)
        T_frame_world = np.linalg.inv(h.T_world_frame)
        local = h.points_m @ T_frame_world[:3, :3].T + T_frame_world[:3, 3]
        world = local @ data.oMf[fid].rotation.T + data.oMf[fid].translation
        j = model.frames[fid].parentJoint
        for p, f in zip(world, check.forces_n[h.limb], strict=True):
            fext[j] += data.oMi[j].actInv(pin.Force(f, np.cross(p, f)))
    zero = np.zeros(model.nv)
    tau = pin.rnea(model, data, q, zero, zero, fext)
    return tau


def test_standing_zero_pose_is_feasible_with_small_ratio(hubo):
    model, data, lim = hubo
    q = standing_q(model)
    feet = robot_feet(model, data, q)
    check = torque_feasibility(model, data, q, feet, lim)
    assert check.feasible and check.equilibrium
    assert 0 <= check.max_ratio < 0.1
    total = sum(f.sum(axis=0) for f in check.forces_n.values())
    np.testing.assert_allclose(total, [0, 0, pin.computeTotalMass(model) * 9.81], atol=1e-5)
    tau = rnea_residual(model, data, q, feet, check)
    np.testing.assert_allclose(tau[:6], 0.0, atol=1e-6)
    v_idx = [model.joints[model.getJointId(n)].idx_v for n in check.joint_names]
    np.testing.assert_allclose(tau[v_idx], check.torques_nm, atol=1e-6)
    assert "feasible" in repr(check) and check.worst_joint in repr(check)


def test_arm_extended_hand_on_rail_ratio_matches_inverse_dynamics(hubo):
    model, data, lim = hubo
    q = set_joint(model, standing_q(model), "RSP", -math.pi / 2)  # right arm forward
    T_palm = frame_pose(model, data, q, "R_palm")
    assert T_palm[0, 3] > 0.6  # the arm points forward
    # A hand hold: push up on the rail and pull the hand towards the ladder (+x).
    rail = Hold("right_hand", "rail", T_palm, np.tile(T_palm[:3, 3], (2, 1)),
                np.array([[0, 0, 1.0], [1.0, 0, 0]]), 0.4)
    stance = robot_feet(model, data, q).with_hold(rail)
    check = torque_feasibility(model, data, q, stance, lim)
    assert check.equilibrium and math.isfinite(check.max_ratio) and check.max_ratio > 0
    tau = rnea_residual(model, data, q, stance, check)
    np.testing.assert_allclose(tau[:6], 0.0, atol=1e-6)
    v_idx = [model.joints[model.getJointId(n)].idx_v for n in check.joint_names]
    np.testing.assert_allclose(tau[v_idx], check.torques_nm, atol=1e-6)
    ratios = np.abs(check.torques_nm) / [lim[n] for n in check.joint_names]
    assert check.max_ratio == pytest.approx(ratios.max())
    assert check.worst_joint == check.joint_names[int(np.argmax(ratios))]


def test_all_weight_on_one_foot_with_com_beside_it_has_no_equilibrium(hubo):
    model, data, lim = hubo
    q = standing_q(model)
    one_foot = robot_feet(model, data, q).without("right_foot")
    check = torque_feasibility(model, data, q, one_foot, lim)
    assert not check.feasible and not check.equilibrium and check.max_ratio == math.inf
    assert "no contact forces" in repr(check)
    region = support_region(one_foot, MASS_KG)
    report = check_stability(model, data, q, one_foot, region, lim)
    assert report.margin_m < 0 and report.torque is None and not report.stable


def test_hanging_from_one_wrist_is_torque_infeasible(hubo):
    model, data, lim = hubo
    q = set_joint(model, standing_q(model), "RSP", -math.pi / 2)  # arm horizontal
    T_palm = frame_pose(model, data, q, "R_palm")
    pts, nrm = grasp_points()
    grasp = Stance((hold("right_hand", T_palm, pts, nrm, target="rail"),))
    region = support_region(grasp, MASS_KG)
    report = check_stability(model, data, q, grasp, region, lim)
    assert report.margin_m > 0  # the grasp can hold any CoM: the CoM test passes ...
    check = report.torque
    assert check is not None and check.equilibrium and not check.feasible  # ... torques not
    assert check.max_ratio > 5
    assert check.worst_joint in RIGHT_ARM
    assert not report.stable and "UNSTABLE" in repr(report)
    weight = pin.computeTotalMass(model) * 9.81
    np.testing.assert_allclose(check.forces_n["right_hand"].sum(axis=0), [0, 0, weight],
                               atol=1e-5)


def test_check_stability_standing_is_stable(hubo):
    model, data, lim = hubo
    q = standing_q(model)
    feet = robot_feet(model, data, q)
    report = check_stability(model, data, q, feet, support_region(feet, MASS_KG), lim,
                             min_margin_m=0.02)
    assert report.stable and report.margin_m > 0.1
    assert "stable" in repr(report)


def test_torque_limits_must_cover_every_joint(hubo):
    model, data, lim = hubo
    q = standing_q(model)
    partial = {k: v for k, v in lim.items() if k != "LKN"}
    with pytest.raises(HuboLadderError, match="LKN"):
        torque_feasibility(model, data, q, robot_feet(model, data, q), partial)
