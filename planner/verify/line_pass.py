"""check-plan's pass over the lines of one segment, a batch at a time.

`planner.verify.check.check_plan` reads as one pass over the lines; this module runs it
on a batch of consecutive lines of one segment at once (`check_lines`), with the robot's
kinematics in numpy (`planner.verify.batch_kinematics`), the torque LP carried from line
to line by its basis (`planner.verify.torque_lines`) and coal asked only about pairs a
bound cannot clear (`planner.verify.collision_lines`). The checks, their order and
their rule for the worst line (the first line with the worst value) are those of the
per-line pass it replaced, and so are its figures, to rounding.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np

from ladders.contact_model import GRIP_LOADS
from robot.plan_sidecar import Segment

if TYPE_CHECKING:
    from planner.contacts import Hold
    from planner.verify.batch_kinematics import JointPoses
    from planner.verify.check import CheckResult, PlanVerifier
    from planner.verify.torque_lines import LineTorques

__all__ = ["check_lines", "offer_lines"]


def offer_lines(result: CheckResult, lines: np.ndarray, keys: np.ndarray,
                values: np.ndarray, failed: np.ndarray, detail: Callable[[int], str]) -> None:
    """`CheckResult.offer` for many lines in order: the first line whose key is within
    `WORST_TIE` of the largest competes, and ``detail(i)`` is built for it only.

    Args:
        result: the check.
        lines: (n,) 1-based lines, increasing.
        keys: (n,) badness (larger is worse).
        values: (n,) the values reported.
        failed: (n,) which lines fail.
        detail: the detail of the i-th of these lines.
    """
    if not len(lines):
        return
    from planner.verify.check import WORST_TIE

    i = int(np.argmax(keys >= np.max(keys) - WORST_TIE))  # the first at the worst
    n_failed = int(np.count_nonzero(failed))
    result.offer(int(lines[i]), float(keys[i]), float(values[i]), detail(i), bool(failed[i]))
    result.failing_lines += n_failed - int(bool(failed[i]))
    result.ok &= n_failed == 0


def check_lines(res: dict[str, CheckResult], v: PlanVerifier, traj_rad: np.ndarray,
                segs: Sequence[Segment], si: int, rows: np.ndarray, every: int) -> None:
    """Every check on lines ``rows`` (0-based, consecutive) of segment ``si``.

    Args:
        res: the results by check name (`planner.verify.check.CHECKS`).
        v: the verifier's models.
        traj_rad: (N, 40) the whole trajectory [rad].
        segs: the sidecar's segments.
        si: the segment these lines belong to.
        rows: the lines, 0-based.
        every: collisions and statics on every n-th line of the segment (and its first
            and last); holds on every line.
    """
    seg = segs[si]
    label = f"{seg.primitive}/{seg.phase}"
    lines = rows + 1
    poses, q = v.line_poses(traj_rad[rows], seg)
    if poses is None:
        offer_lines(res["holds"], lines, np.full(len(lines), math.inf),
                    np.full(len(lines), math.inf), np.ones(len(lines), dtype=bool),
                    lambda i: f"{label}: no foot in contact: the base cannot be placed")
        return
    _check_holds(res["holds"], v, poses, lines, seg, label)
    at_end = (lines == seg.first_line) | (lines == seg.last_line)
    mine = ((lines - seg.first_line) % every == 0) | at_end if every > 1 else \
        np.ones(len(lines), dtype=bool)
    idx = np.flatnonzero(mine)
    if not len(idx):
        return
    sub = poses.subset(idx)
    _check_collisions(res["collision"], v, sub, q.subset(idx), lines[idx], segs, si, label)
    held = v.stance(si, seg)
    margin = np.asarray(held.region.margin(v.kin.com(sub)), dtype=float)
    balance = ", ".join(held.balance_limbs)
    offer_lines(res["stability margin"], lines[idx], -margin, margin, margin < 0.0,
                lambda i: f"{label}: CoM margin {margin[i] * 100:.1f} cm in the support "
                          f"region of {balance}")
    ok = np.flatnonzero(margin >= 0.0)  # the torque LP only where the CoM is inside
    if len(ok):
        lp = v.stance_lines(si, seg).solve(sub.subset(ok))
        _check_loads(res, v, lp, q.subset(idx[ok]), lines[idx[ok]], si, seg, label)


def _check_holds(result: CheckResult, v: PlanVerifier, poses: JointPoses, lines: np.ndarray,
                 seg: Segment, label: str) -> None:
    """Every limb the segment holds: its frame at its hold, and the hold on its object."""
    limbs = list(seg.holds)
    d_frame = np.empty((len(lines), len(limbs)))
    d_target = np.empty(len(limbs))
    for j, limb in enumerate(limbs):
        h = seg.holds[limb]
        p = np.asarray(h.position_m)
        d_frame[:, j] = np.linalg.norm(v.frame_positions(poses, limb) - p, axis=1)
        d_target[j] = v.target_distance(h.target, p)
    err = np.maximum(d_frame, d_target)
    which = len(limbs) - 1 - np.argmax(err[:, ::-1], axis=1)  # the last limb at the max
    worst = err.max(axis=1)

    def detail(i: int) -> str:
        j = int(which[i])
        t = seg.holds[limbs[j]].target
        return (f"{label}: {limbs[j]} {d_frame[i, j] * 100:.2f} cm from its hold on {t}, "
                f"hold {d_target[j] * 100:.2f} cm from {t}")

    from planner.verify.check import HOLD_TOL_M

    offer_lines(result, lines, worst, worst, worst > HOLD_TOL_M, detail)


def _check_collisions(result: CheckResult, v: PlanVerifier, poses: JointPoses, q,
                      lines: np.ndarray, segs: Sequence[Segment], si: int, label: str) -> None:
    """Collisions on every line, the clearance on every `CLEARANCE_EVERY_LINES`-th line
    and on every line that collides; a moving limb may touch what it leaves in the first
    half of its segment and what it reaches in the second (`allowed_contacts`)."""
    from planner.verify.check import CLEARANCE_EVERY_LINES, allowed_contacts

    seg = segs[si]
    frac = (lines - seg.first_line) / max(1, seg.last_line - seg.first_line)
    hit = np.zeros(len(lines), dtype=bool)
    clear = np.full(len(lines), np.nan)
    pair: dict[int, str] = {}
    for part in (np.flatnonzero(frac < 0.5), np.flatnonzero(frac >= 0.5)):
        if not len(part):
            continue
        active = v.collision_lines.active(allowed_contacts(segs, si, float(frac[part[0]])))
        wanted = np.flatnonzero((lines[part] - 1) % CLEARANCE_EVERY_LINES == 0)
        out = v.collision_lines.check(poses.subset(part), q.subset(part), active, wanted)
        hit[part], clear[part] = out.hit, out.clearance_m
        pair.update({int(part[i]): p for i, p in out.pair.items()})
    shown = np.flatnonzero(hit | ~np.isnan(clear))
    d = np.nan_to_num(clear[shown], nan=0.0)
    offer_lines(result, lines[shown], -d + hit[shown], d, hit[shown],
                lambda i: f"{label}: {pair.get(int(shown[i])) or 'in collision'}")


def _check_loads(res: dict[str, CheckResult], v: PlanVerifier, lp: LineTorques, q,
                 lines: np.ndarray, si: int, seg: Segment, label: str) -> None:
    """The torque ratio, and every grip's use of its limits: the torque LP's own wrenches
    where it is feasible, else the least use any load share within the joints needs
    (`torque_feasibility`'s ``contact`` objective, line by line: they are few)."""
    from planner.statics.torque_lp import torque_feasibility
    from planner.verify.check import ContactLoad, contact_wrench_utilisation

    names = v.stance_lines(si, seg).joint_names
    feasible = lp.equilibrium & (lp.max_ratio <= 1.0 + 1e-9)
    offer_lines(res["torque ratio"], lines, lp.max_ratio, lp.max_ratio, ~feasible,
                lambda i: f"{label}: worst joint "
                          f"{names[lp.worst_joint[i]] if lp.worst_joint[i] >= 0 else ''}")
    held = v.stance(si, seg)
    use, grip_clause = _grip_use(held.stance.holds, lp)
    fallback: dict[int, ContactLoad] = {}
    for i in np.flatnonzero(~feasible):
        fallback[int(i)] = contact_wrench_utilisation(torque_feasibility(
            v.model, v.data, q[i], held.stance, held.torque_limits, v.frame_id,
            objective="contact"))
        use[i] = fallback[int(i)].value
    offer_lines(res["contact wrench"], lines, use, use, use > 1.0 + 1e-6,
                lambda i: f"{label}: {fallback[i].detail if i in fallback else grip_clause(i)}")


def _grip_use(holds: Sequence[Hold], lp: LineTorques
              ) -> tuple[np.ndarray, Callable[[int], str]]:
    """Per line, the use of the most used grip limit of the LP's wrenches
    (`TorqueCheck.worst_contact` with ``hands_only``: the first hand and limit in order at
    the largest use; 0 when no grip is used), and the report's clause on it for line i
    (`contact_wrench_utilisation`'s)."""
    from planner.verify.check import _grip_clause

    L = len(lp.max_ratio)
    uses, who = [np.zeros((L, 1))], [("", "")]
    for hold in holds:
        if hold.limb in lp.grip_wrench:
            w = lp.grip_wrench[hold.limb]
            uses.append(_utilisation(hold.limits, w[:, :3], w[:, 3:]))
            who += [(hold.limb, load) for load in GRIP_LOADS]
    all_uses = np.hstack(uses)
    best = np.argmax(all_uses, axis=1)  # column 0 (no grip, 0) wins unless one is larger
    use = all_uses[np.arange(L), best]

    def clause(i: int) -> str:
        limb, load = who[best[i]]
        if not limb:
            return "no grip"
        w = lp.grip_wrench[limb][i]
        return _grip_clause(limb, load, use[i], w[:3], w[3:])

    return use, clause


def _utilisation(limits, force: np.ndarray, torque: np.ndarray) -> np.ndarray:
    """(L, 4) `ladders.contact_model.GripCapacity.utilisation` of (L, 3) wrenches, in
    `GRIP_LOADS` order."""
    cap = limits.capacity
    axis = limits.rail_frame()[:, 0]
    fa, ta = force @ axis, torque @ axis
    radial = np.linalg.norm(force - fa[:, None] * axis, axis=1)

    def ratio(load, capacity):
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(capacity > 0.0, load / np.where(capacity > 0.0, capacity, 1.0),
                            np.where(load > 0.0, math.inf, 0.0))

    return np.column_stack([radial / cap.radial_n, ratio(np.abs(fa), cap.along_n(radial)),
                            ratio(np.abs(ta), cap.about_nm(radial)),
                            np.linalg.norm(torque - ta[:, None] * axis, axis=1)
                            / cap.bending_nm])
