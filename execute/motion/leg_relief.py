"""Leg relief: the gripping compliant arms lift more of the body while a stance leg's
joint pushes near its torque limit.

The plan shares the body's weight between the feet and the hands (the torque LP), and the
compliant arms give their share through their feed-forward. On the robot they give it
only roughly: their PWM stiffness towards the reference, the rigid wrist roll and the
grip's slip about its rail change the wrench the hand delivers, and a position-controlled
leg takes whatever the arms do not. On a one-foot stance the knee then climbs past its
limit and its board trips (a stair mount: planned 48 N·m, 60 N·m in MuJoCo).

The motor current says how hard each leg joint pushes (``τ = η·gear·Kt·I``,
`robot.motors.MotorTable.torque_nm`, which the motion layer applies once a tick). The
joints watched are those that carry the body's weight on the leg, the knee and the hip
pitch (`WEIGHT_JOINTS`). The ankles' and hip rolls' torques say where the foot's centre
of pressure and the body's roll sit; the hand push that would unload them is mostly
horizontal and bends the grip (DRC seed 4: an ankle-pitch relief at 272 s, then the right
grip bent open at 292 s). While the largest share of its limit over the stance legs'
watched joints is above ``onset_fraction``, the hands' extra lift grows at
``rate_n_per_s``; below ``release_fraction`` it shrinks at that rate; it is bounded by
``max_lift_n``. The lift is a force of the rail on each gripping compliant hand, split
evenly, sent as feed-forward torques ``−Jᵀ f`` on the arm's compliant joints at the
sensed configuration and the IMU's tilt; each arm's PWM clamp (the daemon's) bounds what
it can add.

Its direction is the one that unloads the joint that called for it fastest, per newton:
the stance foot takes the reaction, so the joint's torque changes along
`MotionRobotModel.stance_torque_gradient`. A hand never pushes the body down (the
direction's downward part is dropped): that would load the feet. A vertical lift alone
did not relieve knees on `ship`, where the knee's lever is mostly horizontal
(docs/decisions/leg-relief.md).

Nor may the push load another joint of that leg that is already loaded (above
``guard_fraction`` of its limit) further: on a DRC mount (S21, seed 1) the 80 N that held
the left knee at 0.76–0.89 of its limit on one foot drove the left hip yaw from 0.05 to
0.99 of its limit in 8 s, and its board tripped. The direction is then the projection of
the fastest one onto the cone of pushes that load none of them (and do not push down):
the least change from it that the guard allows, found as a non-negative least-squares
problem on the cone's polar (Moreau). A hand with no such push adds nothing.

Nor may the lift pry a grip open. The push's reaction goes through the body to every
hand on a rail, rigid ones too: on a DRC mount (S25, seed 14) 80 N on the compliant left
arm, with the left knee at 0.84–0.89 of its limit, bent the rigid right hand's grip from
0.13 to 1.0 of what it holds in 5 s, and it let go; with at most 40 N, or none, the knee
stayed below its limit and the grip held. The grips' loads are estimated from sensors
(`execute.motion.grip_load`); while the largest is above ``grip_fraction`` of what the
grip holds, the lift does not grow and shrinks at ``rate_n_per_s``, until the largest is
back below ``grip_release_fraction`` (hysteresis: a grip near the bound would otherwise
switch it every few ticks).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.optimize import nnls

from execute.motion.robot_model import MotionRobotModel
from robot.joints import JOINT_NAMES, LEG_JOINTS, joint_indices
from robot.limits import joint_limits

__all__ = ["WEIGHT_JOINTS", "LegRelief", "project_off_cone"]

#: Per leg, the joints whose load is the body's weight on it (module docstring).
WEIGHT_JOINTS = {"left": ("LHP", "LKN"), "right": ("RHP", "RKN")}
#: Downward: the push's direction never has a part along it (module docstring).
_DOWN = np.array([[0.0, 0.0, -1.0]])


def project_off_cone(vector: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """The nearest vector to ``vector`` (3,) with no positive part along any of ``rows``
    (k, 3): its projection onto the cone's polar, ``vector`` less its projection onto the
    cone the rows span (non-negative least squares)."""
    cone = rows.T
    return vector - cone @ nnls(cone, vector)[0]


class LegRelief:
    """The hands' extra lift from the stance legs' sensed torques (module docstring).

    Args:
        model: the motion layer's robot model.
        robot: robot name (torque limits).
        onset_fraction: share of a leg joint's limit above which the lift grows.
        release_fraction: share below which it shrinks (hysteresis).
        rate_n_per_s: how fast it grows or shrinks [N/s].
        max_lift_n: the largest extra lift of all hands together [N].
        guard_fraction: share of its limit above which another joint of the relieved
            leg may not be loaded further by the push.
        grip_fraction: share of what a grip holds above which the lift gives way.
        grip_release_fraction: share below which it may grow again.
    """

    def __init__(self, model: MotionRobotModel, robot: str = "drc-hubo",
                 onset_fraction: float = 0.85, release_fraction: float = 0.75,
                 rate_n_per_s: float = 40.0, max_lift_n: float = 80.0,
                 guard_fraction: float = 0.6, grip_fraction: float = 0.5,
                 grip_release_fraction: float = 0.4):
        self.model = model
        self.limit_nm = joint_limits(robot).torque_max_nm
        self._leg_cols = {side: np.array(joint_indices(WEIGHT_JOINTS[side]))
                          for side in WEIGHT_JOINTS}
        self._guard_cols = {f"{side}_foot": np.array(joint_indices(LEG_JOINTS[side]))
                            for side in LEG_JOINTS}
        self.guard_fraction = guard_fraction
        self.grip_fraction, self.grip_release = grip_fraction, grip_release_fraction
        self.onset, self.release = onset_fraction, release_fraction
        self.rate_n_per_s, self.max_lift_n = rate_n_per_s, max_lift_n
        self.lift_n = 0.0
        #: The largest lift of the run [N] and the leg joint that called for it.
        self.peak_lift_n = 0.0
        self.peak_joint = ""
        #: The leg joint the lift relieves: its column, the sign of its torque and its
        #: leg's foot (the limb that takes the push's reaction).
        self.joint_col, self.joint_sign, self.joint_foot = -1, 0.0, ""
        #: The last tick's largest |τ|/limit over the stance legs' watched joints.
        self.load_share = 0.0
        #: Whether the last tick's grips were too loaded for the lift to grow.
        self.grip_bound = False

    def _leg_load(self, stance_sides: Sequence[str], torque_nm: np.ndarray
                  ) -> tuple[float, int, str]:
        """The largest |τ|/limit over the stance legs' watched joints, its column and its
        leg."""
        share, col, side = 0.0, -1, ""
        for leg in stance_sides:
            cols = self._leg_cols[leg]
            shares = np.abs(torque_nm[cols]) / self.limit_nm[cols]
            k = int(np.argmax(shares))
            if shares[k] > share:
                share, col, side = float(shares[k]), int(cols[k]), leg
        return share, col, side

    def needs_grip_share(self, stance_sides: Sequence[str], torque_nm: np.ndarray) -> bool:
        """Whether the next `update` may lift: a lift is on, or a stance leg's watched
        joint is past the onset. Only then does the grips' load matter (estimating it
        costs an arm Jacobian and a least-squares solve per grip, each tick)."""
        return self.lift_n > 0.0 or self._leg_load(stance_sides, torque_nm)[0] > self.onset

    def update(self, stance_sides: Sequence[str], can_lift: bool, torque_nm: np.ndarray,
               dt_s: float, grip_share: float = 0.0) -> float:
        """The lift after one tick [N]. ``can_lift``: a compliant hand grips a rail;
        ``torque_nm``: the sensed joint torques by column [N·m]; ``grip_share``: the
        largest estimated load of a closed grip, as a share of what it holds (0 when
        `needs_grip_share` is false: the bound is judged only while a lift is on or
        would start)."""
        share, col, side = self._leg_load(stance_sides, torque_nm)
        self.load_share = share
        self.grip_bound = grip_share > (self.grip_release if self.grip_bound
                                        else self.grip_fraction)
        if can_lift and share > self.onset and not self.grip_bound:
            self.joint_col, self.joint_foot = col, f"{side}_foot"
            self.joint_sign = float(np.sign(torque_nm[col]))
            self.lift_n = min(self.max_lift_n, self.lift_n + self.rate_n_per_s * dt_s)
            if self.lift_n > self.peak_lift_n:
                self.peak_lift_n, self.peak_joint = self.lift_n, JOINT_NAMES[col]
        elif share < self.release or not can_lift or self.grip_bound:
            self.lift_n = max(0.0, self.lift_n - self.rate_n_per_s * dt_s)
        return self.lift_n

    def direction(self, q_sensed_rad: np.ndarray, R_tilt: np.ndarray, foot: str,
                  hand: str, torque_nm: np.ndarray) -> np.ndarray:
        """Unit direction (world) of the rail's push on ``hand`` that unloads the relieved
        joint fastest, without a downward part and without loading another joint of
        ``foot``'s leg above ``guard_fraction`` of its limit (``torque_nm``: the sensed
        torques by column [N·m]); straight up if the fastest has only a downward part,
        zero if the guard leaves no push."""
        cols = self._guard_cols[foot]
        guarded = cols[(cols != self.joint_col)
                       & (np.abs(torque_nm[cols]) > self.guard_fraction * self.limit_nm[cols])]
        # one Jacobian for the relieved joint's gradient and the guarded joints'
        gradients = self.model.stance_torque_gradient(
            q_sensed_rad, R_tilt, np.r_[self.joint_col, guarded], foot, hand)
        fastest = -self.joint_sign * gradients[0]
        d = fastest.copy()
        d[2] = max(d[2], 0.0)
        if len(guarded):
            # each row: the growth of one guarded joint's |τ| per unit push
            loading = np.sign(torque_nm[guarded])[:, None] * gradients[1:]
            if (loading @ d > 0.0).any():
                d = project_off_cone(fastest, np.vstack([loading, _DOWN]))
                if float(np.linalg.norm(d)) <= 1e-6 * float(np.linalg.norm(fastest)):
                    return np.zeros(3)
        length = float(np.linalg.norm(d))
        return d / length if length > 1e-9 else np.array([0.0, 0.0, 1.0])

    def feedforward_nm(self, sides: list[str], q_sensed_rad: np.ndarray,
                       R_tilt: np.ndarray, torque_nm: np.ndarray) -> np.ndarray:
        """Feed-forward torques by column [N·m] that make the rail push each hand of
        ``sides`` by its share of the lift, along `direction` (zero off their arms);
        ``torque_nm``: the sensed joint torques by column [N·m]."""
        out = np.zeros(len(q_sensed_rad))
        if self.lift_n <= 0.0 or not sides or self.joint_col < 0:
            return out
        for side in sides:
            direction = self.direction(q_sensed_rad, R_tilt, self.joint_foot, f"{side}_hand",
                                       torque_nm)
            out += self.model.wrench_feedforward_nm(q_sensed_rad, R_tilt, f"{side}_hand",
                                                    direction * (self.lift_n / len(sides)))
        return out
