"""The kinematic tree of a Hubo, built from its parameter table.

Every link frame is parallel to the world frame in the zero pose (arms hanging, legs
straight), so a joint is fully described by its parent, its origin offset and its axis.
URDF, MJCF and the planner's collision model are all written from this one tree.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from robot.joints import JOINT_NAMES
from robot.params import RobotParams

Vec3 = tuple[float, float, float]


@dataclass(frozen=True)
class Geom:
    """A primitive collision/visual shape in its link frame.

    ``capsule``: segment ``p0``–``p1`` with ``radius``; ``box``: centre ``p0`` and
    half extents ``half``; ``sphere``: centre ``p0`` and ``radius``.
    """

    kind: str
    p0: Vec3
    p1: Vec3 = (0.0, 0.0, 0.0)
    radius: float = 0.0
    half: Vec3 = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Link:
    """A rigid body and the joint that connects it to its parent."""

    name: str
    parent: str | None
    joint: str | None  # joint name (one of JOINT_NAMES) or None for the root
    axis: Vec3
    origin_m: Vec3  # joint origin in the parent link frame
    mass_kg: float
    com_m: Vec3
    inertia_kg_m2: Vec3  # principal moments about the CoM, axes parallel to the link frame
    geoms: tuple[Geom, ...]
    lower_rad: float = 0.0
    upper_rad: float = 0.0
    effort_nm: float = 0.0
    velocity_rad_s: float = 0.0
    armature_kg_m2: float = 0.0


@dataclass(frozen=True)
class Frame:
    """A named operational frame (palm, sole, IMU...) fixed to a link."""

    name: str
    link: str
    offset_m: Vec3


@dataclass(frozen=True)
class KinematicTree:
    robot: str
    links: tuple[Link, ...]
    frames: tuple[Frame, ...]
    sole_corners_m: tuple[Vec3, ...]  # in the sole frame, for both feet

    def link(self, name: str) -> Link:
        for lk in self.links:
            if lk.name == name:
                return lk
        raise KeyError(name)

    @property
    def joint_links(self) -> dict[str, Link]:
        return {lk.joint: lk for lk in self.links if lk.joint is not None}


ROOT_LINK = "pelvis"


def _capsule_inertia(mass: float, length: float, radius: float) -> Vec3:
    """Principal moments of a solid cylinder of the capsule's size along z."""
    ixx = mass * (3 * radius**2 + length**2) / 12.0
    izz = mass * radius**2 / 2.0
    return (ixx, ixx, izz)


def _box_inertia(mass: float, half: Vec3) -> Vec3:
    a, b, c = (2 * h for h in half)
    return (mass * (b * b + c * c) / 12, mass * (a * a + c * c) / 12, mass * (a * a + b * b) / 12)


def _limb(name, parent, joint, axis, origin, mass, length, radius, p, *, extra_geoms=(),
          end_on_far_joint=False):
    """A link whose mass is a capsule hanging ``length`` below its joint (zero pose); with
    ``end_on_far_joint`` its collision capsule's far end sphere ends on the next joint
    (centred a radius short of it) instead of reaching a radius past it."""
    capsule_m = length - radius if end_on_far_joint else length
    geoms = ((Geom("capsule", (0, 0, 0), (0, 0, -capsule_m), radius),) if length > 0 else ())
    geoms += tuple(extra_geoms)
    com = (0.0, 0.0, -length / 2)
    inertia = _capsule_inertia(mass, max(length, 2 * radius), radius)
    lo, hi = _limits(p, joint)
    return Link(name, parent, joint, axis, origin, mass, com, inertia, geoms, lo, hi,
                _torque(p, joint), _speed_max(p, joint), _armature(p, joint))


def _limits(p: RobotParams, joint: str) -> tuple[float, float]:
    return p.position_limits_rad.get(joint, (-3.14, 3.14))


def _group(joint: str) -> str:
    if joint == "WST":
        return "waist"
    if joint.startswith("NK"):
        return "neck"
    suffix = joint[1:]
    if suffix.startswith("F"):
        return "finger"
    if suffix in ("WY", "WR", "WP"):
        return "wrist"
    if suffix in ("SP", "SR", "SY", "EB"):
        return "arm"
    return "leg"


