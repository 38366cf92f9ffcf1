"""Collision checking with coal on the robot's primitive geometry and the ladder.

The robot's capsules and boxes come from the kinematic tree (the same primitives the
MuJoCo model uses). Self pairs are every pair of solid bodies not adjacent in the tree
(motor links without geometry do not count) that do not already touch in the zero pose
(the SRDF rule). Environment pairs are every robot geometry against the floor and each
ladder part; a limb's end links are allowed to touch what that limb holds.
"""

from __future__ import annotations

from dataclasses import dataclass

import coal
import numpy as np
import pinocchio as pin

from planner.configuration.kinematics import HuboKinematics
from robot.kinematic_tree import Geom, KinematicTree, build_tree

#: Links of each limb that touch its hold (sole plate; palm and fingers).
LIMB_END_LINKS = {
    "left_foot": ("L_foot",), "right_foot": ("R_foot",),
    "left_hand": ("L_hand",) + tuple(f"L_finger{i}" for i in range(1, 6)),
    "right_hand": ("R_hand",) + tuple(f"R_finger{i}" for i in range(1, 6)),
}
#: Name of the floor in the environment (a half-space at z = 0).
FLOOR = "floor"
#: Links that `CollisionModel`'s ``leg_clearance_m`` keeps off the ladder.
LEG_LINKS = ("L_thigh", "L_shin", "R_thigh", "R_shin")
#: Links that `CollisionModel`'s ``arm_clearance_m`` keeps off the ladder (the hands and
#: fingers touch the rails they hold).
ARM_LINKS = ("L_upper_arm", "L_forearm", "R_upper_arm", "R_forearm")


def _shape(g: Geom) -> tuple[coal.CollisionGeometry, np.ndarray]:
    if g.kind == "capsule":
        p0, p1 = np.asarray(g.p0), np.asarray(g.p1)
        length = float(np.linalg.norm(p1 - p0))
        return coal.Capsule(g.radius, length), (p0 + p1) / 2  # coal takes the full length
    if g.kind == "box":
        return coal.Box(*(2 * np.asarray(g.half))), np.asarray(g.p0)
    return coal.Sphere(g.radius), np.asarray(g.p0)


def _tree_distance(tree: KinematicTree, a: str, b: str) -> int:
    """Bodies between two links along the tree, not counting links without geometry
    (the small motor links between co-located hip, shoulder, elbow and wrist joints):
    the thigh is then adjacent to the pelvis, the upper arm to the torso."""
    by_name = {lk.name: lk for lk in tree.links}

    def chain(x: str) -> list[str]:
        out = [x]
        while by_name[out[-1]].parent is not None:
            out.append(by_name[out[-1]].parent)
        return out

    ca, cb = chain(a), chain(b)
    common = next(x for x in ca if x in cb)
    between = ca[1:ca.index(common) + 1] + cb[1:cb.index(common)]

    def solid(x: str) -> bool:
        return bool(by_name[x].geoms)

    hops = sum(1 for x in between if solid(x)) + 1
    return hops - (0 if solid(common) or common in (a, b) else 1)


@dataclass
class CollisionReport:
    in_collision: bool
    min_distance_m: float
    closest_pair: tuple[str, str]

    def __repr__(self) -> str:
        state = "COLLISION" if self.in_collision else "clear"
        return (f"CollisionReport({state}, min distance {self.min_distance_m * 100:.1f} cm "
                f"between {self.closest_pair[0]} and {self.closest_pair[1]})")


