"""Did the robot climb? Online failure checks and the final-stance check of a simulation.

Failure, checked every tick (the first one ends the run):

- **fall**: pelvis below ``min_pelvis_height_m`` or its z axis more than ``max_tilt_rad``
  from vertical. 0.5 m is half the standing pelvis height (0.968 m): the robot has
  sat down or fallen; 45° of tilt is far beyond any statically stable climbing pose.
- **hard contact**: a robot body other than a foot or a hand touches the ladder or the
  floor with a normal force above ``hard_contact_fraction`` of the robot's weight (25 %
  ≈ 109 N for DRC-Hubo: more than a brush, the robot is leaning on something the plan
  did not put there).
- **board trip**: any board (`daemon.sim.board_trip`).
- **grasp not latched**: a segment holds a hand on a rail and, ``latch_grace_s`` after
  the segment started, that hand is not latched to that rail (1 s: the daemon's
  reference filter needs ≈ 0.6 s to bring fingers to 95 % of a step).
- **grasp lost**: a hand latched on a rail it must hold lets go (slip, trip, opening).

Success, after the last line plus ``settle_s``: every final hold is in contact — a foot's
sole within ``sole_tolerance_m`` of its planned position (moved with the ladder when the
ladder is misplaced and the hold is on it) and touching its target geom; a hand latched
on its planned rail.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import mujoco
import numpy as np

from robot.constants import GRAVITY_M_S2
from robot.plan_sidecar import HoldRecord, PlanSidecar
from robot.vocabulary import FailureCause, HoldTargetKind, Limb

__all__ = ["Failure", "Verdict", "VerdictConfig", "VerdictMonitor", "default_config"]


@dataclass(frozen=True)
class VerdictConfig:
    """Thresholds of the verdict (see the module docstring for the reasons)."""

    min_pelvis_height_m: float = 0.5
    max_tilt_rad: float = math.radians(45.0)
    hard_contact_fraction: float = 0.25
    latch_grace_s: float = 1.0
    sole_tolerance_m: float = 0.03
    settle_s: float = 1.0


def default_config() -> VerdictConfig:
    return VerdictConfig()


@dataclass(frozen=True)
class Failure:
    """Why a run failed: ``cause`` (a `robot.vocabulary.FailureCause`; ``grasp_unverified``:
    the motion layer could not confirm a grasp and held the pose), when, on which line, and
    a sentence with the physical quantities behind it."""

    cause: FailureCause
    time_s: float
    line: int
    why: str
    details: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        object.__setattr__(self, "cause", FailureCause(self.cause))  # a str: checked here


@dataclass(frozen=True)
class Verdict:
    climbed: bool
    failure: Failure | None
    final_holds: dict[str, str]  # limb → "ok" or what is wrong

    def __repr__(self) -> str:
        if self.climbed:
            return "Verdict(climbed)"
        f = self.failure
        return f"Verdict(failed: {f.cause} at t = {f.time_s:.2f} s, line {f.line}: {f.why})"


class VerdictMonitor:
    """Applies the checks to a `daemon.sim.board_model.BoardModel` as it runs.

    Args:
        board: the board model (its MuJoCo model/data, latches and trips are read).
        sidecar: the plan's sidecar (holds per segment, final holds).
        T_err: 4×4 world transform of the ladder's misplacement (identity if none);
            planned positions on the ladder move with it.
        config: thresholds.
    """

    def __init__(self, board, sidecar: PlanSidecar, T_err: np.ndarray,
                 config: VerdictConfig | None = None):
        self.board = board
        self.sidecar = sidecar
        self.T_err = T_err
        self._segment_entry: tuple[int, float] = (-1, 0.0)  # (first line, time entered)
        self.config = config or default_config()
        m = board.model
        self.model, self.data = m, board.data
        self.pelvis = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "pelvis")
        mass_kg = float(sum(m.body_mass[board.model.body_rootid == self.pelvis]))
        self.weight_n = mass_kg * GRAVITY_M_S2
        ladder = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "ladder")
        self.env_geoms = {g for g in range(m.ngeom)
                          if m.geom_bodyid[g] in (0, ladder)}
        allowed = set()
        for b in range(m.nbody):
            name = m.body(b).name
            if name.endswith("_foot") or name.endswith("_hand") or "_finger" in name:
                allowed.add(b)
        self.allowed_bodies = allowed
        self._force = np.zeros(6)
        self.peak_bad_contact: tuple[float, str, str] = (0.0, "", "")

    # ------------------------------------------------------------------ positions
    def planned_position(self, hold: HoldRecord) -> np.ndarray:
        p = np.asarray(hold.position_m, dtype=float)
        if hold.target == "floor":
            return p
        return self.T_err[:3, :3] @ p + self.T_err[:3, 3]

    def _sole(self, limb: str) -> np.ndarray:
        return self.data.site(f"{Limb(limb).side[0].upper()}_sole").xpos.copy()

    def _touching(self, limb: str, target: str) -> bool:
        m, d = self.model, self.data
        side = Limb(limb).side[0].upper()
        body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, f"{side}_foot")
        for i in range(d.ncon):
            c = d.contact[i]
            g1, g2 = int(c.geom1), int(c.geom2)
            for a, b in ((g1, g2), (g2, g1)):
                if m.geom_bodyid[a] == body and m.geom(b).name == target:
                    return True
        return False

    # ------------------------------------------------------------------ per tick
    def check(self, time_s: float, line_index: int, trips, grasps,
              holds: bool = True) -> Failure | None:
        """Checks after one tick; the first failure found, or None. ``holds``: check the
        plan's holds at ``line_index`` too (False while the robot plays something other
        than the plan's lines: trips, falls and hard contacts only)."""
        line = line_index + 1
        if trips:
            ev = trips[0]
            extra = ""
            if ev.board in ("EJMC4", "EJMC5"):
                extra = ("; it shares the board with that hand's fingers, so the hand "
                         "lost its grip")
            return Failure(FailureCause.BOARD_TRIP, time_s, line, str(ev) + extra,
                           {"board": ev.board, "joint": ev.joint,
                            "torque_limit_nm": ev.torque_limit_nm,
                            "peak_torque_nm": ev.peak_torque_nm,
                            "threshold_nm": ev.threshold_nm,
                            "overload_s": ev.overload_s})
        d = self.data
        z = float(d.xpos[self.pelvis][2])
        tilt = math.acos(min(max(float(d.xmat[self.pelvis][8]), -1.0), 1.0))
        if z < self.config.min_pelvis_height_m or tilt > self.config.max_tilt_rad:
            return Failure(FailureCause.FALL, time_s, line,
                           f"pelvis at {z:.2f} m (limit {self.config.min_pelvis_height_m} m), "
                           f"tilted {math.degrees(tilt):.0f}° (limit "
                           f"{math.degrees(self.config.max_tilt_rad):.0f}°)",
                           {"pelvis_height_m": z, "tilt_deg": math.degrees(tilt)})
        bad = self._hard_contact()
        if bad is not None:
            f, body, geom = bad
            return Failure(FailureCause.HARD_CONTACT, time_s, line,
                           f"{body} hit {geom} with {f:.0f} N (limit "
                           f"{self.config.hard_contact_fraction * self.weight_n:.0f} N, "
                           f"{self.config.hard_contact_fraction:.0%} of the robot's weight)",
                           {"body": body, "geom": geom, "force_n": f})
        if not holds:
            return None
        seg = self.sidecar.segment_at(line)
        for g in grasps:
            if g.kind == "released":
                limb = f"{g.hand}_hand"
                hold = seg.holds.get(limb)
                if hold is not None and hold.target == g.rail:
                    return Failure(FailureCause.GRASP_LOST, time_s, line,
                                   f"{g.hand} hand let go of {g.rail}: {g.reason}",
                                   {"hand": g.hand, "rail": g.rail, "reason": g.reason})
        if self._segment_entry[0] != seg.first_line:
            self._segment_entry = (seg.first_line, time_s)  # played lines, pauses counted
        if time_s - self._segment_entry[1] >= self.config.latch_grace_s:
            for limb, hold in seg.holds.items():
                if not (Limb(limb).is_hand and hold.hold_target.kind is HoldTargetKind.RAIL):
                    continue
                f = self._latch_failure(limb, hold, time_s, line)
                if f is not None:
                    return f
        return None

    def _latch_failure(self, limb: str, hold: HoldRecord, time_s: float,
                       line: int) -> Failure | None:
        latch = self.board.latches[Limb(limb).side]
        if latch.latched and latch.rail == hold.target:
            return None
        dist, ang = latch.palm_to_rails()[hold.target]
        planned = self.planned_position(hold)
        palm = self.data.site_xpos[latch.palm_site]
        miss = float(np.linalg.norm(palm - planned))
        state = latch.state.value
        why = (f"{Limb(limb).side} hand is {state}, not latched on {hold.target}: palm "
               f"{dist * 100:.1f} cm from the rail axis (tolerance "
               f"{latch.config.position_tolerance_m * 100:.0f} cm), grip axis "
               f"{math.degrees(ang):.0f}° off, {miss * 100:.1f} cm from the planned grasp")
        return Failure(FailureCause.GRASP_NOT_LATCHED, time_s, line, why,
                       {"hand": Limb(limb).side, "rail": hold.target,
                        "palm_to_axis_m": dist, "grip_angle_deg": math.degrees(ang),
                        "palm_to_plan_m": miss, "hand_state": state})

    def _hard_contact(self) -> tuple[float, str, str] | None:
        m, d = self.model, self.data
        limit = self.config.hard_contact_fraction * self.weight_n
        worst = None
        for i in range(d.ncon):
            c = d.contact[i]
            g1, g2 = int(c.geom1), int(c.geom2)
            if g1 in self.env_geoms:
                env, rob = g1, g2
            elif g2 in self.env_geoms:
                env, rob = g2, g1
            else:
                continue
            body = int(m.geom_bodyid[rob])
            if body in self.allowed_bodies or rob in self.env_geoms:
                continue
            mujoco.mj_contactForce(m, d, i, self._force)
            f = abs(float(self._force[0]))
            if f > self.peak_bad_contact[0]:
                self.peak_bad_contact = (f, m.body(body).name, m.geom(env).name)
            if f > limit and (worst is None or f > worst[0]):
                worst = (f, m.body(body).name, m.geom(env).name or "floor")
        return worst

    # ------------------------------------------------------------------ the end
    def final(self, time_s: float, line_index: int) -> Verdict:
        """The final-stance check (after the last line has been held ``settle_s``)."""
        status: dict[str, str] = {}
        for limb, hold in self.sidecar.final_holds.items():
            if limb.endswith("_hand"):
                latch = self.board.latches[Limb(limb).side]
                if latch.latched and latch.rail == hold.target:
                    status[limb] = "ok"
                else:
                    dist, _ = latch.palm_to_rails().get(hold.target, (float("nan"), 0))
                    status[limb] = (f"not latched on {hold.target} ({latch.state.value}, "
                                    f"palm {dist * 100:.1f} cm from its axis)")
                continue
            err = float(np.linalg.norm(self._sole(limb) - self.planned_position(hold)))
            touching = self._touching(limb, hold.target)
            if err <= self.config.sole_tolerance_m and touching:
                status[limb] = "ok"
            else:
                status[limb] = (f"sole {err * 100:.1f} cm from its planned hold on "
                                f"{hold.target} (tolerance "
                                f"{self.config.sole_tolerance_m * 100:.0f} cm), "
                                f"{'touching' if touching else 'not touching'} it")
        bad = {k: v for k, v in status.items() if v != "ok"}
        if bad:
            why = "final stance not reached: " + "; ".join(f"{k} {v}" for k, v in bad.items())
            return Verdict(False, Failure(FailureCause.FINAL_STANCE, time_s, line_index + 1, why,
                                          {"holds": status}), status)
        return Verdict(True, None, status)