def _torque(p: RobotParams, joint: str) -> float:
    if joint in p.torque_limits_nm:
        return p.torque_limits_nm[joint]
    suffix = joint[1:]
    if suffix.startswith("F"):
        return p.torque_limits_nm["F"]
    if joint.startswith("NK"):
        return p.torque_limits_nm["NK"]
    return p.torque_limits_nm[suffix]


def _speed_max(p: RobotParams, joint: str) -> float:
    group = _group(joint)
    key = {"waist": "arm", "neck": "arm", "wrist": "arm"}.get(group, group)
    return p.speed_max_rad_s[key]


def _armature(p: RobotParams, joint: str) -> float:
    return p.armature_kg_m2[_group(joint)]


def _leg(p: RobotParams, side: str) -> list[Link]:
    s = 1.0 if side == "L" else -1.0
    m = p.leg_masses_kg
    hip = (0.0, s * p.half_hip_width_m, -p.torso_to_hip_pitch_m)
    r_thigh, r_shin = 0.06, 0.05
    foot_half = (p.foot_length_m / 2, p.foot_width_m / 2, 0.02)
    foot_box = Geom("box", (0.0, 0.0, -p.ankle_to_sole_m + foot_half[2]), half=foot_half)
    # The ankle block ends on top of the foot plate, clear of the floor.
    ankle_r = 0.045
    ankle_block = Geom("capsule", (0, 0, 0), (0, 0, -p.ankle_to_sole_m + 0.04 + ankle_r), ankle_r)
    foot_mass = m["AR"] + m["foot"]
    foot_com = (0.0, 0.0, -p.ankle_to_sole_m / 2)
    lo, hi = _limits(p, f"{side}AR")
    return [
        _limb(f"{side}_hip_yaw", ROOT_LINK, f"{side}HY", (0, 0, 1), hip, m["HY"], 0.0, 0.05, p),
        _limb(f"{side}_hip_roll", f"{side}_hip_yaw", f"{side}HR", (1, 0, 0), (0, 0, 0), m["HR"],
              0.0, 0.05, p),
        _limb(f"{side}_thigh", f"{side}_hip_roll", f"{side}HP", (0, 1, 0), (0, 0, 0), m["HP"],
              p.thigh_m, r_thigh, p),
        _limb(f"{side}_shin", f"{side}_thigh", f"{side}KN", (0, 1, 0), (0, 0, -p.thigh_m),
              m["KN"], p.shin_m, r_shin, p),
        _limb(f"{side}_ankle_pitch", f"{side}_shin", f"{side}AP", (0, 1, 0), (0, 0, -p.shin_m),
              m["AP"], 0.0, 0.04, p),
        Link(f"{side}_foot", f"{side}_ankle_pitch", f"{side}AR", (1, 0, 0), (0, 0, 0),
             foot_mass, foot_com, _box_inertia(foot_mass, foot_half), (ankle_block, foot_box),
             lo, hi, _torque(p, f"{side}AR"), _speed_max(p, f"{side}AR"),
             _armature(p, f"{side}AR")),
    ]


#: Finger curl angle [rad] at which the hand is closed around a rail.
FINGER_CLOSED_RAD = 1.6
FINGER_LENGTH_M = 0.09
FINGER_RADIUS_M = 0.011
#: A finger joint sits this far beside the grip centre, on the palm plate's side [m] ...
FINGER_JOINT_OUTSET_M = 0.04
#: ... and this far above it, towards the wrist [m].
FINGER_JOINT_ABOVE_GRIP_M = 0.045


