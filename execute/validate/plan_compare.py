"""What the plan expected against what the simulation did, at the line a run ended on.

A failed run says what broke (a board tripped, a grip let go); this says how the physics
had drifted from the plan by then. The plan side is check-plan's own account of the line
(`planner.verify.check.planned_loads`): the body placed from a held foot, and the torque
LP's joint torques and contact forces. The simulation side is the board model's state at
the end of the run, which is the failure's instant when the run stops on failure (the
default), with the joint torques of the tick before (a board that tripped reports
none). Joints are ranked by how far their torque is from the plan's, as a share of
their limit: the closed chain of hands and feet is statically indeterminate, so the LP
picks one load share and the robot's compliance another, and the joints where the two
part most are usually where the run broke (DRC seed 1 at 81.1 s: the left hip pitch at
12 N·m against 35 planned, the left foot pushed sideways with 111 N against 31).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np

from daemon.sim.board_model import TICK_S
from ladders.contact_model import HandLimits
from ladders.geometry import LadderGeometry
from robot.joints import FINGER_JOINTS, JOINT_INDEX
from robot.limits import joint_limits
from robot.vocabulary import Limb

__all__ = ["GripAgreement", "JointLoad", "PlanComparison", "compare_with_plan", "grip_agreement",
           "planned_torque_history"]

FINGERS = frozenset(n for hand in FINGER_JOINTS.values() for n in hand)
#: How many joints the comparison lists (the largest departures from the plan).
JOINTS_LISTED = 6


@dataclass(frozen=True)
class JointLoad:
    """One joint's torque in the plan and in the simulation [N·m], and its limit [N·m]."""

    joint: str
    planned_nm: float
    simulated_nm: float
    limit_nm: float

    @property
    def departure(self) -> float:
        """|simulated − planned| as a share of the limit."""
        return abs(self.simulated_nm - self.planned_nm) / self.limit_nm


@dataclass(frozen=True, eq=False)
class PlanComparison:
    """Plan against simulation at one line.

    Attributes:
        line: the line compared (1-based); time_s: simulated time [s].
        pelvis_offset_m: simulated − planned root position, world frame [m].
        pelvis_turn_rad: angle between the planned and the simulated root orientation.
        joints: the joints whose torque departs most from the plan, largest first.
        hold_forces_n: per held limb, (planned, simulated) total force the environment
            applies to it, world frame [N]; simulated is None for a hand whose grip is
            not latched.
        planned_worst_ratio: the LP's worst |τ|/τmax at this line.
        grips: per segment and held hand, planned against simulated grip load
            (`grip_agreement`).
    """

    line: int
    time_s: float
    pelvis_offset_m: np.ndarray
    pelvis_turn_rad: float
    joints: tuple[JointLoad, ...]
    hold_forces_n: dict[str, tuple[np.ndarray, np.ndarray | None]]
    planned_worst_ratio: float
    grips: tuple[GripAgreement, ...] = ()

    def summary(self) -> str:
        """One clause for the verdict's explanation."""
        worst = ", ".join(f"{j.joint} {j.simulated_nm:+.1f} N·m (plan {j.planned_nm:+.1f})"
                          for j in self.joints[:3])
        return (f"at line {self.line} against the plan: {worst}; body "
                f"{100 * np.linalg.norm(self.pelvis_offset_m):.1f} cm and "
                f"{math.degrees(self.pelvis_turn_rad):.1f}° off")

    def to_json(self) -> dict[str, Any]:
        def vec(v):
            return None if v is None else [round(float(x), 2) for x in v]

        return {
            "line": self.line,
            "time_s": round(self.time_s, 3),
            "pelvis_offset_m": [round(float(x), 4) for x in self.pelvis_offset_m],
            "pelvis_turn_deg": round(math.degrees(self.pelvis_turn_rad), 2),
            "planned_worst_ratio": round(self.planned_worst_ratio, 4),
            "joints": [{"joint": j.joint, "planned_nm": round(j.planned_nm, 2),
                        "simulated_nm": round(j.simulated_nm, 2), "limit_nm": j.limit_nm}
                       for j in self.joints],
            "hold_forces_n": {limb: {"planned": vec(p), "simulated": vec(s)}
                              for limb, (p, s) in self.hold_forces_n.items()},
            "grips_by_segment": [g.to_json() for g in self.grips],
            "grip_departure_median": (None if not self.grips else round(float(
                np.median([g.departure for g in self.grips])), 3)),
        }


