"""Whole-body IK with placo: keep the supporting holds, reach the moving limbs' targets.

Supporting holds are hard tasks (a foot: full pose; a hand: position plus grip axis along
the rail); moving targets are soft with a high weight, so an unreachable target yields
a best effort whose residual is reported instead of an infeasible QP. The CoM is pulled
inside a (clockwise) support polygon by a heavily weighted constraint; a soft posture task pulls
towards the primitive's seed posture.
"""

from __future__ import annotations

import logging
import math
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from planner.configuration.kinematics import HuboKinematics
from planner.contacts import Hold

log = logging.getLogger(__name__)

#: Joints the IK never moves: fingers are set by the grasp schedule, the neck stays still.
FIXED_JOINT_PREFIXES = ("RF", "LF", "NK")


@dataclass(frozen=True)
class IKConfig:
    """Tunables of the IK projection."""

    max_iterations: int = 80
    step_dt_s: float = 0.02
    # A hard hold further off than one bounded step corrects makes the QP infeasible: the
    # bound, not the hold, then gives way, doubling up to this step.
    max_step_dt_s: float = 0.32
    position_tol_m: float = 1e-4  # supporting holds (hard tasks)
    moving_tol_m: float = 1e-3  # a moving limb reaching its new hold
    waypoint_tol_m: float = 5e-3  # a moving limb in the air, between way-points
    angle_tol_rad: float = 2e-3  # supporting holds
    moving_angle_tol_rad: float = 3e-3  # a moving limb reaching its new hold
    waypoint_angle_tol_rad: float = 0.01  # a moving limb in the air: 0.6°
    # Moving targets are soft (an unreachable one must not make the QP infeasible) but
    # weighted 10⁶ above the posture so their residual is negligible.
    moving_position_weight: float = 1e4
    moving_orientation_weight: float = 1e3
    posture_weight: float = 1e-2
    torso_upright_weight: float = 0.5
    regularization: float = 1e-4
    com_margin_m: float = 0.01
    com_polygon_weight: float = 1e3


class HoldMiss(NamedTuple):
    """One hold an IK result does not meet within its tolerance: what a failure message
    tells a user (which limb, on what, how far off)."""

    limb: str  # e.g. ``left_hand``
    target: str  # what the hold is on: ``rung_0``, ``rail_left``, ``floor``
    position_error_m: float  # distance of the limb's frame from the hold [m]
    angle_error_rad: float  # its turn from the hold's orientation (a hand: grip axis) [rad]


@dataclass
class IKResult:
    """The configuration an IK solve ended at and how far it is from its holds.

    Attributes:
        position_error_m, angle_error_rad: the worst over every hold [m], [rad].
        misses: the holds not met within their tolerance, per limb (empty when
            converged), so a failure can name the limb and hold instead of only the figure.
    """

    q: np.ndarray = field(repr=False)
    converged: bool
    iterations: int
    position_error_m: float
    angle_error_rad: float
    misses: tuple[HoldMiss, ...] = ()

    def __repr__(self) -> str:
        return (f"IKResult({'converged' if self.converged else 'NOT converged'} in "
                f"{self.iterations} it, {self.position_error_m * 1000:.2f} mm, "
                f"{np.degrees(self.angle_error_rad):.2f} deg)")


def _grip_axis(hold_T: np.ndarray) -> np.ndarray:
    return hold_T[:3, 0]


#: placo's AxisAlignTask builds its error frame from ``cross(current, target).normalized()``,
#: a zero vector when the two axes are exactly parallel or opposite: the QP then holds NaN
#: and every solve from that state fails. A way-point taken from the hand's current pose
#: (backing off its rail) starts exactly there; on the ship ladder (seeds 12 and 13) every
#: sample of a hand move failed so. Such a target is turned by this angle, far below any
#: tolerance.
AXIS_ALIGN_NUDGE_RAD = 1e-6


def _axis_target(current: np.ndarray, target: np.ndarray) -> np.ndarray:
    """``target``, turned by `AXIS_ALIGN_NUDGE_RAD` if it is exactly (anti)parallel to the
    frame's ``current`` axis (both unit vectors)."""
    # Scalar cross product (np.cross's per-call overhead was 6 % of a search).
    (a0, a1, a2), (b0, b1, b2) = current.tolist(), target.tolist()
    if math.hypot(a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0) > 1e-12:
        return target
    perpendicular = np.cross(target, np.eye(3)[int(np.argmin(np.abs(target)))])
    perpendicular /= np.linalg.norm(perpendicular)
    return (np.cos(AXIS_ALIGN_NUDGE_RAD) * target
            + np.sin(AXIS_ALIGN_NUDGE_RAD) * perpendicular)


