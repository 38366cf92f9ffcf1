"""Can this robot climb this ladder at all? A pre-check from the robot's model, in
milliseconds, before the search spends minutes finding out.

Each test is a necessary condition, computed optimistically from the robot's parameter
table and joint limits (`robot.params`, `robot.limits`): a ladder it refuses cannot be
climbed by any plan; a ladder it passes may still fail in the search, which then explains
itself (`planner.failure_report`).

- **Step height.** Two feet stand on consecutive rungs (the floor and rung 0 for the
  mount) with level soles. In the sagittal plane, each sole lies at
  ``hip + thigh·d(φ₁) + shin·d(φ₂) − (0, ankle_to_sole)`` with ``d(φ) = (−sin φ, −cos φ)``,
  ``φ₁ = θ + HP``, ``φ₂ = θ + HP + KN`` and ankle pitch ``AP = −φ₂`` (a level sole), θ the
  pelvis's pitch. Both legs share θ and the hip. Over a grid of θ, HP and KN within their
  limits (AP within its limits), the largest height between the two soles at the
  horizontal offset the rungs have (± a tread's depth and a foot's length, where the
  soles may stand) must reach the rung spacing.
- **Arm span.** Both hands hold their rails at once, so each hand reaches sideways from
  its shoulder by half the rail spacing less half the shoulder width, at most the arm's
  length (shoulder to palm).
- **Foot room.** Both feet stand side by side on one rung: the rung is at least two
  feet wide.

Not tested here, left to the search: knee and shin clearance from the rungs above, the
rails' height, torque and balance.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cache

import numpy as np

from ladders.spec import LadderSpec
from robot.errors import HuboLadderError
from robot.joints import JOINT_INDEX
from robot.limits import joint_limits
from robot.params import RobotParams, robot_params

__all__ = ["LadderOutOfReach", "ReachShortfall", "check_reach", "reach_shortfalls",
           "step_height_reach_m"]

#: Grid of the step-height search: samples of the pelvis pitch, hip pitch and knee.
_PITCH_SAMPLES, _HIP_SAMPLES, _KNEE_SAMPLES = 37, 91, 79
#: Bin width of the soles' horizontal offsets in the step-height search [m].
_X_BIN_M = 0.01


@dataclass(frozen=True)
class ReachShortfall:
    """One thing this robot cannot reach on this ladder.

    Attributes:
        what: the ladder parameter at fault (a spec field name).
        needed: what the ladder asks [m].
        reachable: the most the robot reaches [m].
        message: the reason in a user's words.
    """

    what: str
    needed: float
    reachable: float
    message: str


class LadderOutOfReach(HuboLadderError):
    """The pre-check found the ladder out of this robot's reach (`reach_shortfalls`)."""

    def __init__(self, robot: str, ladder: str, shortfalls: list[ReachShortfall]):
        self.shortfalls = shortfalls
        title = robot_params(robot).title or robot
        super().__init__(f"ladder '{ladder}' is out of the {title}'s reach: "
                         + "; ".join(s.message for s in shortfalls))


@cache
def _sole_offsets(robot: str) -> list[np.ndarray]:
    """Per sampled pelvis pitch, the (n, 2) sagittal (x forward, z up) positions of a
    level sole relative to its hip over the hip-pitch × knee grid within limits [m]."""
    p: RobotParams = robot_params(robot)
    lim = joint_limits(robot)
    i_hp, i_kn, i_ap = JOINT_INDEX["LHP"], JOINT_INDEX["LKN"], JOINT_INDEX["LAP"]
    hp_lo, hp_hi = lim.lower_rad[i_hp], lim.upper_rad[i_hp]
    kn_lo, kn_hi = lim.lower_rad[i_kn], lim.upper_rad[i_kn]
    ap_lo, ap_hi = lim.lower_rad[i_ap], lim.upper_rad[i_ap]
    hp, kn = np.meshgrid(np.linspace(hp_lo, hp_hi, _HIP_SAMPLES),
                         np.linspace(kn_lo, kn_hi, _KNEE_SAMPLES), indexing="ij")
    hp, kn = hp.ravel(), kn.ravel()
    out = []
    for theta in np.linspace(-math.pi / 2, math.pi / 2, _PITCH_SAMPLES):
        phi1, phi2 = theta + hp, theta + hp + kn
        ok = (-phi2 >= ap_lo) & (-phi2 <= ap_hi)
        x = -p.thigh_m * np.sin(phi1[ok]) - p.shin_m * np.sin(phi2[ok])
        z = -p.thigh_m * np.cos(phi1[ok]) - p.shin_m * np.cos(phi2[ok]) - p.ankle_to_sole_m
        out.append(np.column_stack([x, z]))
    return out


