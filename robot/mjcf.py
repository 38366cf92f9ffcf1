"""MuJoCo model of a Hubo (mjSpec), written from the same kinematic tree as the URDF.

Conventions follow mujoco_menagerie: radians, ``visual``/``collision`` default classes,
position actuators saturating at each joint's torque limit, palm/sole/IMU sites and a
``home`` keyframe (standing, zero joint angles).
"""

from __future__ import annotations

import math

import mujoco
import numpy as np

from robot.joints import JOINT_NAMES
from robot.kinematic_tree import ROOT_LINK, Geom, KinematicTree, build_tree
from robot.params import RobotParams, robot_params

PHYSICS_DT_S = 0.002
#: Position-mode stiffness: the torque limit is reached at this tracking error [rad].
POSITION_SATURATION_ERROR_RAD = 0.02

#: Contact bit masks: the robot touches the environment but not itself (the planner
#: checks self-collision on the same primitives with coal).
ROBOT_CONTYPE, ROBOT_CONAFFINITY = 1, 2
ENV_CONTYPE, ENV_CONAFFINITY = 2, 1


def position_gains(effort_nm: float, armature_kg_m2: float) -> tuple[float, float]:
    """(kp [N·m/rad], kv [N·m·s/rad]) of the simulated board's position loop.

    kp saturates the torque at ``POSITION_SATURATION_ERROR_RAD``; kv critically damps the
    reflected rotor inertia, the dominant inertia of a geared joint.
    """
    kp = effort_nm / POSITION_SATURATION_ERROR_RAD
    kv = 2.0 * math.sqrt(kp * max(armature_kg_m2, 1e-4))
    return kp, kv


def _add_geom(body, g: Geom, classname, rgba) -> None:
    if g.kind == "capsule":
        geom = body.add_geom(type=mujoco.mjtGeom.mjGEOM_CAPSULE,
                             fromto=[*g.p0, *g.p1], size=[g.radius, 0, 0])
    elif g.kind == "box":
        geom = body.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, pos=list(g.p0), size=list(g.half))
    else:
        geom = body.add_geom(type=mujoco.mjtGeom.mjGEOM_SPHERE, pos=list(g.p0),
                             size=[g.radius, 0, 0])
    # mjSpec applies a class's values at creation only; set the contact bits explicitly.
    geom.classname = classname
    geom.contype, geom.conaffinity, geom.group = ROBOT_CONTYPE, ROBOT_CONAFFINITY, 3
    geom.friction = [1.0, 0.005, 0.0001]
    geom.rgba = rgba


def new_spec(timestep_s: float = PHYSICS_DT_S) -> mujoco.MjSpec:
    """An empty spec with this project's physics options and default classes."""
    spec = mujoco.MjSpec()
    spec.compiler.degree = False
    spec.compiler.autolimits = True
    spec.option.timestep = timestep_s
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    # Elliptic cones and a high impratio keep friction grasps and footholds from creeping.
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    spec.option.impratio = 10.0
    visual = spec.add_default("visual", spec.default)
    visual.geom.contype = 0
    visual.geom.conaffinity = 0
    visual.geom.group = 2
    collision = spec.add_default("collision", spec.default)
    collision.geom.contype = ROBOT_CONTYPE
    collision.geom.conaffinity = ROBOT_CONAFFINITY
    collision.geom.group = 3
    collision.geom.friction = [1.0, 0.005, 0.0001]
    env = spec.add_default("environment", spec.default)
    env.geom.contype = ENV_CONTYPE
    env.geom.conaffinity = ENV_CONAFFINITY
    return spec


