"""The grasp latch: a hand closed on a rail holds it, within what the grip can carry.

MuJoCo friction alone cannot keep a five-finger hook grip on a round rail (library notes:
a hand slid metres with default cones), and a real Hubo hand holds by closure rather
than by friction alone. So a closed hand is *latched* to the ladder by a weld equality
(one per hand, added to the spec inactive and switched through ``data.eq_active``), made
at the hand's orientation relative to the ladder at the moment it latches, with the grip
centre (the palm site) on the rail axis: fingers that close round a rail pull it into
the middle of the grip. A hand that closed off-centre (a misplaced ladder, an arm that
sagged) is drawn onto the axis; a compliant arm gives way, a stiff one fights the grip.

When it latches (all of):

- the fingers are driven closed (sent reference at least ``open_fraction`` ·
  ``FINGER_CLOSED_RAD``, where an opening would release) and their mean curl has reached
  the rail: the curl at which a finger
  meets a rail lying at the grip centre (`robot.kinematic_tree.finger_contact_curl_rad`,
  0.09 rad for a 25 mm rail). The board model keeps fingers from colliding with the
  rails (their single-link capsules' curl sweeps through the grip centre): the grip is
  this latch, not finger contact. While latched the fingers stop at that curl (their
  joints' upper range is set to it), as real fingers stop on the rail they wrap, so the
  finger encoders read a closed grip on a rail; fingers that pass it closed on nothing
  and go on to ``FINGER_CLOSED_RAD``;
- the hand was open before (a fist that closed on nothing does not grasp a rail it
  meets later: it must open first);
- its palm site (the grip centre) is within ``position_tolerance_m`` of a rail axis and
  its grip axis (palm x) within ``angle_tolerance_rad`` of the rail direction (either
  sense: the hand is symmetric along x).

When it lets go:

- the fingers are commanded open (sent reference below ``open_fraction`` · closed);
- the finger board tripped (no finger torque, no grip);
- the load across the rail (radial force or bending torque, which pull the rail out of
  the fingers or pry them open) exceeds the grip's capacity for ``slip_persistence_s``.

When it slips, still latched: a closed hand on a round rail turns about it or slides
along it once the load in that direction exceeds what friction holds, as a real grip
does; the fingers stay round the rail. Each tick such a load is over capacity, the
weld's anchor is moved about (or along) the rail, by the share of the hand's offset
from it that leaves the weld's spring carrying only the capacity. `slip_rad` and
`slip_m` add up how far the hand turned and slid; `max_grasp_turn_rad` and
`max_grasp_slide_m` are the largest net turn and slide of one grasp (from its latch on).

The fingers close round the rail and press it with the grip's ``finger_squeeze_nm`` each, 1 N·m by
default, a fifth of their limit:

- not at the limit: a grip that squeezed with all five fingers at their limit (8.3 N·m
  about the rail) does not turn, while the plan turns a held hand on its rail by up to
  55° as the body rises past it (`planner.arm_schedule`'s held-palm turn): the arm then folded
  elsewhere, bent the grip open and the hand dropped the rail (DRC seed 1, 72.0 s);
- not zero: a hook that does not squeeze holds along an inclined rail only what the
  load across it presses, and the planned hand forces push along the rail (the planner's
  hand hold is a push-up and a pull-in contact; on a 60° rail both have a component
  along it). The DRC mount's holds need up to 65 N of squeeze, 0.78 N·m a finger; with
  none the hands slid 2–3 cm down the rails and a hip roll's board tripped at 31 s.

Capacities: the squeeze and the fingers' strength set what the grip holds. They are the
contact model's (`ladders.contact_model.GripCapacity`, from the Hubo hand's
`ladders.contact_model.GripGeometry`), the same limits the planner plans hand wrenches
within (with a reserve) and check-plan checks: radial force 417 N and bending torque
9.0 N·m release the grip; along the rail 67 N + μ·F_r and about it 1.7 N·m + 0.01 m·F_r
(μ = 0.4, 25 mm rail) make it slip. The load is the weld's constraint wrench on the
hand, about the palm site, split along and across the rail. ``slip_persistence_s =
10 ms`` (two ticks) only filters single-step constraint spikes at impacts; it is not a
tuning knob.

Size: one latch per hand (latch, slip, release on one weld); most of the file is this
description.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import Enum

import mujoco
import numpy as np

from ladders.contact_model import (
    RELEASE_LOADS,
    SLIP_LOADS,
    GripCapacity,
    GripGeometry,
    default_grip,
)
from robot.kinematic_tree import FINGER_CLOSED_RAD, finger_contact_curl_rad

__all__ = ["RELEASE_LOADS", "SLIP_LOADS", "GraspEvent", "GraspLatch", "GripCapacity",
           "GripConfig", "GripState"]
#: A latched grip's load is kept every this long [s] (`GraspLatch.load_history`), for
#: validate-plan's comparison with the plan's hold wrenches.
LOAD_SAMPLE_S = 0.1
#: ``efc_type`` of an equality's constraint rows as a plain int: numpy compares an array
#: with the binding's enum object element by element, a hundred times slower.
_EQUALITY_ROW = int(mujoco.mjtConstraint.mjCNSTR_EQUALITY)


@dataclass(frozen=True)
class GripConfig:
    """Latch thresholds (see the module docstring).

    Attributes:
        closed_fraction: share of ``FINGER_CLOSED_RAD`` at which fingers count closed.
        open_fraction: share of it below which a commanded opening releases; fingers
            stopped on a rail grip it once their reference is past this share.
        position_tolerance_m: palm site to rail axis [m].
        angle_tolerance_rad: grip axis to rail direction [rad].
        grip: the hand's fingers and their torques (`ladders.contact_model`; the Hubo
            hand's by default, the planner's and check-plan's too).
        slip_persistence_s: how long an overload must last to release [s].
    """

    closed_fraction: float = 0.8
    open_fraction: float = 0.5
    position_tolerance_m: float = 0.02
    angle_tolerance_rad: float = math.radians(20.0)
    grip: GripGeometry = field(default_factory=default_grip)
    slip_persistence_s: float = 0.01


class GripState(Enum):
    OPEN = "open"
    LATCHED = "latched"
    CLOSED_EMPTY = "closed on nothing"


@dataclass(frozen=True)
class GraspEvent:
    """A change of a hand's grip: ``latched`` / ``released`` / ``missed``."""

    hand: str  # "left" / "right"
    kind: str
    time_s: float
    rail: str | None
    reason: str
    distance_m: float | None = None  # palm to nearest rail axis at the event
    angle_rad: float | None = None

    def __str__(self) -> str:
        where = f" rail {self.rail}" if self.rail else ""
        return f"{self.hand} hand {self.kind}{where} at t = {self.time_s:.2f} s: {self.reason}"