class CollisionModel:
    """Robot + environment geometry, with pairs switched on and off per stance."""

    def __init__(self, kin: HuboKinematics,
                 environment: list[tuple[str, coal.CollisionGeometry, coal.Transform3s]],
                 leg_clearance_m: float = 0.0, arm_clearance_m: float = 0.0):
        """``leg_clearance_m``, ``arm_clearance_m``: thighs and shins, upper arms and
        forearms count as colliding with the ladder when closer than this [m]
        (`in_collision`; `report` gives the true distance)."""
        self.kin = kin
        tree = build_tree(kin.params)
        model = kin.model
        geom = pin.GeometryModel()
        self.robot_link_of: list[str] = []
        for lk in tree.links:
            fid = model.getFrameId(lk.name)
            frame = model.frames[fid]
            for i, g in enumerate(lk.geoms):
                shape, centre = _shape(g)
                placement = frame.placement * pin.SE3(np.eye(3), centre)
                obj = pin.GeometryObject(f"{lk.name}/{i}", frame.parentJoint, fid, placement,
                                         shape)
                geom.addGeometryObject(obj)
                self.robot_link_of.append(lk.name)
        self.n_robot = len(self.robot_link_of)
        self.env_names: list[str] = []
        for name, shape, tf in [(FLOOR, coal.Halfspace(np.array([0, 0, 1.0]), 0.0),
                                 coal.Transform3s())] + list(environment):
            placement = pin.SE3(tf.getRotation(), tf.getTranslation())
            geom.addGeometryObject(pin.GeometryObject(name, 0, 0, placement, shape))
            self.env_names.append(name)
        self.geom = geom
        # Self pairs: links ≥ 3 joints apart and apart in the zero pose.
        self.self_pairs: list[tuple[int, int]] = []
        self.env_pairs: dict[tuple[str, str], int] = {}  # (robot link, env name) → pair idx
        q0 = pin.neutral(model)
        candidates = []
        for i in range(self.n_robot):
            for j in range(i + 1, self.n_robot):
                la, lb = self.robot_link_of[i], self.robot_link_of[j]
                if la != lb and _tree_distance(tree, la, lb) >= 2:
                    candidates.append((i, j))
        for i, j in candidates:
            geom.addCollisionPair(pin.CollisionPair(i, j))
        gdata = pin.GeometryData(geom)
        pin.computeCollisions(model, kin.data, geom, gdata, q0, False)
        keep = [k for k, _ in enumerate(candidates) if not gdata.collisionResults[k].isCollision()]
        geom.removeAllCollisionPairs()
        for k in keep:
            geom.addCollisionPair(pin.CollisionPair(*candidates[k]))
            self.self_pairs.append(candidates[k])
        self.env_pair_index: list[tuple[str, str]] = []
        for i in range(self.n_robot):
            for e, name in enumerate(self.env_names):
                geom.addCollisionPair(pin.CollisionPair(i, self.n_robot + e))
                self.env_pair_index.append((self.robot_link_of[i], name))
        self.n_self_pairs = len(self.self_pairs)
        self.gdata = pin.GeometryData(geom)
        self._leg_pairs = self._ladder_pairs(LEG_LINKS)
        self.leg_clearance_m = -1.0
        self.set_leg_clearance(leg_clearance_m)
        self.arm_clearance_m = arm_clearance_m
        self._set_margin(self._ladder_pairs(ARM_LINKS), arm_clearance_m)
        self._allowed: frozenset[tuple[str, str]] = frozenset()

    def _ladder_pairs(self, links: tuple[str, ...]) -> list[int]:
        """Indices of the pairs of ``links`` against the ladder's parts (not the floor)."""
        return [self.n_self_pairs + k for k, (link, env) in enumerate(self.env_pair_index)
                if link in links and env != FLOOR]

    def _set_margin(self, pairs: list[int], clearance_m: float) -> None:
        """``pairs`` count as colliding when closer than ``clearance_m`` [m]."""
        for idx in pairs:
            self.gdata.collisionRequests[idx].security_margin = clearance_m

    def set_leg_clearance(self, clearance_m: float) -> None:
        """Keep thighs and shins ``clearance_m`` off the ladder from now on [m]."""
        if clearance_m == self.leg_clearance_m:
            return
        self.leg_clearance_m = clearance_m
        self._set_margin(self._leg_pairs, clearance_m)

    def allow(self, contacts: dict[str, str]) -> None:
        """Let each limb's end links touch the object it holds: ``{limb: env name}``."""
        allowed = {(link, target) for limb, target in contacts.items()
                   for link in LIMB_END_LINKS[limb]}
        if allowed == self._allowed:
            return
        self._allowed = frozenset(allowed)
        for k, pair in enumerate(self.env_pair_index):
            idx = self.n_self_pairs + k
            if pair in allowed:
                self.gdata.deactivateCollisionPair(idx)
            else:
                self.gdata.activateCollisionPair(idx)

    def in_collision(self, q: np.ndarray) -> bool:
        return bool(pin.computeCollisions(self.kin.model, self.kin.data, self.geom, self.gdata,
                                          q, True))

    def report(self, q: np.ndarray) -> CollisionReport:
        """Collision flag and the smallest distance over the active pairs [m]."""
        # coal's distances over every active pair, in pinocchio's C++ loop: it returns
        # the pair with the smallest distance (5× faster than a Python loop over pairs).
        k = pin.computeDistances(self.kin.model, self.kin.data, self.geom, self.gdata, q)
        if k >= len(self.geom.collisionPairs):  # no active pair
            return CollisionReport(False, np.inf, ("", ""))
        best = float(self.gdata.distanceResults[k].min_distance)
        cp = self.geom.collisionPairs[k]
        pair = (self.geom.geometryObjects[cp.first].name, self.geom.geometryObjects[cp.second].name)
        return CollisionReport(best <= 0.0, best, pair)

    def colliding_pairs(self, q: np.ndarray) -> list[tuple[str, str]]:
        pin.computeCollisions(self.kin.model, self.kin.data, self.geom, self.gdata, q, False)
        out = []
        # Results first: reading a pair's flags through the bindings costs microseconds, and
        # a few of the ~700 pairs collide. An inactive pair keeps a stale result.
        for k, result in enumerate(self.gdata.collisionResults):
            if result.isCollision() and self.gdata.activeCollisionPairs[k]:
                cp = self.geom.collisionPairs[k]
                out.append((self.geom.geometryObjects[cp.first].name,
                            self.geom.geometryObjects[cp.second].name))
        return out
