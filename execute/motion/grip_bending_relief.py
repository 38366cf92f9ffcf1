"""Relief of a closed grip's bending torque, by the compliant arm that holds it.

The planner holds a hand as a point: it plans forces on the rail and no moment
(docs/decisions/contact-model.md). A compliant arm's joints still push the hand with
whatever their PWM law gives at the sensed configuration, and what the wrist cannot give
way to reaches the grip as a moment. Across the rail that moment pries the fingers open
(`ladders.contact_model.GripCapacity.bending_nm`). It peaks where the plan turns a held
wrist through zero pitch: there the wrist's yaw and roll axes line up and the wrist
cannot give way about the third direction.

The bending is estimated from the arm's motor currents (`MotionRobotModel.hand_wrench`,
the estimate `execute.motion.grip_load` reads). While it is above ``onset_share`` of the
capacity, an integral term asks the rail for the opposite moment: a feed-forward
``−Jᵀ(0, Δm)``, ``Δm`` growing at ``gain_per_s`` times the excess. The currents carry
the feed-forward, so the next estimate includes its effect and the term settles where
the bending is back at the onset. Below ``release_share`` the term shrinks at
``decay_nm_per_s``; when the hand stops holding it is dropped. The moment along the rail
is left alone: the grip turns on its rail there, it does not open. ``max_moment_share``
bounds the term; each joint's PWM clamp bounds what it can add.

The feed-forward acts on the shoulder and elbow only. The compliant wrist is what lets
the hand give way to the rail; a feed-forward on its joints holds them instead (on a
zero-pitch crossing it held the wrist pitch back, near the alignment, and the grip let
go). At the alignment the wrist's joints carry no torque for a moment about the
direction they cannot turn about, so the shoulder and elbow alone hold exactly that
moment.

The moment taken off a grip goes to the other holds, the stance legs above all: a moment
``m`` asked of the rail on the palm changes a stance leg joint's torque by ``b·m``, ``b``
the angular part of that joint's column of the sole's Jacobian (the foot taking the
whole reaction, as the leg relief assumes). Each step of the term is projected so that it
raises no stance leg joint already above ``leg_guard_share`` of its torque limit (the
leg relief's onset), and keeps no part along the rail.

What was measured with it, and why it is off by default:
docs/decisions/grip-bending-relief.md.
"""

from __future__ import annotations

import math

import numpy as np

from execute.motion.leg_relief import project_off_cone
from execute.motion.robot_model import MotionRobotModel
from robot.joints import LEG_JOINTS, joint_indices
from robot.limits import joint_limits

__all__ = ["GripBendingRelief"]

#: the arm joints the term's feed-forward acts on (module docstring)
_SHOULDER_AND_ELBOW = ("SP", "SR", "SY", "EB")


