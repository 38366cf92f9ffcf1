"""Turning seed holds (relative to rungs and rails) into concrete `Hold`s on a ladder."""

from __future__ import annotations

import numpy as np

from ladders.contact_model import FootPatch, sole_patch_x
from ladders.geometry import LadderGeometry
from planner.contacts import Hold
from primitives.hold_seeds import FloorSeed, HoldSeed, RailSeed, RungSeed
from robot.params import RobotParams


def half_tread_m(spec) -> float:
    """Half the depth of a rung's tread that supports a sole [m]: 0 on a round rung,
    which supports it along a line (`ladders.contact_model.sole_patch_x`)."""
    return spec.rung_depth_m / 2 if spec.rung_shape == "box" else 0.0


def _pose(R: np.ndarray, p: np.ndarray) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, p
    return T


#: Ways to roll a closed hand about its rail (see `palm_rotation`).
GRIP_STYLES = ("facing", "shoulder")


def palm_rotation(geom: LadderGeometry, side: str, grip_m: np.ndarray | None = None,
                  shoulder_m: np.ndarray | None = None, style: str = "facing") -> np.ndarray:
    """R_world_palm of a hand closed on a rail at ``grip_m``. The grip axis (palm x) runs
    along the rail; the roll about the rail depends on ``style``:

    - ``facing``: the hand's open side (s·y_palm, s = +1 left, −1 right) faces into the
      ladder and the wrist (palm +z) is inboard of the rail; the hand backs off towards the
      climber. Suits rails well outboard of the shoulders.
    - ``shoulder``: the wrist points back towards the shoulder at ``shoulder_m``, the way a
      person grips a rail in front of them, and the open side faces outboard; the hand
      backs off inboard. The forearm never crosses the chest, however close the rails.
    """
    s = 1.0 if side == "left" else -1.0
    d, n = geom.ladder_direction, geom.rung_line_normal
    if style == "facing":
        x, y = -d, -s * n
        return np.column_stack([x, y, np.cross(x, y)])
    if style != "shoulder":
        raise ValueError(f"unknown grip style {style!r}; use one of {GRIP_STYLES}")
    v = np.asarray(shoulder_m, dtype=float) - np.asarray(grip_m, dtype=float)
    z = v - (v @ d) * d
    z /= np.linalg.norm(z)
    outboard = s * geom.lateral_direction
    for x in (-d, d):
        y = np.cross(z, x)
        if (s * y) @ outboard >= 0:
            return np.column_stack([x, y, z])
    raise AssertionError("unreachable: one of the two grip-axis signs is outboard")


def hand_retreat_direction(limb: str, T_world_palm: np.ndarray) -> np.ndarray:
    """Unit vector along which a hand at ``T_world_palm`` leaves (or approaches) its rail:
    away from its open side (s·y_palm, s = +1 left, −1 right)."""
    s = 1.0 if limb == "left_hand" else -1.0
    return -s * T_world_palm[:3, 1]


def rail_point(geom: LadderGeometry, side: str, rung: int, along_m: float = 0.0) -> np.ndarray:
    """Point of a rail axis vertically above rung ``rung`` (any index), moved ``along_m``
    up the rail [m]."""
    p0, _ = geom.rail_axis(side)
    spec = geom.spec
    s_m = spec.rung_height_m(rung) / np.sin(spec.slope_rad) + along_m
    return p0 + s_m * geom.ladder_direction


def shoulder_room_along_m(geom: LadderGeometry, params: RobotParams, rung: int,
                          torso_along_m: float) -> float:
    """Along-rail offset from the point above rung ``rung`` [m] where a rail hold is an upper
    arm's length, horizontally, from the shoulder of a torso standing ``torso_along_m``
    up-ladder of the rung's tread centre; −inf if the rails are that far aside anyway.

    A hand held nearer than that leaves the elbow no room but folded to its limit, where a
    compliant arm carries nothing: on the ship ladder (rails 0.79 m apart, 0.17 m outside
    the shoulders) a mount hold beside the shoulders folded both elbows to −2.65 rad and the
    floor foot's lift-off was found in 1 of 6 searches (0.99 of the torque limits), against
    6 of 6 (0.90) with it 0.2–0.3 m up the rail.
    """
    spec = geom.spec
    aside_m = spec.rail_spacing_m / 2 - params.half_shoulder_width_m
    ahead_sq_m2 = params.upper_arm_m ** 2 - aside_m ** 2
    if ahead_sq_m2 <= 0:
        return -np.inf
    # Rail points above rung k and the rung's tread centre share x_L; d x_L / d along = cos.
    return float((torso_along_m + np.sqrt(ahead_sq_m2)) / np.cos(spec.slope_rad))