@dataclass(frozen=True)
class GripAgreement:
    """A held hand's planned against simulated grip load in one segment, each of
    `ladders.contact_model.GRIP_LOADS` as a share of the grip's whole capacity.

    Attributes:
        segment: the sidecar segment's index; label: its primitive/phase.
        limb: the hand; line: the line compared (the latch's sample nearest the
            segment's middle); time_s: the sample's simulated time [s].
        planned, simulated: load → share of its limit (check-plan's LP; the latch's
            `grip_load`).
    """

    segment: int
    label: str
    limb: str
    line: int
    time_s: float
    planned: dict[str, float]
    simulated: dict[str, float]

    @property
    def departure(self) -> float:
        """max |simulated − planned| over the loads, as a share of the limit."""
        return max(abs(self.simulated[k] - self.planned[k]) for k in self.planned)

    def to_json(self) -> dict[str, Any]:
        return {"segment": self.segment, "label": self.label, "limb": self.limb,
                "line": self.line, "time_s": round(self.time_s, 2),
                "planned": {k: round(v, 3) for k, v in self.planned.items()},
                "simulated": {k: round(v, 3) for k, v in self.simulated.items()},
                "departure": round(self.departure, 3)}


def grip_agreement(run, trajectory_rad: np.ndarray, ladder, verifier=None
                   ) -> tuple[GripAgreement, ...]:
    """Per segment and held hand, the plan's grip load (check-plan's torque LP, the
    contact model's limits) against the latch's (`GraspLatch.load_history`), at the
    latch's sample nearest the segment's middle."""
    from planner.verify.check import planned_loads

    log = run.log
    picks = []  # (segment, limb, line, time, force, torque)
    for k, seg in enumerate(run.sidecar.segments):
        for limb in seg.holds:
            if not Limb(limb).is_hand:
                continue
            hist = run.board.latches[Limb(limb).side].load_history
            best = None
            mid = 0.5 * (seg.first_line + seg.last_line)
            for t, f, tq in hist:
                i = min(int(np.searchsorted(log.time_s, t)), len(log.time_s) - 1)
                line = int(log.line_index[i]) + 1
                if seg.first_line <= line <= seg.last_line and (
                        best is None or abs(line - mid) < abs(best[0] - mid)):
                    best = (line, t, f, tq)
            if best is not None:
                picks.append((k, limb, *best))
    if not picks:
        return ()
    axis = LadderGeometry(ladder).ladder_direction
    plans = planned_loads(trajectory_rad, run.sidecar, ladder, [p[2] for p in picks],
                          run.board.robot, verifier)
    out = []
    for (k, limb, line, t, f, tq), plan in zip(picks, plans, strict=True):
        if plan.torque is None or not plan.torque.equilibrium:
            continue
        planned = plan.torque.contact_use.get(limb)
        if planned is None:
            continue
        # the latch's capacity is the contact model's; the rail runs up the rung line
        lim = HandLimits(run.board.latches[limb.removesuffix("_hand")].capacity, axis)
        seg = run.sidecar.segments[k]
        out.append(GripAgreement(k, f"{seg.primitive}/{seg.phase}", limb, line, t, planned,
                                 lim.utilisation(f, tq)))
    return tuple(out)


def _body_contact_force(model: mujoco.MjModel, data: mujoco.MjData, body: int) -> np.ndarray:
    """Total contact force on ``body`` from everything it touches, world frame [N]."""
    total = np.zeros(3)
    f6 = np.zeros(6)
    for i in range(data.ncon):
        c = data.contact[i]
        b1, b2 = model.geom_bodyid[c.geom1], model.geom_bodyid[c.geom2]
        if body not in (b1, b2):
            continue
        mujoco.mj_contactForce(model, data, i, f6)
        f_world = c.frame.reshape(3, 3).T @ f6[:3]  # on geom2, along the normal 1 → 2
        total += f_world if b2 == body else -f_world
    return total