class GripBendingRelief:
    """Feed-forward that keeps a compliant gripping arm's bending torque off its grip
    (module docstring).

    Args:
        model: the motion layer's robot model.
        bending_capacity_nm: the bending torque the grip holds [N·m].
        onset_share: share of the capacity above which the term grows [-].
        release_share: share below which it shrinks [-]; two thirds of the onset when
            None.
        gain_per_s: growth of the term per unit of excess bending, per second [1/s].
        decay_nm_per_s: how fast it shrinks below ``release_share`` [N·m/s].
        max_moment_share: bound on the term, as a share of the capacity [-].
        leg_guard_share: share of a stance leg joint's torque limit above which the term
            may not load it further [-].
        robot: robot name (torque limits).
    """

    def __init__(self, model: MotionRobotModel, bending_capacity_nm: float,
                 onset_share: float = 0.35, release_share: float | None = None,
                 gain_per_s: float = 4.0, decay_nm_per_s: float = 2.0,
                 max_moment_share: float = 1.0, leg_guard_share: float = 0.85,
                 robot: str = "drc-hubo"):
        if release_share is None:
            release_share = onset_share * 2.0 / 3.0
        if not 0.0 < release_share < onset_share < 1.0:
            raise ValueError("need 0 < release_share < onset_share < 1")
        self.leg_guard = leg_guard_share
        self.limit_nm = joint_limits(robot).torque_max_nm
        self._leg_cols = {side: np.array(joint_indices(LEG_JOINTS[side]))
                          for side in LEG_JOINTS}
        #: the shoulder and elbow joints of each arm: the term's feed-forward acts on
        #: them alone (module docstring)
        self._proximal_cols = {side: joint_indices([side[0].upper() + j
                                                    for j in _SHOULDER_AND_ELBOW])
                               for side in ("left", "right")}
        self.model = model
        self.capacity_nm = bending_capacity_nm
        self.onset, self.release = onset_share, release_share
        self.gain_per_s = gain_per_s
        self.decay_nm_per_s = decay_nm_per_s
        self.max_moment_nm = max_moment_share * bending_capacity_nm
        #: side → the moment the feed-forward asks of the rail on the palm, world [N·m]
        self.moment_nm: dict[str, np.ndarray] = {}
        #: side → the estimated bending as a share of the capacity, this tick [-]
        self.share: dict[str, float] = {}
        #: sides whose bending has passed the onset and not yet fallen below the release
        self.active: set[str] = set()
        #: the largest term asked so far [N·m]
        self.peak_moment_nm = 0.0

    def update(self, side: str, holding: bool, q_rad: np.ndarray, R_tilt: np.ndarray,
               torque_nm: np.ndarray, rail_axis: np.ndarray, dt_s: float,
               stance_sides: tuple[str, ...] = ()) -> None:
        """One tick of ``side``'s term.

        Args:
            side: ``left`` or ``right``.
            holding: the arm is compliant and its fingers are closed round ``rail_axis``.
            q_rad: encoder positions by column [rad].
            R_tilt: the body's attitude (the estimator's).
            torque_nm: joint torques by column, from the motor currents [N·m].
            rail_axis: the rail's unit direction, world frame.
            dt_s: time since the last tick [s].
            stance_sides: the sides whose feet stand on their holds.
        """
        if not holding:
            self.moment_nm.pop(side, None)
            self.share.pop(side, None)
            self.active.discard(side)
            return
        wrench = self.model.hand_wrench(q_rad, R_tilt, f"{side}_hand", torque_nm)
        moment = wrench[3:]
        bending = moment - float(moment @ rail_axis) * rail_axis
        size = math.sqrt(float(bending @ bending))
        share = size / self.capacity_nm
        self.share[side] = share
        term = self.moment_nm.get(side, np.zeros(3))
        if share > self.onset:
            self.active.add(side)
            excess = bending * (1.0 - self.onset / share)
            step = self._spare_hot_legs(-self.gain_per_s * dt_s * excess, q_rad, R_tilt,
                                        torque_nm, rail_axis, stance_sides)
            term = term + step
        length = math.sqrt(float(term @ term))
        if share < self.release:
            self.active.discard(side)
            if length > 0.0:
                shrunk = max(0.0, length - self.decay_nm_per_s * dt_s)
                term, length = term * (shrunk / length), shrunk
        if length > self.max_moment_nm:
            term, length = term * (self.max_moment_nm / length), self.max_moment_nm
        self.moment_nm[side] = term
        self.peak_moment_nm = max(self.peak_moment_nm, length)

    def _spare_hot_legs(self, step: np.ndarray, q_rad: np.ndarray, R_tilt: np.ndarray,
                        torque_nm: np.ndarray, rail_axis: np.ndarray,
                        stance_sides: tuple[str, ...]) -> np.ndarray:
        """``step`` (a change of the term [N·m], world) projected onto the moments that
        raise no stance leg joint above the guard and have no part along the rail
        (module docstring)."""
        rows = [rail_axis[None, :], -rail_axis[None, :]]
        for leg in stance_sides:
            cols = self._leg_cols[leg]
            hot = cols[np.abs(torque_nm[cols]) > self.leg_guard * self.limit_nm[cols]]
            if len(hot):
                b = self.model.stance_moment_gradient(q_rad, R_tilt, hot, f"{leg}_foot")
                rows.append(np.sign(torque_nm[hot])[:, None] * b)
        loading = np.vstack(rows)
        if len(loading) == 2 or not (loading @ step > 1e-12).any():
            return step
        return project_off_cone(step, loading)

    def feedforward_nm(self, side: str, q_rad: np.ndarray, R_tilt: np.ndarray) -> np.ndarray:
        """Feed-forward torques by column [N·m] that make the rail's moment on ``side``'s
        palm change by its term (zero off that arm, and when no term is on)."""
        term = self.moment_nm.get(side)
        if term is None or not term.any():
            return np.zeros(len(q_rad))
        return self.model.wrench_feedforward_nm(q_rad, R_tilt, f"{side}_hand", np.zeros(3),
                                                term, self._proximal_cols[side])