class _HoldCheck(NamedTuple):
    """What an IK iteration measures of one hold, taken from it once per solve: every
    iteration checks every hold, hundreds of thousands of times in a search."""

    hold: Hold
    frame: str
    target: tuple[tuple[float, ...], ...]  # the target pose's top three rows
    is_hand: bool
    position_tol_m: float
    angle_tol_rad: float


def _hold_checks(support, moving, config: IKConfig) -> tuple[_HoldCheck, ...]:
    """The holds' checks, supporting holds first, each with its tolerances."""
    return tuple(_HoldCheck(h, h.frame, tuple(map(tuple, h.T_world_frame[:3].tolist())),
                            h.is_hand, tol, atol)
                 for holds, tol, atol in ((support, config.position_tol_m, config.angle_tol_rad),
                                          (moving, config.moving_tol_m,
                                           config.moving_angle_tol_rad))
                 for h in holds)


def _hold_error(kin: HuboKinematics, check: _HoldCheck) -> tuple[float, float]:
    """The frame's distance from its target [m] and its turn from it [rad]: a hand's grip
    axis (x), the only axis its hold constrains, or a foot's whole orientation."""
    # Scalar math on Python floats: this runs every IK iteration for every hold, half a
    # million times a search, and numpy's per-call overhead was most of its cost.
    (a00, a01, a02, ax), (a10, a11, a12, ay), (a20, a21, a22, az) = \
        kin.wrapper.get_T_world_frame(check.frame)[:3].tolist()
    (b00, b01, b02, bx), (b10, b11, b12, by), (b20, b21, b22, bz) = check.target
    dp = math.sqrt((ax - bx) ** 2 + (ay - by) ** 2 + (az - bz) ** 2)
    c = a00 * b00 + a10 * b10 + a20 * b20  # cos of the turn between the x axes
    if not check.is_hand:  # (trace(R_a^T R_b) - 1) / 2
        c = (c + a01 * b01 + a11 * b11 + a21 * b21 + a02 * b02 + a12 * b12 + a22 * b22
             - 1.0) / 2.0
    return dp, math.acos(min(max(c, -1.0), 1.0))


def solve_ik(kin: HuboKinematics, q_seed: np.ndarray, support: tuple[Hold, ...],
             moving: tuple[Hold, ...] = (), *, posture_rad: dict[str, float] | None = None,
             torso_R: np.ndarray | None = None, pelvis_target_m: np.ndarray | None = None,
             pelvis_weight: float = 0.0, com_polygon_cw: np.ndarray | None = None,
             preferences: bool = True, joint_bounds_rad: dict[str, tuple[float, float]] | None
             = None, config: IKConfig = IKConfig()) -> IKResult:
    """Project ``q_seed`` onto the holds and pull the moving limbs to their targets.

    Args:
        kin: robot model; its state is overwritten.
        q_seed: starting configuration (pinocchio layout).
        support: holds that must be kept (hard).
        moving: targets of moving limbs (soft, high weight).
        posture_rad: preferred angle per joint (soft).
        torso_R: preferred torso orientation (soft), usually facing the ladder, upright.
        pelvis_target_m: preferred pelvis position (soft, ``pelvis_weight``).
        com_polygon_cw: clockwise CoM polygon (k, 2) to stay inside, with margin.
        preferences: add soft preferences of the holds (hand open side towards the
            ladder). Off for projections, where only the posture task may pull.
        joint_bounds_rad: joint → (lower, upper) [rad], narrowing its limits for this
            solve only (hard, as the limits are).

    Returns:
        The result; ``converged`` means every hold and target is met within tolerance.
    """
    robot = kin.wrapper
    with _narrowed_limits(kin, joint_bounds_rad or {}):
        kin.set_q(q_seed)
        solver = robot.make_solver()
        solver.mask_fbase(False)
        solver.enable_joint_limits(True)
        # Bounding each step by the joints' speed limits × dt keeps the linearised hard tasks
        # valid; unbounded steps from a far soft target made the QP diverge. The bound is
        # set per step (`_solve_widening_step`).
        solver.enable_velocity_limits(True)
        for name in robot.joint_names():
            if name.startswith(FIXED_JOINT_PREFIXES):
                solver.mask_dof(name)
        for hold in support:
            _add_hold_task(solver, hold, "hard", 1.0, 1.0, preferences)
        for hold in moving:
            _add_hold_task(solver, hold, "soft", config.moving_position_weight,
                           config.moving_orientation_weight, preferences)
        if posture_rad:
            jt = solver.add_joints_task()
            jt.set_joints({k: v for k, v in posture_rad.items() if k in kin.q_index})
            jt.configure("posture", "soft", config.posture_weight)
        if torso_R is not None:
            # Torso and pelvis both face the ladder: otherwise waist and hip yaws trade off
            # freely and neighbouring IK solutions twist the pelvis by tens of degrees.
            for frame in ("torso_frame", "pelvis"):
                ot = solver.add_orientation_task(frame, torso_R)
                ot.configure(f"{frame}_upright", "soft", config.torso_upright_weight)
        if pelvis_target_m is not None and pelvis_weight > 0:
            pt = solver.add_position_task("pelvis", np.asarray(pelvis_target_m, dtype=float))
            pt.configure("pelvis", "soft", pelvis_weight)
        if com_polygon_cw is not None:
            cc = solver.add_com_polygon_constraint(np.asarray(com_polygon_cw, dtype=float),
                                                   config.com_margin_m)
            # Soft: a hard polygon is infeasible for a start outside it within one bounded
            # step. Stability is verified on the result anyway.
            cc.configure("com_polygon", "soft", config.com_polygon_weight)
        solver.add_regularization_task(config.regularization)
        checks = _hold_checks(support, moving, config)
        it = 0
        pos_err = ang_err = np.inf
        for it in range(1, config.max_iterations + 1):
            robot.update_kinematics()
            if not _solve_widening_step(solver, config, it):
                break
            robot.update_kinematics()
            pos_err, ang_err, ok = _errors(kin, checks)
            if ok and it > 2:
                break
        final = list(_each_hold_error(kin, checks))
        converged = bool(np.isfinite(pos_err)) and all(met for *_, met in final)
        misses = () if converged else tuple(HoldMiss(h.limb, h.target, dp, da)
                                            for h, dp, da, met in final if not met)
        return IKResult(kin.q, converged, it, float(pos_err), float(ang_err), misses)