def _conj(q: np.ndarray) -> np.ndarray:
    out = np.zeros(4)
    mujoco.mju_negQuat(out, q)
    return out


def _mean(values: np.ndarray) -> float:
    """``float(np.mean(values))`` of a 1-D float64 array, the same sum and division
    without np.mean's overhead (several calls a tick)."""
    return float(np.add.reduce(values)) / len(values)


def _norm(v: np.ndarray) -> float:
    """``float(np.linalg.norm(v))`` of a 1-D float64 vector, the same dot product and
    square root without its overhead."""
    return math.sqrt(v.dot(v))


def _segment_closest(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    d = b - a
    t = float(np.clip((p - a) @ d / (d @ d), 0.0, 1.0))
    return a + t * d


class GraspLatch:
    """The latch of one hand (see the module docstring).

    Args:
        model, data: the compiled scene and its data.
        hand: ``"left"`` or ``"right"``.
        eq_id: id of the hand's (inactive) weld equality, hand body ↔ ladder body.
        finger_qpos: qpos addresses of the hand's five finger joints.
        finger_cols: their columns in the 40-column order.
        rails: rail name → (p0 site id, p1 site id, geom id).
        friction: ladder friction μ [-].
        rail_radius_m: rail radius [m].
        config: thresholds.
    """

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, hand: str, eq_id: int,
                 finger_qpos: np.ndarray, finger_cols: np.ndarray,
                 rails: dict[str, tuple[int, int, int]], friction: float,
                 rail_radius_m: float, config: GripConfig | None = None):
        self.model, self.data, self.hand = model, data, hand
        self.config = config or GripConfig()
        self.eq_id = eq_id
        side = "L" if hand == "left" else "R"
        self.body_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, f"{side}_hand")
        self.palm_site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, f"{side}_palm")
        self.ladder_body = int(model.eq_obj2id[eq_id])
        self.finger_qpos = np.asarray(finger_qpos)
        self.finger_cols = np.asarray(finger_cols)
        self.rails = rails
        self.friction, self.rail_radius_m = friction, rail_radius_m
        self.capacity = GripCapacity.of(self.config.grip, friction, rail_radius_m)
        self.rail_contact_curl_rad = finger_contact_curl_rad(rail_radius_m)
        joint_of_qpos = {int(model.jnt_qposadr[j]): j for j in range(model.njnt)}
        self._finger_joints = np.array([joint_of_qpos[int(a)] for a in self.finger_qpos])
        self._finger_range = model.jnt_range[self._finger_joints].copy()
        self._jac = np.zeros((6, model.nv))  # palm site: translation rows, rotation rows
        # The robot's floating base: its six velocities see every wrench on the hand
        # through an invertible 6×6 block of the palm's Jacobian.
        root = int(model.body_rootid[self.body_id])
        free = int(model.body_jntadr[root])
        if free < 0 or model.jnt_type[free] != mujoco.mjtJoint.mjJNT_FREE:
            raise ValueError(f"{hand} hand: its robot has no floating base")
        self._base_dofs = slice(int(model.jnt_dofadr[free]), int(model.jnt_dofadr[free]) + 6)
        self._qfrc = np.zeros(model.nv)
        self.reset()

    # ------------------------------------------------------------------ state
    def reset(self) -> None:
        """Open hand, weld off."""
        self.state = GripState.OPEN
        self._passed_rail = False
        self.rail: str | None = None
        self._overload_s = 0.0
        self.slip_m = self.slip_rad = 0.0
        #: The largest net turn about [rad] and slide along [m] its rail of one grasp,
        #: over the grasps so far (signed slips of a grasp add up; the sums above do not).
        self.max_grasp_turn_rad = self.max_grasp_slide_m = 0.0
        self._grasp_turn_rad = self._grasp_slide_m = 0.0
        self.peak_utilisation = 0.0
        self.last_utilisation = (0.0, "")
        #: (time [s], force [N], torque [N·m]) of the grip's load, world frame, every
        #: `LOAD_SAMPLE_S` while latched.
        self.load_history: list[tuple[float, np.ndarray, np.ndarray]] = []
        self.data.eq_active[self.eq_id] = 0
        self._fingers_on_rail(False)

    def _fingers_on_rail(self, on: bool) -> None:
        """Stop the fingers where they meet the rail (latched), or free them."""
        rng = self.model.jnt_range
        rng[self._finger_joints] = self._finger_range
        if on:
            rng[self._finger_joints, 1] = self.rail_contact_curl_rad

    @property
    def latched(self) -> bool:
        return self.state is GripState.LATCHED

    def palm_to_rails(self) -> dict[str, tuple[float, float]]:
        """Rail → (distance of the palm site from its axis [m], grip-axis angle [rad])."""
        p = self.data.site_xpos[self.palm_site]
        x = self.data.site_xmat[self.palm_site].reshape(3, 3)[:, 0]
        out = {}
        for name, (s0, s1, _g) in self.rails.items():
            a, b = self.data.site_xpos[s0], self.data.site_xpos[s1]
            axis = (b - a) / np.linalg.norm(b - a)
            dist = float(np.linalg.norm(p - _segment_closest(p, a, b)))
            ang = math.acos(min(1.0, abs(float(x @ axis))))
            out[name] = (dist, ang)
        return out

    def grip_load(self) -> tuple[np.ndarray, np.ndarray]:
        """Weld wrench on the hand about the palm site: force [N], torque [N·m] (world)."""
        m, d = self.model, self.data
        n = d.nefc
        rows = (d.efc_type[:n] == _EQUALITY_ROW) & (d.efc_id[:n] == self.eq_id)
        if not rows.any():
            return np.zeros(3), np.zeros(3)
        f = np.where(rows, d.efc_force[:n], 0.0)
        mujoco.mj_mulJacTVec(m, d, self._qfrc, f)
        J = self._jac
        mujoco.mj_jac(m, d, J[:3], J[3:], d.site_xpos[self.palm_site], self.body_id)
        # qfrc = Jᵀ w; the floating base's rows of it determine w (the ladder side of
        # the weld is fixed, so no other body takes this force)
        b = self._base_dofs
        w = np.linalg.solve(J[:, b].T, self._qfrc[b])
        return w[:3], w[3:]

    # ------------------------------------------------------------------ update
    def update(self, time_s: float, dt_s: float, finger_ref_rad: np.ndarray,
               finger_board_ok: bool) -> GraspEvent | None:
        """One check after a tick. ``finger_ref_rad`` is the sent finger reference (5,)."""
        cfg = self.config
        ref_mean_rad = _mean(finger_ref_rad)
        closed_ref = ref_mean_rad >= cfg.closed_fraction * FINGER_CLOSED_RAD
        opening = ref_mean_rad < cfg.open_fraction * FINGER_CLOSED_RAD
        curl = _mean(self.data.qpos[self.finger_qpos])
        if self.state is GripState.LATCHED:
            if not finger_board_ok:
                return self._release(time_s, "its finger board tripped: no finger torque, "
                                              "the fingers let go", GripState.CLOSED_EMPTY)
            if opening:
                return self._release(time_s, "fingers commanded open", GripState.OPEN)
            force, torque = self.grip_load()
            if not self.load_history or time_s - self.load_history[-1][0] >= LOAD_SAMPLE_S:
                self.load_history.append((time_s, force.copy(), torque.copy()))
            axis = self._rail_axis(self.rail)
            parts = self.capacity.utilisation(force, torque, axis)
            self._slip(parts, axis)
            what = max(RELEASE_LOADS, key=parts.get)
            u = parts[what]
            self.last_utilisation = (u, what)
            self.peak_utilisation = max(self.peak_utilisation, u)
            self._overload_s = self._overload_s + dt_s if u > 1.0 else 0.0
            if self._overload_s >= cfg.slip_persistence_s - 1e-12:
                return self._release(time_s, f"{what} {u:.2f}× what the grip holds "
                                              f"(|F| = {np.linalg.norm(force):.0f} N, "
                                              f"|T| = {np.linalg.norm(torque):.1f} N·m)",
                                     GripState.CLOSED_EMPTY)
            return None
        if self.state is GripState.CLOSED_EMPTY:
            if opening and curl < cfg.open_fraction * FINGER_CLOSED_RAD:
                self.state = GripState.OPEN
                self._passed_rail = False
            return None
        # OPEN
        if not finger_board_ok:
            return None
        driven = not opening  # the reference is past where a commanded opening releases
        if curl < self.rail_contact_curl_rad:
            if not driven:
                self._passed_rail = False
            return None  # not yet where a rail in the hand would stop them
        near = self.palm_to_rails()
        rail = min(near, key=lambda r: near[r][0])
        dist, ang = near[rail]
        within = dist <= cfg.position_tolerance_m and ang <= cfg.angle_tolerance_rad
        if within and not self._passed_rail:
            self._fingers_on_rail(True)  # the rail in the grip stops the fingers
            if not driven:
                return None  # touching it, not yet squeezing
            self._latch(rail)
            return GraspEvent(self.hand, "latched", time_s, rail,
                              f"palm {dist * 100:.1f} cm from the axis, grip axis "
                              f"{math.degrees(ang):.0f}° off", dist, ang)
        self._fingers_on_rail(False)
        self._passed_rail = True  # the fingers went past where a rail would stop them
        if not closed_ref or curl < cfg.closed_fraction * FINGER_CLOSED_RAD:
            return None  # not (yet) closed, on nothing
        self.state = GripState.CLOSED_EMPTY
        why = []
        if dist > cfg.position_tolerance_m:
            why.append(f"palm {dist * 100:.1f} cm from the {rail} axis (tolerance "
                       f"{cfg.position_tolerance_m * 100:.0f} cm)")
        if ang > cfg.angle_tolerance_rad:
            why.append(f"grip axis {math.degrees(ang):.0f}° off the rail (tolerance "
                       f"{math.degrees(cfg.angle_tolerance_rad):.0f}°)")
        return GraspEvent(self.hand, "missed", time_s, rail,
                          "fingers closed on nothing: " + "; ".join(why), dist, ang)

    def _slip(self, parts: dict[str, float], axis: np.ndarray) -> None:
        """Move the weld's anchor about and along the rail where friction gives way
        (module docstring): by the share ``1 − 1/utilisation`` of the hand's offset from
        the anchor in that direction."""
        u_along, u_about = (parts[load] for load in SLIP_LOADS)
        if max(u_along, u_about) <= 1.0:
            return
        d, eq = self.data, self.model.eq_data[self.eq_id]
        R_l, x_l = d.xmat[self.ladder_body].reshape(3, 3), d.xpos[self.ladder_body]
        if u_along > 1.0:
            anchor = R_l @ eq[0:3] + x_l
            offset_m = float((d.site_xpos[self.palm_site] - anchor) @ axis)
            shift_m = offset_m * (1.0 - 1.0 / u_along)
            eq[0:3] += R_l.T @ (axis * shift_m)
            self.slip_m += abs(shift_m)
            self._grasp_slide_m += shift_m
            self.max_grasp_slide_m = max(self.max_grasp_slide_m, abs(self._grasp_slide_m))
        if u_about > 1.0:
            q_lad = d.xquat[self.ladder_body]
            q_anchor, q_err, turn = np.zeros(4), np.zeros(4), np.zeros(4)
            mujoco.mju_mulQuat(q_anchor, q_lad, _conj(eq[6:10]))
            mujoco.mju_mulQuat(q_err, d.xquat[self.body_id], _conj(q_anchor))
            rotvec = np.zeros(3)
            mujoco.mju_quat2Vel(rotvec, q_err, 1.0)
            turn_rad = float(rotvec @ axis) * (1.0 - 1.0 / u_about)
            mujoco.mju_axisAngle2Quat(turn, axis, turn_rad)
            mujoco.mju_mulQuat(q_anchor, turn, q_anchor.copy())
            eq[6:10] = self._relpose(q_anchor)
            self.slip_rad += abs(turn_rad)
            self._grasp_turn_rad += turn_rad
            self.max_grasp_turn_rad = max(self.max_grasp_turn_rad, abs(self._grasp_turn_rad))

    def _relpose(self, q_hand: np.ndarray) -> np.ndarray:
        """The weld's relpose quaternion that holds the hand at orientation ``q_hand``:
        ``q_ladder = q_hand · relpose``."""
        out = np.zeros(4)
        mujoco.mju_mulQuat(out, _conj(q_hand), self.data.xquat[self.ladder_body])
        return out

    def _rail_axis(self, rail: str) -> np.ndarray:
        s0, s1, _ = self.rails[rail]
        d = self.data.site_xpos[s1] - self.data.site_xpos[s0]
        return d / _norm(d)

    def _latch(self, rail: str) -> None:
        """Weld hand ↔ ladder at their current relative orientation, the palm site on the
        rail axis."""
        m, d = self.model, self.data
        h, lad = self.body_id, self.ladder_body
        p = d.site_xpos[self.palm_site]
        R_h = d.xmat[h].reshape(3, 3)
        R_l = d.xmat[lad].reshape(3, 3)
        eq = m.eq_data[self.eq_id]
        s0, s1, _ = self.rails[rail]
        on_axis = _segment_closest(p, d.site_xpos[s0], d.site_xpos[s1])
        eq[0:3] = R_l.T @ (on_axis - d.xpos[lad])  # anchor in the ladder (body2) frame
        eq[3:6] = R_h.T @ (p - d.xpos[h])  # the palm site in the hand (body1) frame
        eq[6:10] = self._relpose(d.xquat[h])
        eq[10] = 1.0  # torquescale
        d.eq_active[self.eq_id] = 1
        self.state = GripState.LATCHED
        self.rail = rail
        self._overload_s = 0.0
        self._grasp_turn_rad = self._grasp_slide_m = 0.0

    def _release(self, time_s: float, reason: str, new_state: GripState) -> GraspEvent:
        rail = self.rail
        self.data.eq_active[self.eq_id] = 0
        self._fingers_on_rail(False)
        self.state = new_state
        self.rail = None
        self._overload_s = 0.0
        return GraspEvent(self.hand, "released", time_s, rail, reason)
