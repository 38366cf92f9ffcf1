"""The planner's collision geometry is the robot's: coal and the MuJoCo scene agree."""

from types import SimpleNamespace

import mujoco
import numpy as np
import pinocchio as pin
import pytest

from ladders.collision import ladder_collision_objects
from ladders.loader import load_ladder
from ladders.scene import build_scene
from planner.configuration.collision import ARM_LINKS, LEG_LINKS, CollisionModel
from robot.mjcf import ROBOT_CONTYPE, joint_qpos_addresses
from robot.params import robot_params
from robot.urdf import robot_urdf


def test_planner_and_simulator_measure_the_same_distances_to_the_rungs():
    """Over random poses in front of the DRC ladder, each robot body's distance to each
    rung is the same in the planner's coal model and in the MuJoCo scene (a capsule of
    the wrong length in either would show as centimetres)."""
    spec = load_ladder("drc")
    params = robot_params("drc-hubo")
    model = pin.buildModelFromXML(robot_urdf(params), pin.JointModelFreeFlyer())
    data = model.createData()
    planner = CollisionModel(SimpleNamespace(model=model, data=data, params=params),
                             ladder_collision_objects(spec))
    mj = build_scene(spec, params).compile()
    mjd = mujoco.MjData(mj)
    qadr = joint_qpos_addresses(mj)
    rungs = [f"rung_{k}" for k in range(3)]
    rung_geoms = {r: mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_GEOM, r) for r in rungs}
    body_geoms: dict[str, list[int]] = {}
    for g in range(mj.ngeom):
        if mj.geom_contype[g] == ROBOT_CONTYPE:
            body_geoms.setdefault(mj.body(mj.geom_bodyid[g]).name, []).append(g)
    rng = np.random.default_rng(3)
    compared = 0
    for _ in range(15):
        q = pin.randomConfiguration(model)
        q[:3] = (rng.uniform(0.0, 0.25), rng.uniform(-0.1, 0.1), rng.uniform(0.8, 1.2))
        q[3:7] = (0.0, 0.0, 0.0, 1.0)
        pin.computeDistances(model, data, planner.geom, planner.gdata, q)
        coal_m: dict[tuple[str, str], float] = {}
        for k, cp in enumerate(planner.geom.collisionPairs):
            a = planner.geom.geometryObjects[cp.first].name
            b = planner.geom.geometryObjects[cp.second].name
            if b in rungs:
                key = (a.split("/")[0], b)
                coal_m[key] = min(coal_m.get(key, np.inf),
                                  planner.gdata.distanceResults[k].min_distance)
        mjd.qpos[:3] = q[:3]
        mjd.qpos[3:7] = (1.0, 0.0, 0.0, 0.0)
        for j in range(2, model.njoints):
            mjd.qpos[qadr[model.names[j]]] = q[model.joints[j].idx_q]
        mujoco.mj_kinematics(mj, mjd)
        for (body, rung), d_coal in coal_m.items():
            if d_coal > 0.3:
                continue
            d_mj = min(mujoco.mj_geomDistance(mj, mjd, g, rung_geoms[rung], 0.5, None)
                       for g in body_geoms[body])
            if d_coal <= 0.0:  # in contact: both say so (penetration depths differ)
                assert d_mj <= 1e-4, (body, rung, d_mj, d_coal)
            else:
                assert abs(d_mj - d_coal) < 1e-4, (body, rung, d_mj, d_coal)
            compared += 1
    assert compared > 50


def _model_with_box_near(link: str, gap_m: float, leg_clearance_m: float,
                         arm_clearance_m: float = 0.0):
    """A CollisionModel whose only obstacle is a small box ``gap_m`` in front (+x) of
    ``link``'s capsule in the zero pose lifted off the floor, and that pose."""
    import coal

    params = robot_params("drc-hubo")
    model = pin.buildModelFromXML(robot_urdf(params), pin.JointModelFreeFlyer())
    data = model.createData()
    robot = SimpleNamespace(model=model, data=data, params=params)
    q = pin.neutral(model)
    q[2] = 1.2  # feet off the floor
    probe = CollisionModel(robot, [])
    pin.updateGeometryPlacements(model, data, probe.geom, probe.gdata, q)
    k = next(i for i, g in enumerate(probe.geom.geometryObjects) if g.name == f"{link}/0")
    shape, pose = probe.geom.geometryObjects[k].geometry, probe.gdata.oMg[k]
    reach_x = (shape.radius if isinstance(shape, coal.Capsule)  # a box: its extent along x
               else float(np.abs(pose.rotation[0]) @ shape.halfSide))
    front_m = pose.translation + (reach_x, 0.0, 0.0)
    half = 0.02
    box = coal.Box(2 * half, 2 * half, 2 * half)
    tf = coal.Transform3s(np.eye(3), front_m + (gap_m + half, 0.0, 0.0))
    return CollisionModel(robot, [("box", box, tf)], leg_clearance_m, arm_clearance_m), q


@pytest.mark.parametrize("clearance", ["legs", "arms"])
def test_legs_and_arms_keep_their_own_clearance_and_other_links_do_not(clearance):
    """A link 0.5 cm from the ladder collides under a 1 cm clearance of its own group
    only: the legs' applies to thighs and shins, the arms' to upper arms and forearms;
    other links (the torso here) keep none."""
    legs_m, arms_m = (0.01, 0.0) if clearance == "legs" else (0.0, 0.01)
    for link in ("L_shin", "L_thigh", "R_upper_arm", "L_forearm", "torso"):
        margin_applies = link in (LEG_LINKS if clearance == "legs" else ARM_LINKS)
        without, q = _model_with_box_near(link, 0.005, 0.0)
        with_clearance, _ = _model_with_box_near(link, 0.005, legs_m, arms_m)
        assert not without.in_collision(q)
        assert with_clearance.in_collision(q) is margin_applies, link
        # the report stays the true distance
        assert with_clearance.report(q).min_distance_m == without.report(q).min_distance_m
        assert 0.004 < without.report(q).min_distance_m < 0.006


def test_the_leg_clearance_can_be_relaxed_and_restored():
    """The search relaxes the legs' clearance for a step that found nothing with it
    (`PlannerConfig.leg_clearance_samples`): a shin 1.5 cm from the box collides at
    2.5 cm, not at 1 cm, and again at 2.5 cm."""
    model, q = _model_with_box_near("L_shin", 0.015, 0.025)
    assert model.in_collision(q)
    model.set_leg_clearance(0.01)
    assert not model.in_collision(q) and model.leg_clearance_m == 0.01
    model.set_leg_clearance(0.025)
    assert model.in_collision(q)