def finger_contact_curl_rad(rail_radius_m: float) -> float:
    """The curl [rad] at which a closing finger meets a rail whose axis lies at the grip
    centre: where the finger capsule's axis passes ``rail_radius_m + FINGER_RADIUS_M``
    from the rail axis.

    A finger hangs from its joint at ``(−outset, +above)`` (across the grip, along the
    palm) and curls towards the open side; at curl θ its axis runs along
    ``(sin θ, −cos θ)``, whose distance from the grip centre is
    ``outset·cos θ − above·sin θ``. A hand closed on a rail stops there, one closed on
    nothing reaches ``FINGER_CLOSED_RAD``: the finger encoders tell the two apart. A rail
    too thick to enter the open hand stops the fingers at 0.
    """
    a, b = FINGER_JOINT_OUTSET_M, FINGER_JOINT_ABOVE_GRIP_M
    ratio = (rail_radius_m + FINGER_RADIUS_M) / math.hypot(a, b)
    if ratio >= 1.0:
        return 0.0
    return max(0.0, math.acos(ratio) - math.atan2(b, a))


def _arm(p: RobotParams, side: str) -> tuple[list[Link], list[Frame]]:
    """Shoulder pitch-roll-yaw, elbow, wrist yaw, wrist pitch, wrist roll, hand, fingers."""
    s = 1.0 if side == "L" else -1.0
    m = p.arm_masses_kg
    shoulder = (0.0, s * p.half_shoulder_width_m, p.shoulder_above_torso_m)
    wr_joint = f"{side}WR" if p.has_wrist_roll else None
    hand_half = (0.045, 0.02, 0.045)
    palm_z = -p.wrist_to_palm_m
    # The grip centre (palm frame) is where a grasped rail's axis lies; the palm plate sits
    # on the outer side of it, the fingers start above it and curl over it.
    # The rail enters the hand from its open side, +s·y; plate and open fingers clear a
    # 25 mm-radius rail at the grip centre by 5 mm.
    palm_plate = Geom("box", (0.0, -s * 0.05, palm_z + 0.01), half=hand_half)
    finger_mass = m["hand"] * 0.3 / 5
    palm_mass = m["WR"] + m["hand"] * 0.7
    links = [
        _limb(f"{side}_shoulder_pitch", "torso", f"{side}SP", (0, 1, 0), shoulder, m["SP"], 0.0,
              0.05, p),
        _limb(f"{side}_shoulder_roll", f"{side}_shoulder_pitch", f"{side}SR", (1, 0, 0),
              (0, 0, 0), m["SR"], 0.0, 0.05, p),
        _limb(f"{side}_upper_arm", f"{side}_shoulder_roll", f"{side}SY", (0, 0, 1), (0, 0, 0),
              m["SY"], p.upper_arm_m, 0.045, p),
        _limb(f"{side}_elbow", f"{side}_upper_arm", f"{side}EB", (0, 1, 0),
              (0, 0, -p.upper_arm_m), m["EB"], 0.0, 0.04, p),
        # The forearm's end sphere would otherwise reach 4 cm into the hand, where a short
        # hand's closed fingers lie.
        _limb(f"{side}_forearm", f"{side}_elbow", f"{side}WY", (0, 0, 1), (0, 0, 0), m["WY"],
              p.forearm_m, 0.04, p, end_on_far_joint=True),
        _limb(f"{side}_wrist_pitch", f"{side}_forearm", f"{side}WP", (0, 1, 0),
              (0, 0, -p.forearm_m), m["WP"], 0.0, 0.035, p),
    ]
    lo, hi = _limits(p, f"{side}WR")
    links.append(
        Link(f"{side}_hand", f"{side}_wrist_pitch", wr_joint, (0, 0, 1), (0, 0, 0), palm_mass,
             (0.0, -s * 0.04, palm_z + 0.01), _box_inertia(palm_mass, hand_half), (palm_plate,),
             lo, hi, _torque(p, f"{side}WR"), _speed_max(p, f"{side}WR"),
             _armature(p, f"{side}WR"))
    )
    # Five fingers spaced along the grip axis (x), each curling about ±x across the grip
    # centre towards the open side, so positive curl closes both hands.
    for i in range(5):
        x = -0.036 + 0.018 * i
        joint = f"{side}F{i + 1}"
        links.append(
            _limb(f"{side}_finger{i + 1}", f"{side}_hand", joint, (s, 0, 0),
                  (x, -s * FINGER_JOINT_OUTSET_M, palm_z + FINGER_JOINT_ABOVE_GRIP_M),
                  finger_mass, FINGER_LENGTH_M,
                  FINGER_RADIUS_M, p)
        )
    frames = [Frame(f"{side}_palm", f"{side}_hand", (0.0, 0.0, palm_z))]
    return links, frames