def compare_with_plan(run, trajectory_rad: np.ndarray, ladder, verifier=None
                      ) -> PlanComparison | None:
    """Compare the end of ``run`` (an `execute.validate.simulate.SimulationRun`) with the plan's
    account of its line; None when the plan places no body there (no foot held).
    ``verifier``: the plan's `planner.verify.check.PlanVerifier`, built here if None."""
    from planner.verify.check import plan_verifier, planned_loads

    board, sidecar = run.board, run.sidecar
    verifier = verifier or plan_verifier(sidecar, ladder, board.robot)
    line = int(run.log.line_index[-1]) + 1
    plan = planned_loads(trajectory_rad, sidecar, ladder, [line], board.robot, verifier)[0]
    if plan.torque is None or not plan.torque.equilibrium:
        return None
    m, d = board.model, board.data
    R_sim = np.zeros(9)
    mujoco.mju_quat2Mat(R_sim, d.qpos[3:7])
    R_rel = plan.base_pose[:3, :3].T @ R_sim.reshape(3, 3)
    turn = math.acos(float(np.clip((np.trace(R_rel) - 1.0) / 2.0, -1.0, 1.0)))
    # The tick before the last: a board that tripped on the last one reports no torque.
    tau_sim = run.log.torque_nm[max(len(run.log.torque_nm) - 2, 0)]
    tmax = joint_limits(board.robot).torque_max_nm
    # Fingers are not the LP's: a closed hand's fingers press its rail at their own limit.
    loads = [JointLoad(n, float(plan.torque.torques_nm[k]),
                       float(tau_sim[JOINT_INDEX[n]]), float(tmax[JOINT_INDEX[n]]))
             for k, n in enumerate(plan.torque.joint_names)
             if n in JOINT_INDEX and tmax[JOINT_INDEX[n]] > 0 and n not in FINGERS]
    loads.sort(key=lambda j: j.departure, reverse=True)
    holds: dict[str, tuple[np.ndarray, np.ndarray | None]] = {}
    for limb, f in plan.torque.forces_n.items():
        side = Limb(limb).side
        if Limb(limb).is_hand:
            latch = board.latches[side]
            sim = latch.grip_load()[0] if latch.latched else None
        else:
            body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f"{side[0].upper()}_foot")
            sim = _body_contact_force(m, d, body)
        holds[limb] = (f.sum(axis=0), sim)
    return PlanComparison(line, board.time_s, d.qpos[:3] - plan.base_pose[:3, 3], turn,
                          tuple(loads[:JOINTS_LISTED]), holds, plan.torque.max_ratio,
                          grip_agreement(run, trajectory_rad, ladder, verifier))


def planned_torque_history(run, trajectory_rad: np.ndarray, ladder, joints: list[str],
                           every_s: float = 0.5, verifier=None
                           ) -> tuple[np.ndarray, np.ndarray]:
    """The plan's torques of ``joints`` along the run, for plotting against the
    simulation's: (times [s], torques (k, len(joints)) [N·m]), a line every ``every_s``
    of the run (NaN where the plan places no body)."""
    from planner.verify.check import planned_loads

    log = run.log
    ticks = np.arange(0, len(log.time_s), max(1, round(every_s / TICK_S)))
    lines = [int(log.line_index[k]) + 1 for k in ticks]
    torques = np.full((len(ticks), len(joints)), np.nan)
    for row, plan in enumerate(planned_loads(trajectory_rad, run.sidecar, ladder, lines,
                                             run.board.robot, verifier)):
        if plan.torque is not None and plan.torque.equilibrium:
            torques[row] = [plan.torque.torque(n) for n in joints]
    return log.time_s[ticks], torques