#: A sole's centre stands at least this far, horizontally, behind the back edge of the
#: tread above its own [m]: the shin's room under that tread. The ball-of-foot seed
#: (`primitives.hold_seeds.FOOT_ALONG_M`) leaves 0.185 m on the DRC ladder and 0.177 m on
#: the stair, which both climb with it (this is the less of the two, rounded down); the
#: ship ladder's closer rungs (0.254 m apart, treads 0.178 m deep) leave 0.129 m, and
#: there the search found the mount's right step only with the legs' clearance relaxed to
#: 1 cm, after 31-71 failed samples, and the shin then met rung 1 in MuJoCo
#: (docs/decisions/shin-room.md).
SHIN_ROOM_M = 0.175
#: The tread keeps at least this much of a sole on it (or all of a shallower tread: the
#: DRC's 0.102 m carries 0.10 m at the seed) when the shin's room moves the sole back [m].
TREAD_UNDER_SOLE_M = 0.10


def shin_room_along_m(geom: LadderGeometry, params: RobotParams) -> float:
    """The furthest up-ladder offset from its tread's centre (x_L) [m] at which a sole's
    centre keeps `SHIN_ROOM_M` behind the back edge of the tread above, but no further
    back than leaves `TREAD_UNDER_SOLE_M` of the sole on its own tread; +inf on round
    rungs, which carry the sole under the ball of the foot, along a line."""
    spec = geom.spec
    if spec.rung_shape != "box":
        return np.inf
    half_depth_m = spec.rung_depth_m / 2
    above_m = spec.rung_run_m(1) - spec.rung_run_m(0) - half_depth_m  # its back edge
    on_tread_m = min(spec.rung_depth_m, TREAD_UNDER_SOLE_M)
    return float(max(above_m - SHIN_ROOM_M,
                     on_tread_m - half_depth_m - params.foot_length_m / 2))


#: The feet's centre of pressure is kept this far inside the sole's support (the sole,
#: or the part of it on a tread) [m]. The torque LP's optimum is a vertex, which puts a
#: centre of pressure on the support's edge, where a real sole rocks and the hands take
#: the load the ankles do not give (docs/decisions/foot-cop-margin.md).
FOOT_COP_MARGIN_M = 0.02
#: Share of the ladder's μ the planner lets a foot use. The torque LP's optimum puts a
#: foot's friction on its cone, and the load share the robot's compliance makes is not
#: the LP's, so a foot planned on the cone slides. 3/4 of μ is the usual margin of
#: legged-robot planners, not a tuned figure; check-plan checks the whole μ
#: (docs/decisions/foot-friction-share.md).
FOOT_FRICTION_SHARE = 0.75

#: How far from zero a hand's wrist pitch stays while the hand holds and a foot is in the
#: air [rad]; 0: no bound. At zero pitch the wrist's yaw and roll axes line up: the arm
#: cannot turn the palm about the third direction, and whatever the body's motion asks of
#: that turn (a ladder not quite where the plan has it, a compliant arm lagging its
#: reference) reaches the grip as bending. Off by default: at 0.15 rad more DRC mounts
#: climbed under the harder perturbation, but whole climbs planned less often and climbed
#: no more often (docs/decisions/held-wrist-singularity.md).
HELD_WRIST_MARGIN_RAD = 0.0

#: Hand → its wrist pitch joint.
WRIST_PITCH_JOINT = {"left_hand": "LWP", "right_hand": "RWP"}


def wrist_bound_hands(holding_limbs) -> tuple[str, ...]:
    """Of the limbs on their holds, the hands that keep their wrists out of the
    singularity (`HELD_WRIST_MARGIN_RAD`): every hand on its hold while a foot is in the
    air. With both feet down the legs carry the body and a held wrist may pass zero; the
    plans do, between the foot steps. The planner's feasibility check and check-plan's
    `held wrists` both apply this rule."""
    limbs = list(holding_limbs)
    if sum(1 for limb in limbs if limb.endswith("_foot")) >= 2:
        return ()
    return tuple(limb for limb in limbs if limb in WRIST_PITCH_JOINT)


