"""Joint-torque feasibility of a configuration on its contacts: one LP.

With hands gripping, the CoM test (`planner.statics.com_region`) alone lets much pass: a
hand can pull hard enough to hold a CoM far from the feet. This LP balances the
generalized gravity of a configuration with contact wrenches, exactly on the free-flyer
rows, and minimises the worst joint-torque ratio max_j |τ_j| / τmax_j.

Contacts (`ladders.contact_model`, issue 22): a foot is point contacts at the corners of
its contact patch, in friction cones; a hand with grip limits (``Hold.limits``, a
`ladders.contact_model.HandLimits`) is a 6-D wrench about its palm frame inside the
linearised grip capacity, the same limits the MuJoCo latch lets go at
(`planner.statics.contact_wrenches`). Among equally good load shares the LP takes the one
that loads the grips least (`GRIP_LOAD_COST`).

Frames: world x forward, y left, z up; gravity along −z. Forces are those the environment
applies to the robot [N].
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from ladders.contact_model import FootPatch, HandLimits
from planner.contacts import LIMB_FRAME, Hold, Stance
from planner.statics.config import StabilityConfig, StabilityError, default_config
from planner.statics.contact_wrenches import cone_edges_cached, grip_rows, split_wrench_basis
from planner.statics.highs_lp import solve_lp
from robot.errors import HuboLadderError
from robot.vocabulary import Limb

__all__ = ["GRIP_LOAD_COST", "OBJECTIVES", "TorqueCheck", "actuated_joints",
           "torque_feasibility", "torque_limits_by_joint"]

#: Cost of a hand's wrench in the torque LP, per unit of its use of the grip (each
#: component as a share of its radial or bending capacity), against 1 per unit of the
#: worst joint ratio. The min-max optimum leaves the share of the load between grips and
#: feet free (only the worst joint counts); without a cost HiGHS returns any vertex of
#: that face, often a grip at its limit. The compliant arms give less than the LP asks
#: (`planner.statics.arm_capacity`), so among equal optima the least-loaded grip is the
#: plan the robot follows best. Small enough to move the optimum's ratio by < 0.005.
GRIP_LOAD_COST = 1e-3
#: What `torque_feasibility` minimises: the worst joint ratio (the planner's test), or the
#: worst grip utilisation with the joints within their limits (check-plan's contact check).
OBJECTIVES = ("torque", "contact")



def torque_limits_by_joint(robot: str = "drc-hubo") -> dict[str, float]:
    """Torque limit of every joint that has one, by joint name [N·m]."""
    from robot.joints import JOINT_NAMES
    from robot.limits import joint_limits

    lim = joint_limits(robot).torque_max_nm
    return {n: float(t) for n, t in zip(JOINT_NAMES, lim, strict=True) if t > 0}


@dataclass(frozen=True, eq=False)
class TorqueCheck:
    """Result of `torque_feasibility`.

    Attributes:
        feasible: the equilibrium LP is feasible and ``max_ratio <= 1`` (and, for the
            ``contact`` objective, every grip within its limits).
        equilibrium: contact wrenches within the contacts' limits can balance gravity
            (free-flyer rows; with the ``contact`` objective, with the joints within
            their limits too).
        max_ratio: max_j |τ_j| / τmax_j of the solution (the minimum over contact
            wrenches for the ``torque`` objective; inf if no equilibrium).
        worst_joint: joint reaching ``max_ratio`` ("" if no equilibrium).
        forces_n: per limb, (k, 3) world-frame forces on the robot at the hold's points
            [N]; a grip's is (1, 3), at its palm frame.
        joint_names: actuated joints, in pinocchio velocity order.
        torques_nm: (len(joint_names),) joint torques holding the configuration [N·m].
        wrenches: per limb, the (force [N], torque [N·m]) the hold applies to the robot
            about its limb frame's origin (palm or sole), world frame.
        contact_use: per limb whose hold has limits, each limit's use: a grip's
            `ladders.contact_model.GRIP_LOADS` as shares of its whole capacity, a foot's
            friction and centre of pressure (`ladders.contact_model.FootPatch.utilisation`).
        objective: what the LP minimised (`OBJECTIVES`).
        grip_share: for the ``contact`` objective, the LP's bound on the grips' use
            (≥ every grip's linearised use).
    """

    feasible: bool
    equilibrium: bool
    max_ratio: float
    worst_joint: str
    forces_n: dict[str, np.ndarray] = field(default_factory=dict, repr=False)
    joint_names: tuple[str, ...] = field(default=(), repr=False)
    torques_nm: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    wrenches: dict[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict,
                                                               repr=False)
    contact_use: dict[str, dict[str, float]] = field(default_factory=dict, repr=False)
    objective: str = "torque"
    grip_share: float = math.nan

    def torque(self, joint: str) -> float:
        """Torque of one joint [N·m]."""
        return float(self.torques_nm[self.joint_names.index(joint)])

    def worst_contact(self, hands_only: bool = False) -> tuple[str, str, float]:
        """(limb, limit, use) of the most used contact limit (of the grips only, if
        ``hands_only``); ("", "", 0) if none."""
        best = ("", "", 0.0)
        for limb, use in self.contact_use.items():
            if hands_only and not Limb(limb).is_hand:
                continue
            for load, u in use.items():
                if u > best[2]:
                    best = (limb, load, u)
        return best

    def __repr__(self) -> str:
        if not self.equilibrium:
            return "TorqueCheck(infeasible: no contact forces balance gravity)"
        loads = ", ".join(f"{limb} {np.linalg.norm(f.sum(axis=0)):.0f} N"
                          for limb, f in self.forces_n.items())
        verdict = "feasible" if self.feasible else "INFEASIBLE"
        limb, load, use = self.worst_contact()
        grip = f"; {limb} {load} {use:.2f} of its limit" if limb else ""
        return (f"TorqueCheck({verdict}, max |τ|/τmax = {self.max_ratio:.3f} at "
                f"{self.worst_joint}, {self.torque(self.worst_joint):+.1f} N·m; {loads}{grip})")


#: `actuated_joints` per model and limits: (model, result), keyed by the model's id and the
#: limits' items. The torque LP runs ~13,000 times a rung on a handful of limit tables,
#: and walking the model's joints took a tenth of its time.
_ACTUATED: dict[tuple[int, frozenset], tuple[object, tuple]] = {}


def _cross_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise ``a × b`` of (n, 3) arrays: `np.cross`'s arithmetic without its axis
    handling, which cost more than the products on the torque LP's few rows."""
    out = np.empty_like(b)
    out[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
    out[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
    out[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return out


def actuated_joints(model, torque_max_nm_by_joint: Mapping[str, float]):
    """Names, velocity indices, limits of the model's actuated (1-dof) joints and the
    model's weight [N] (memoised per model and limits)."""
    key = (id(model), frozenset(torque_max_nm_by_joint.items()))
    hit = _ACTUATED.get(key)
    if hit is not None and hit[0] is model:
        return hit[1]
    result = _walk_actuated(model, torque_max_nm_by_joint)
    _ACTUATED[key] = (model, result)
    return result


def _walk_actuated(model, torque_max_nm_by_joint: Mapping[str, float]):
    names, idx, tmax, missing = [], [], [], []
    for j in range(1, model.njoints):
        if model.joints[j].nv != 1:  # the free flyer
            continue
        name = model.names[j]
        lim = torque_max_nm_by_joint.get(name)
        if lim is None or lim <= 0:
            missing.append(name)
            continue
        names.append(name)
        idx.append(model.joints[j].idx_v)
        tmax.append(float(lim))
    if missing:
        raise HuboLadderError(
            f"no positive torque limit for joints {missing}; limits given for "
            f"{sorted(torque_max_nm_by_joint)}")
    weight_n = float(sum(model.inertias[j].mass for j in range(model.njoints))
                     * np.linalg.norm(model.gravity.linear))
    idx_a, tmax_a = np.array(idx), np.array(tmax)
    idx_a.setflags(write=False)
    tmax_a.setflags(write=False)
    return tuple(names), idx_a, tmax_a, weight_n


def torque_feasibility(model, data, q: np.ndarray, stance: Stance,
                       torque_max_nm_by_joint: Mapping[str, float],
                       frame_ids: Mapping[str, int] | None = None, *,
                       config: StabilityConfig | None = None,
                       objective: str = "torque") -> TorqueCheck:
    """Can the joints hold configuration q on the stance's contacts? (one LP)

    Static equilibrium g(q) = Sᵀτ + Σ Jᵀ w: the free-flyer rows (first 6) are met exactly
    by contact wrenches w, each inside its contact's limits: point forces in the
    linearised cones at a hold's points, or for a hold with grip limits
    (`ladders.contact_model.HandLimits`) a 6-D wrench about its limb frame inside the
    grip's halfspaces. With ``objective="torque"`` the LP minimises t = max_j |τ_j| /
    τmax_j over the actuated joints (epigraph form), plus `GRIP_LOAD_COST` per unit of
    grip use; with ``"contact"`` it keeps every |τ_j| ≤ τmax_j and minimises s, the
    share of their halfspaces' bounds the grips use (check-plan's contact-wrench check).

    Each hold's contact points are rigidly attached to its limb frame: their offsets in
    the frame are taken from the hold (``inv(T_world_frame) @ p``) and placed with the
    frame's pose at q, so a configuration that misses its hold slightly still gets the
    right lever arms. Normals, and therefore friction cones, stay those of the hold
    (world frame), as does a grip's rail axis. The point Jacobian is the frame's
    LOCAL_WORLD_ALIGNED Jacobian shifted to the point, so J_pᵀ f = J_vᵀ f + J_ωᵀ (r × f).

    Args:
        model: pinocchio model with a free-flyer root (gravity from ``model.gravity``).
        data: its pinocchio data (overwritten: kinematics, Jacobians, gravity).
        q: (model.nq,) configuration, free flyer first.
        stance: the holds in contact.
        torque_max_nm_by_joint: torque limit of every actuated joint of the model, by
            name [N·m] (see `torque_limits_by_joint`).
        frame_ids: frame id per limb; looked up from ``LIMB_FRAME`` if None.
        config: tunables, `default_config()` if None.
        objective: one of `OBJECTIVES`.

    Returns:
        The check; ``feasible`` iff the equilibrium is feasible and max ratio ≤ 1.
    """
    import pinocchio as pin

    if objective not in OBJECTIVES:
        raise ValueError(f"unknown objective {objective!r}; use one of {OBJECTIVES}")
    cfg = config or default_config()
    names, v_idx, tmax, weight_n = actuated_joints(model, torque_max_nm_by_joint)

    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    grav = pin.computeGeneralizedGravity(model, data, q) / weight_n

    contacts = _contact_columns(model, data, stance, frame_ids, cfg, weight_n)
    n_c = contacts.gmat.shape[1]
    # Variables [contacts (body weights), t or s]. τ/W = g_a/W − G_a x.
    g_a, gm_a = grav[v_idx], contacts.gmat[v_idx]
    a_ub, b_ub = _inequality_rows(objective, g_a, gm_a, (tmax / weight_n)[:, None], contacts)
    a_eq = np.hstack([contacts.gmat[:6], np.zeros((6, 1))])
    b_eq = grav[:6]
    upper = np.full(n_c + 1, cfg.force_max_weights)
    upper[n_c] = np.inf
    cost = np.concatenate(contacts.cost_parts + [[1.0]])
    status, x = solve_lp(cost, a_ub, b_ub, a_eq, b_eq, upper)
    if status == "infeasible":
        return TorqueCheck(False, False, math.inf, "", joint_names=names, objective=objective)
    if status != "optimal":
        raise StabilityError(f"torque LP failed for {stance!r}: HiGHS status {status}")

    tau = (g_a - gm_a @ x[:n_c]) * weight_n
    ratios = np.abs(tau) / tmax
    worst = int(np.argmax(ratios))
    forces, wrenches, use = _contact_loads(contacts, x, weight_n)
    max_ratio = float(ratios[worst])
    share = float(x[n_c]) if objective == "contact" else math.nan
    feasible = max_ratio <= 1.0 + 1e-9 and (objective == "torque" or share <= 1.0 + 1e-9)
    return TorqueCheck(feasible, True, max_ratio, names[worst], forces, names, tau,
                       wrenches, use, objective, share)


class _ContactColumns(NamedTuple):
    """The torque LP's contact variables, hold by hold.

    Attributes:
        gmat: (nv, n_c) generalized force of each contact variable (Jᵀ times its wrench
            direction), per unit body weight.
        starts: (holds + 1,) first column of each hold's variables in ``gmat``, and n_c.
        parts: per hold, (hold, R_world_frame at q, cone edges (m, k, 3) and world-frame
            point offsets (m, 3) from the frame origin [m]; both None for a grip).
        grip_rows: per limited grip, (index into ``parts``, its halfspace rows (r, 12),
            their bounds (r,) in body weights).
        cost_parts: per hold, the cost of each of its variables (`GRIP_LOAD_COST` on a
            grip's, 0 on a cone's).
    """

    gmat: np.ndarray
    starts: np.ndarray
    parts: list[tuple[Hold, np.ndarray, np.ndarray | None, np.ndarray | None]]
    grip_rows: list[tuple[int, np.ndarray, np.ndarray]]
    cost_parts: list[np.ndarray]


def _limb_frame_id(model, hold: Hold, frame_ids: Mapping[str, int] | None) -> int:
    """The model frame of the hold's limb: from ``frame_ids`` if given, else by name."""
    if frame_ids is not None and hold.limb in frame_ids:
        return frame_ids[hold.limb]
    fname = LIMB_FRAME[hold.limb]
    if not model.existFrame(fname):
        raise HuboLadderError(f"frame {fname!r} of {hold.limb} is not in the model")
    return model.getFrameId(fname)


def _contact_columns(model, data, stance: Stance, frame_ids: Mapping[str, int] | None,
                     cfg: StabilityConfig, weight_n: float) -> _ContactColumns:
    """Every hold's contact variables mapped through its frame Jacobian at the
    configuration ``data`` holds: a grip's split wrench (12 columns), or a foot's cone
    coefficients at its points placed with the frame's pose (m k columns)."""
    import pinocchio as pin

    cols, parts, grips, cost_parts = [], [], [], []
    for hold in stance.holds:
        fid = _limb_frame_id(model, hold, frame_ids)
        o_m_f = data.oMf[fid]
        jac = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
        if isinstance(hold.limits, HandLimits):
            cols.append(jac.T @ split_wrench_basis(np.zeros(3)))  # (nv, 12)
            rows, rhs = grip_rows(hold.limits, weight_n)
            grips.append((len(parts), rows, rhs))
            cap = hold.limits.capacity
            per = np.array([cap.radial_n] * 3 + [cap.bending_nm] * 3)
            cost_parts.append(np.tile(GRIP_LOAD_COST * weight_n / per, 2))
            parts.append((hold, o_m_f.rotation.copy(), None, None))
            continue
        # world-frame offsets of the points from the frame's origin [m]
        r = hold.points_in_frame_m @ o_m_f.rotation.T
        e = cone_edges_cached(np.ascontiguousarray(hold.normals, dtype=float).tobytes(),
                              float(hold.friction), cfg.cone_edges)  # (m, k, 3)
        k = e.shape[1]
        e_flat = e.reshape(-1, 3)
        wrench = np.vstack([e_flat.T, _cross_rows(np.repeat(r, k, axis=0), e_flat).T])
        cols.append(jac.T @ wrench)  # (nv, m k), per unit weight
        cost_parts.append(np.zeros(e_flat.shape[0]))
        parts.append((hold, o_m_f.rotation.copy(), e, r))
    starts = np.concatenate([[0], np.cumsum([c.shape[1] for c in cols])])
    return _ContactColumns(np.hstack(cols), starts, parts, grips, cost_parts)


def _inequality_rows(objective: str, g_a: np.ndarray, gm_a: np.ndarray, tm: np.ndarray,
                     contacts: _ContactColumns) -> tuple[np.ndarray, np.ndarray]:
    """The LP's A_ub, b_ub: each actuated joint's |τ_j| against its limit, then each
    grip's halfspaces.

    ``torque``: |τ_j| ≤ t τmax_j, and a grip's A y ≤ b. ``contact``: |τ_j| ≤ τmax_j, and
    A y ≤ s b. τ/W = g_a − G_a x (``g_a``, ``gm_a`` the actuated rows, ``tm`` (n, 1) the
    limits, all per body weight); the last variable is t or s.
    """
    n_c = contacts.gmat.shape[1]
    if objective == "torque":  # |τ_j| ≤ t τmax_j; grips A y ≤ b
        a_ub = np.block([[gm_a, -tm], [-gm_a, -tm]])
        b_ub = np.concatenate([g_a, -g_a])
    else:  # |τ_j| ≤ τmax_j; grips A y ≤ s b
        a_ub = np.block([[gm_a, np.zeros_like(tm)], [-gm_a, np.zeros_like(tm)]])
        b_ub = np.concatenate([g_a + tm[:, 0], -g_a + tm[:, 0]])
    starts = contacts.starts
    for i, rows, rhs in contacts.grip_rows:
        block = np.zeros((len(rows), n_c + 1))
        block[:, starts[i]:starts[i + 1]] = rows
        if objective == "torque":
            b_ub = np.concatenate([b_ub, rhs])
        else:
            block[:, n_c] = -rhs
            b_ub = np.concatenate([b_ub, np.zeros(len(rhs))])
        a_ub = np.vstack([a_ub, block])
    return a_ub, b_ub


def _contact_loads(contacts: _ContactColumns, x: np.ndarray, weight_n: float
                   ) -> tuple[dict[str, np.ndarray], dict[str, tuple[np.ndarray, np.ndarray]],
                              dict[str, dict[str, float]]]:
    """The LP's solution per limb, in newtons: its point forces, its wrench about its limb
    frame's origin, and its use of its contact's limits (`TorqueCheck`'s fields)."""
    forces, wrenches, use = {}, {}, {}
    starts = contacts.starts
    for i, (hold, rot, e, r) in enumerate(contacts.parts):
        xi = x[starts[i]:starts[i + 1]]
        if e is None:  # a grip: its split wrench
            w = (xi[:6] - xi[6:]) * weight_n
            force, torque = w[:3], w[3:]
            forces[hold.limb] = force[None, :]
            use[hold.limb] = hold.limits.utilisation(force, torque)
        else:
            m, k = e.shape[:2]
            f = np.einsum("mk,mki->mi", xi.reshape(m, k), e) * weight_n
            forces[hold.limb] = f
            force, torque = f.sum(axis=0), _cross_rows(r, f).sum(axis=0)
            if isinstance(hold.limits, FootPatch):
                use[hold.limb] = _foot_use(hold.limits, rot, force, torque)
        wrenches[hold.limb] = (force, torque)
    return forces, wrenches, use


def _foot_use(patch: FootPatch, R_world_sole: np.ndarray, force: np.ndarray,
              torque: np.ndarray) -> dict[str, float]:
    """A sole's friction and centre-of-pressure use of its patch, from its wrench about
    the sole frame's origin (world frame)."""
    f_l, t_l = R_world_sole.T @ force, R_world_sole.T @ torque
    fz = float(f_l[2])
    if fz <= 1e-6:  # an unloaded sole: no friction, no centre of pressure to place
        return dict.fromkeys(patch.utilisation(np.array([0.0, 0.0, 1.0]), np.zeros(2)), 0.0)
    return patch.utilisation(f_l, np.array([-t_l[1] / fz, t_l[0] / fz]))