def step_height_reach_m(robot: str, dx_lo_m: float = -math.inf,
                        dx_hi_m: float = math.inf) -> float:
    """The highest one level sole reaches above the other while both legs hang from one
    hip, with the upper sole ``dx_lo_m``–``dx_hi_m`` ahead of the lower [m]."""
    best = -math.inf
    for pts in _sole_offsets(robot):
        if len(pts) == 0:
            continue
        bins = np.floor(pts[:, 0] / _X_BIN_M).astype(int)
        lo_bin = bins.min()
        n = bins.max() - lo_bin + 1
        z_max = np.full(n, -np.inf)
        z_min = np.full(n, np.inf)
        np.maximum.at(z_max, bins - lo_bin, pts[:, 1])
        np.minimum.at(z_min, bins - lo_bin, pts[:, 1])
        x = (np.arange(n) + lo_bin + 0.5) * _X_BIN_M
        # upper sole in bin j, lower in bin i: height z_max[j] − z_min[i] at x_j − x_i
        rise = z_max[None, :] - z_min[:, None]
        ahead = x[None, :] - x[:, None]
        ok = (ahead >= dx_lo_m - _X_BIN_M) & (ahead <= dx_hi_m + _X_BIN_M) & np.isfinite(rise)
        if ok.any():
            best = max(best, float(rise[ok].max()))
    return best


def reach_shortfalls(spec: LadderSpec, robot: str = "drc-hubo") -> list[ReachShortfall]:
    """What this robot cannot reach on this ladder (module docstring); empty if nothing
    rules the climb out."""
    p = robot_params(robot)
    title = p.title or robot
    out: list[ReachShortfall] = []

    mount = step_height_reach_m(robot)
    if spec.first_rung_height_m > mount:
        out.append(ReachShortfall(
            "first_rung_height_m", spec.first_rung_height_m, mount,
            f"first rung {spec.first_rung_height_m:.2f} m above the floor: the {title}'s "
            f"hip, knee and ankle limits lift one foot at most {mount:.2f} m above the other"))
    if spec.num_rungs > 1:
        ahead = spec.rung_spacing_m / math.tan(spec.slope_rad)
        room = spec.rung_depth_m + p.foot_length_m
        step = step_height_reach_m(robot, ahead - room, ahead + room)
        if spec.rung_spacing_m > step:
            out.append(ReachShortfall(
                "rung_spacing_m", spec.rung_spacing_m, step,
                f"rungs {spec.rung_spacing_m:.2f} m apart: the {title}'s hip, knee and "
                f"ankle limits lift one foot at most {step:.2f} m above the other when it "
                f"stands {ahead:.2f} m further along, as this ladder's rungs do"))

    arm_m = p.upper_arm_m + p.forearm_m + p.wrist_to_palm_m
    sideways = spec.rail_spacing_m / 2 - p.half_shoulder_width_m
    if sideways > arm_m:
        widest = 2 * (p.half_shoulder_width_m + arm_m)
        out.append(ReachShortfall(
            "rail_spacing_m", spec.rail_spacing_m, widest,
            f"rails {spec.rail_spacing_m:.2f} m apart: the {title}'s hands reach at most "
            f"{arm_m:.2f} m sideways from shoulders {2 * p.half_shoulder_width_m:.2f} m "
            f"apart, so both rails at once at most {widest:.2f} m apart"))

    two_feet = 2 * p.foot_width_m
    if spec.rung_width_m < two_feet:
        out.append(ReachShortfall(
            "rung_width_m", spec.rung_width_m, two_feet,
            f"rungs {spec.rung_width_m:.2f} m wide: the {title}'s two feet side by side "
            f"need at least {two_feet:.2f} m"))
    return out


def check_reach(spec: LadderSpec, robot: str = "drc-hubo") -> None:
    """Raise `LadderOutOfReach` if the pre-check rules the climb out."""
    shortfalls = reach_shortfalls(spec, robot)
    if shortfalls:
        raise LadderOutOfReach(robot, spec.name, shortfalls)