def sole_contact_points(params: RobotParams, T_world_sole: np.ndarray,
                        x_range_m: tuple[float, float], margin_m: float) -> np.ndarray:
    """Four corners of the sole part between ``x_range_m`` (sole frame x), each side
    ``margin_m`` inwards (along x only where the part is wider than twice that) [m],
    world."""
    patch = FootPatch(tuple(x_range_m), params.foot_width_m / 2, 0.0).shrunk(margin_m)
    return _to_world(T_world_sole, patch.corners())


def _to_world(T: np.ndarray, local: np.ndarray) -> np.ndarray:
    return local @ T[:3, :3].T + T[:3, 3]


def foot_patch(params: RobotParams, x_range_m: tuple[float, float], friction: float,
               margin_m: float) -> FootPatch:
    """The patch a sole's centre of pressure may use: the sole part ``x_range_m`` (sole
    frame x) ``margin_m`` inside its sides, at ``friction``."""
    return FootPatch(tuple(x_range_m), params.foot_width_m / 2, friction).shrunk(margin_m)


def make_hold(seed: HoldSeed, geom: LadderGeometry, params: RobotParams,
              floor_pose: dict[str, np.ndarray] | None = None, offset_m=(0.0, 0.0),
              shoulder_m: np.ndarray | None = None, grip_style: str = "facing",
              cop_margin_m: float = FOOT_COP_MARGIN_M,
              friction_share: float = FOOT_FRICTION_SHARE) -> Hold:
    """A concrete hold for a seed, shifted by ``offset_m`` = (along, lateral) in L [m].

    A rail hold takes a ``grip_style`` (see `palm_rotation`); the ``shoulder`` style needs
    ``shoulder_m``, the current position of that arm's shoulder [m]; it is the thesis's
    point hold (see below).
    A foot hold's contact patch (`ladders.contact_model`: the sole ∩ tread overlap, a
    line on a round rung) keeps its centre of pressure ``cop_margin_m`` inside its
    sides, and its friction is ``friction_share`` of the ladder's μ.
    """
    mu = geom.spec.friction
    foot_mu = mu * friction_share
    up = np.array([0.0, 0.0, 1.0])
    hl = params.foot_length_m / 2
    if isinstance(seed, FloorSeed):
        T = floor_pose[seed.limb]
        patch = foot_patch(params, (-hl, hl), foot_mu, cop_margin_m)
        return Hold(seed.limb, "floor", T, _to_world(T, patch.corners()), np.tile(up, (4, 1)),
                    foot_mu, limits=patch)
    if isinstance(seed, RungSeed):
        along = min(seed.along_m, shin_room_along_m(geom, params)) + offset_m[0]
        lateral = seed.lateral_m + offset_m[1]
        p = geom.rung_top_point(seed.rung, lateral_m=lateral, along_m=along)
        T = _pose(geom.R_world_ladder, p)
        # The tread's centre lies at -along in the sole frame.
        x_range = sole_patch_x(geom.spec.rung_shape, half_tread_m(geom.spec), -along,
                               params.foot_length_m)
        if x_range is None:
            raise ValueError(f"the sole does not overlap rung {seed.rung} at offset {along} m")
        patch = foot_patch(params, x_range, foot_mu, cop_margin_m)
        return Hold(seed.limb, seed.target, T, _to_world(T, patch.corners()),
                    np.tile(up, (4, 1)), foot_mu, limits=patch)
    if isinstance(seed, RailSeed):
        along = seed.along_m
        if seed.torso_along_m is not None:
            along = max(along, shoulder_room_along_m(geom, params, seed.rung,
                                                     seed.torso_along_m))
        p = rail_point(geom, seed.side, seed.rung, along + offset_m[0])
        T = _pose(palm_rotation(geom, seed.side, p, shoulder_m, grip_style), p)
        # The thesis's point hold: a contact pushing up and one pulling the hand towards
        # the ladder, at the grip centre, in μ cones. The grip's 6-D wrench limits
        # (`ladders.contact_model.hand_limits`) are what check-plan verifies and the latch
        # enforces; planned with them (0.8 reserve, moments or forces only), DRC mounts
        # climbed far less often in MuJoCo (docs/decisions/contact-model.md).
        towards_ladder = geom.R_world_ladder @ np.array([1.0, 0.0, 0.0])
        return Hold(seed.limb, seed.target, T, np.vstack([p, p]),
                    np.vstack([up, towards_ladder]), mu)
    raise TypeError(f"unknown seed {seed!r}")