@contextmanager
def _narrowed_limits(kin: HuboKinematics, bounds_rad: dict[str, tuple[float, float]]):
    """The joints' limits narrowed to ``bounds_rad`` (within their own) while the block
    runs, then put back."""
    robot = kin.wrapper
    lower, upper = robot.model.lowerPositionLimit, robot.model.upperPositionLimit
    saved = {name: (float(lower[kin.q_index[name]]), float(upper[kin.q_index[name]]))
             for name in bounds_rad}
    try:
        for name, (lo, hi) in bounds_rad.items():
            robot.set_joint_limits(name, max(lo, saved[name][0]), min(hi, saved[name][1]))
        yield
    finally:
        for name, (lo, hi) in saved.items():
            robot.set_joint_limits(name, lo, hi)


def _solve_widening_step(solver, config: IKConfig, iteration: int) -> bool:
    """One QP step; while it is infeasible, the step bound doubles up to
    ``config.max_step_dt_s`` (for this step only). False when even that bound leaves it
    infeasible."""
    solver.dt = config.step_dt_s
    while True:
        try:
            solver.solve(True)
            return True
        except RuntimeError as exc:  # placo reports infeasible QPs as bare RuntimeErrors
            if solver.dt * 2 > config.max_step_dt_s + 1e-12:
                log.debug("IK QP failed at iteration %d (step %.2f s): %s", iteration,
                          solver.dt, exc)
                return False
            solver.dt *= 2


def _each_hold_error(kin: HuboKinematics, checks: tuple[_HoldCheck, ...]):
    """Per hold (supporting ones first): the hold, its position [m] and angle [rad] errors
    and whether both are within its tolerance."""
    for check in checks:
        dp, da = _hold_error(kin, check)
        yield check.hold, dp, da, dp < check.position_tol_m and da < check.angle_tol_rad


def _errors(kin: HuboKinematics, checks: tuple[_HoldCheck, ...]) -> tuple[float, float, bool]:
    """Worst position and angle errors, and whether every hold meets its tolerance."""
    ok = True
    pos_err = ang_err = 0.0
    for _, dp, da, met in _each_hold_error(kin, checks):
        ok &= met
        pos_err, ang_err = max(pos_err, dp), max(ang_err, da)
    return pos_err, ang_err, ok


def _add_hold_task(solver, hold: Hold, priority: str, w_pos: float, w_ori: float,
                   preferences: bool) -> None:
    name = hold.limb
    if hold.is_hand:
        R_now = solver.robot.get_T_world_frame(hold.frame)[:3, :3]
        t = solver.add_position_task(hold.frame, hold.T_world_frame[:3, 3].copy())
        t.configure(f"{name}_position", priority, w_pos)
        a = solver.add_axisalign_task(hold.frame, np.array([1.0, 0.0, 0.0]),
                                      _axis_target(R_now[:, 0], _grip_axis(hold.T_world_frame)))
        a.configure(f"{name}_grip_axis", priority, w_ori)
        if preferences:  # open side of the hand towards the ladder: soft, a preference
            b = solver.add_axisalign_task(hold.frame, np.array([0.0, 1.0, 0.0]),
                                          _axis_target(R_now[:, 1], hold.T_world_frame[:3, 1]))
            b.configure(f"{name}_open_side", "soft", 0.1)
    else:
        t = solver.add_frame_task(hold.frame, hold.T_world_frame.copy())
        t.configure(name, priority, w_pos, w_ori)
