"""What holds the planned robot up, for display: support regions and hold forces.

- The support region of each segment (the CoM positions at which the holds that may
  balance the robot keep it in static equilibrium: check-plan's, Bretl–Lall), drawn as a
  polygon at the height of the held feet.
- The planned hold forces: check-plan's torque LP
  (`planner.statics.torque_lp.torque_feasibility`) on the verifier's stance, the force
  each hold applies to the robot at its limb frame, on a decimated set of lines. One LP
  is a few milliseconds, so a whole climb gets at most `MAX_FORCE_LINES` of them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from execute.view.plan_poses import PlanKinematics

__all__ = ["FORCE_EVERY_S", "HoldForces", "MAX_FORCE_LINES", "SupportPolygon",
           "force_rows", "hold_forces", "support_polygon"]

#: Planned hold forces are computed on a line every this long [s] ...
FORCE_EVERY_S = 0.5
#: ... but on at most this many lines of a plan (a DRC climb: one every ~4 s).
MAX_FORCE_LINES = 400


@dataclass(frozen=True, eq=False)
class SupportPolygon:
    """A segment's support region as a closed polygon in the world.

    Attributes:
        segment: the segment's index; vertices_m: (m + 1, 3) the polygon, closed, at
            ``z`` [m] (empty when the stance has no equilibrium).
        limbs: the holds that may balance the robot.
    """

    segment: int
    vertices_m: np.ndarray
    limbs: tuple[str, ...]


@dataclass(frozen=True, eq=False)
class HoldForces:
    """The torque LP's hold forces on one line.

    Attributes:
        row: the line, 0-based.
        limbs: the held limbs; origins_m: (n, 3) their recorded holds [m];
            forces_n: (n, 3) the force each hold applies to the robot, world frame [N].
        max_ratio: the LP's worst |τ|/τmax (inf: no equilibrium within the limits).
    """

    row: int
    limbs: tuple[str, ...]
    origins_m: np.ndarray
    forces_n: np.ndarray
    max_ratio: float


def support_polygon(kin: PlanKinematics, si: int) -> SupportPolygon:
    """Segment ``si``'s support region (the verifier's, on the holds that may balance the
    robot), at the mean height of the segment's held feet (the floor if none)."""
    seg = kin.sidecar.segments[si]
    held = kin.verifier.stance(si, seg)
    feet = [h.position_m[2] for limb, h in seg.holds.items() if limb.endswith("_foot")]
    z = float(np.mean(feet)) if feet else 0.0
    v = held.region.vertices
    closed = np.vstack([v, v[:1]]) if len(v) else np.zeros((0, 2))
    return SupportPolygon(si, np.column_stack([closed, np.full(len(closed), z)]),
                          held.balance_limbs)


def force_rows(line_count: int, rate_hz: float, every_s: float = FORCE_EVERY_S,
               most: int = MAX_FORCE_LINES) -> np.ndarray:
    """The 0-based lines the hold forces are computed on: one every ``every_s``, spread
    wider when that would exceed ``most`` lines."""
    step = max(1, round(every_s * rate_hz), int(np.ceil(line_count / most)))
    return np.arange(0, line_count, step)


def hold_forces(kin: PlanKinematics, rows: np.ndarray) -> list[HoldForces]:
    """The torque LP's hold forces on each of ``rows`` whose base a held foot places."""
    from planner.statics.torque_lp import torque_feasibility

    v = kin.verifier
    out = []
    for row in rows:
        si = int(kin.segment_of_row[row])
        seg = kin.sidecar.segments[si]
        q = v.configuration(kin.trajectory_rad[row], seg)
        if q is None:
            continue
        held = v.stance(si, seg)
        lp = torque_feasibility(v.model, v.data, q, held.stance, held.torque_limits,
                                v.frame_id)
        limbs = tuple(sorted(lp.wrenches)) if lp.equilibrium else ()
        out.append(HoldForces(
            int(row), limbs,
            np.array([seg.holds[limb].position_m for limb in limbs]).reshape(-1, 3),
            np.array([lp.wrenches[limb][0] for limb in limbs]).reshape(-1, 3),
            float(lp.max_ratio)))
    return out