def add_robot(spec: mujoco.MjSpec, tree: KinematicTree, base_pos_m=(0.0, 0.0, None),
              base_yaw_rad: float = 0.0, prefix: str = "") -> None:
    """Add the robot (floating base named ``pelvis``), its actuators, sites and ``home`` key.

    ``base_pos_m[2] = None`` puts the soles on the floor in the zero pose.
    """
    p = robot_params(tree.robot)
    z = p.pelvis_height_m if base_pos_m[2] is None else base_pos_m[2]
    base = [float(base_pos_m[0]), float(base_pos_m[1]), float(z)]
    quat = [math.cos(base_yaw_rad / 2), 0.0, 0.0, math.sin(base_yaw_rad / 2)]
    bodies = {}
    collision_rgba = [0.55, 0.6, 0.7, 1.0]
    for lk in tree.links:
        parent = spec.worldbody if lk.parent is None else bodies[lk.parent]
        pos = base if lk.parent is None else list(lk.origin_m)
        body = parent.add_body(name=prefix + lk.name, pos=pos)
        if lk.parent is None:
            body.quat = quat
            body.add_freejoint(name=prefix + "root")
        body.mass = max(lk.mass_kg, 1e-4)
        body.ipos = list(lk.com_m)
        body.inertia = [max(i, 1e-6) for i in lk.inertia_kg_m2]
        body.explicitinertial = True
        if lk.joint is not None:
            body.add_joint(name=prefix + lk.joint, type=mujoco.mjtJoint.mjJNT_HINGE,
                           axis=list(lk.axis), range=[lk.lower_rad, lk.upper_rad],
                           armature=lk.armature_kg_m2,
                           actfrcrange=[-lk.effort_nm, lk.effort_nm])
        for g in lk.geoms:
            _add_geom(body, g, spec.find_default("collision"), collision_rgba)
        bodies[lk.name] = body
    for f in tree.frames:
        bodies[f.link].add_site(name=prefix + f.name, pos=list(f.offset_m), size=[0.01, 0, 0])
    links_by_joint = tree.joint_links
    for name in JOINT_NAMES:
        lk = links_by_joint.get(name)
        if lk is None:
            continue
        kp, kv = position_gains(lk.effort_nm, lk.armature_kg_m2)
        act = spec.add_actuator(name=prefix + name, target=prefix + name,
                                trntype=mujoco.mjtTrn.mjTRN_JOINT)
        act.set_to_position(kp=kp, kv=kv)
        act.forcelimited = True
        act.forcerange = [-lk.effort_nm, lk.effort_nm]
    njoints = sum(1 for lk in tree.links if lk.joint is not None)
    spec.add_key(name="home", qpos=base + quat + [0.0] * njoints, ctrl=[0.0] * njoints)


def add_floor(spec: mujoco.MjSpec, friction: float = 1.0) -> None:
    floor = spec.worldbody.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE,
                                    size=[10, 10, 0.1], rgba=[0.8, 0.8, 0.75, 1])
    floor.classname = spec.find_default("environment")
    floor.contype, floor.conaffinity = ENV_CONTYPE, ENV_CONAFFINITY
    floor.friction = [friction, 0.005, 0.0001]
    spec.worldbody.add_light(pos=[0, -2, 4], dir=[0, 0.5, -1])


def robot_spec(robot: str | RobotParams = "drc-hubo", *, with_floor: bool = True) -> mujoco.MjSpec:
    """A standalone scene: the robot standing on a floor."""
    p = robot_params(robot) if isinstance(robot, str) else robot
    spec = new_spec()
    spec.modelname = p.name
    if with_floor:
        add_floor(spec)
    add_robot(spec, build_tree(p))
    return spec


def actuated_columns(model: mujoco.MjModel) -> np.ndarray:
    """For each actuator of ``model``, its column in the 40-column file (``-1`` if none)."""
    index = {n: i for i, n in enumerate(JOINT_NAMES)}
    return np.array([index.get(model.actuator(i).name, -1) for i in range(model.nu)])


def joint_qpos_addresses(model: mujoco.MjModel) -> dict[str, int]:
    """qpos address of every hinge named like a trajectory column."""
    out = {}
    for name in JOINT_NAMES:
        jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
        if jid >= 0:
            out[name] = int(model.jnt_qposadr[jid])
    return out


__all__ = ["ROOT_LINK", "actuated_columns", "add_floor", "add_robot", "joint_qpos_addresses",
           "new_spec", "position_gains", "robot_spec"]