def build_tree(p: RobotParams) -> KinematicTree:
    """The full tree of robot ``p``: pelvis (floating root), legs, waist, torso, arms, head."""
    pelvis_half = (0.08, 0.12, 0.06)
    torso_half = (0.10, 0.16, 0.14)
    links: list[Link] = [
        Link(ROOT_LINK, None, None, (0, 0, 0), (0, 0, 0), p.mass_pelvis_kg, (0, 0, -0.06),
             _box_inertia(p.mass_pelvis_kg, pelvis_half),
             (Geom("box", (0, 0, -0.06), half=pelvis_half),)),
    ]
    links += _leg(p, "R") + _leg(p, "L")
    lo, hi = _limits(p, "WST")
    links.append(
        Link("torso", ROOT_LINK, "WST", (0, 0, 1), (0, 0, 0), p.mass_torso_kg, (-0.02, 0, 0.14),
             _box_inertia(p.mass_torso_kg, torso_half),
             (Geom("box", (-0.02, 0, 0.14), half=torso_half),), lo, hi, _torque(p, "WST"),
             _speed_max(p, "WST"), _armature(p, "WST"))
    )
    frames: list[Frame] = [Frame("torso_frame", "torso", (0, 0, 0)),
                           Frame("imu", ROOT_LINK, (0, 0, 0))]
    for side in "RL":
        arm_links, arm_frames = _arm(p, side)
        links += arm_links
        frames += arm_frames
        frames.append(Frame(f"{side}_sole", f"{side}_foot", (0.0, 0.0, -p.ankle_to_sole_m)))
    neck = (0.0, 0.0, p.neck_above_torso_m)
    neck_motor_kg = 0.05  # each of the two neck motor links; the rest of the head mass is the head
    links += [
        _limb("neck_yaw", "torso", "NKY", (0, 0, 1), neck, neck_motor_kg, 0.0, 0.03, p),
        _limb("neck_pitch", "neck_yaw", "NK1", (0, 1, 0), (0, 0, 0), neck_motor_kg, 0.0, 0.03, p),
    ]
    head_kg = p.mass_head_kg - 2 * neck_motor_kg
    head = Link("head", "neck_pitch", "NK2", (1, 0, 0), (0, 0, 0), head_kg,
                (0.0, 0.0, 0.08), _box_inertia(head_kg, (0.08, 0.08, 0.08)),
                (Geom("sphere", (0.0, 0.0, 0.08), radius=0.09),), *_limits(p, "NK2"),
                _torque(p, "NK2"), _speed_max(p, "NK2"), _armature(p, "NK2"))
    links.append(head)
    hx, hy = p.foot_length_m / 2, p.foot_width_m / 2
    corners = ((hx, hy, 0.0), (hx, -hy, 0.0), (-hx, -hy, 0.0), (-hx, hy, 0.0))
    tree = KinematicTree(p.name, tuple(links), tuple(frames), corners)
    _check(tree)
    return tree


def _check(tree: KinematicTree) -> None:
    joints = {lk.joint for lk in tree.links if lk.joint}
    expected = set(JOINT_NAMES)
    # Hubo2+ has no wrist roll joint; its columns stay in the file, fixed at 0.
    missing = expected - joints - {"RWR", "LWR"}
    assert not missing, f"tree lacks joints {missing}"


def zero_pose_link_origins(tree: KinematicTree) -> dict[str, np.ndarray]:
    """World position of every link frame in the zero pose, pelvis at the origin."""
    out: dict[str, np.ndarray] = {}
    for lk in tree.links:  # parents always come before children
        base = out[lk.parent] if lk.parent else np.zeros(3)
        out[lk.name] = base + np.asarray(lk.origin_m)
    return out
