"""The motion layer's robot model: pinocchio on the robot's own URDF.

What hubo-motion-rt computed from the robot description (thesis §4.3.4): gravity torques
by recursive Newton–Euler at a given configuration and body tilt, frame poses by forward
kinematics, and small limb corrections by damped least squares on one limb's chain.

Everything here takes the 40 file columns (`robot.joints.JOINT_NAMES` order) and a
pelvis pose, so callers never handle pinocchio's configuration layout.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from robot.joints import ARM_JOINTS, JOINT_NAMES, LEG_JOINTS
from robot.params import robot_params
from robot.urdf import robot_urdf

__all__ = ["LimbChain", "MotionRobotModel"]


@dataclass(frozen=True)
class LimbChain:
    """One limb for a correction: its end frame and the columns of its joints."""

    limb: str  # "left_hand", "right_foot", ...
    frame: str  # pinocchio frame name ("L_palm", "R_sole")
    columns: tuple[int, ...]  # file columns of the joints that move it


def _memo_key(q_cols_rad: np.ndarray, R_world_pelvis: np.ndarray) -> bytes:
    """The bytes of a configuration (joints, tilt): the memos compare them at every call,
    several times a tick, and comparing bytes costs far less than comparing arrays."""
    return (np.asarray(q_cols_rad, dtype=float).tobytes()
            + np.asarray(R_world_pelvis, dtype=float).tobytes())


class MotionRobotModel:
    """Gravity, kinematics and limb IK of one robot (see the module docstring).

    Args:
        robot: robot name (`robot.params.robot_params`).
    """

    def __init__(self, robot: str = "drc-hubo"):
        params = robot_params(robot)
        self.model = pin.buildModelFromXML(robot_urdf(params), pin.JointModelFreeFlyer())
        self.data = self.model.createData()
        m = self.model
        self.mass_kg = float(sum(inertia.mass for inertia in m.inertias))
        self._q_of_col = np.full(len(JOINT_NAMES), -1)
        self._v_of_col = np.full(len(JOINT_NAMES), -1)
        for c, name in enumerate(JOINT_NAMES):
            if m.existJointName(name):
                j = m.joints[m.getJointId(name)]
                self._q_of_col[c], self._v_of_col[c] = j.idx_q, j.idx_v
        self._have = self._q_of_col >= 0
        self._q_cols = self._q_of_col[self._have]
        self._v_cols = self._v_of_col[self._have]
        self._neutral = pin.neutral(m)
        self.lower_rad = np.full(len(JOINT_NAMES), -np.inf)
        self.upper_rad = np.full(len(JOINT_NAMES), np.inf)
        self.lower_rad[self._have] = m.lowerPositionLimit[self._q_of_col[self._have]]
        self.upper_rad[self._have] = m.upperPositionLimit[self._q_of_col[self._have]]
        self.chains: dict[str, LimbChain] = {}
        for side, s in (("left", "L"), ("right", "R")):
            arm = tuple(c for c, n in enumerate(JOINT_NAMES)
                        if n in ARM_JOINTS[side] and self._have[c])
            leg = tuple(c for c, n in enumerate(JOINT_NAMES)
                        if n in LEG_JOINTS[side] and self._have[c])
            self.chains[f"{side}_hand"] = LimbChain(f"{side}_hand", f"{s}_palm", arm)
            self.chains[f"{side}_foot"] = LimbChain(f"{side}_foot", f"{s}_sole", leg)
        self._frame_id = {c.frame: m.getFrameId(c.frame) for c in self.chains.values()}
        # Jacobians and frame placements of the last (joints, tilt) asked for, in a data
        # of their own (the other methods overwrite `self.data` with other configurations):
        # a tick asks several questions of the sensed configuration (`_kinematics_at`).
        self._jac_data = m.createData()
        self._jac_at: bytes | None = None  # `_memo_key` of the configuration in it
        #: (`_memo_key`, torques) of the last two `gravity_torques` configurations
        self._gravity_memo: list[tuple[bytes, np.ndarray]] = []
        #: hand → (its configuration's and arm torques' bytes, the last `hand_wrench`):
        #: the leg relief's grip bound and the bending relief read it in the same tick
        self._wrench_memo: dict[str, tuple[bytes, np.ndarray]] = {}

    # ------------------------------------------------------------------ conversions
    def configuration(self, q_cols_rad: np.ndarray, T_world_pelvis: np.ndarray | None = None
                      ) -> np.ndarray:
        """pinocchio's q for the 40 columns and a pelvis pose (identity when None)."""
        q = self._neutral.copy()
        q[self._q_cols] = np.asarray(q_cols_rad)[self._have]
        if T_world_pelvis is not None:
            q[:3] = T_world_pelvis[:3, 3]
            q[3:7] = pin.Quaternion(T_world_pelvis[:3, :3]).coeffs()
        return q

    def _tilted(self, q_cols_rad: np.ndarray, R_world_pelvis: np.ndarray) -> np.ndarray:
        """pinocchio's q for the 40 columns, the pelvis at the origin turned by
        ``R_world_pelvis``."""
        T = np.eye(4)
        T[:3, :3] = R_world_pelvis
        return self.configuration(q_cols_rad, T)

    def _kinematics_at(self, q_cols_rad: np.ndarray, R_world_pelvis: np.ndarray):
        """`_jac_data` with joint Jacobians and frame placements at these joints and tilt,
        computed again only when they differ from the last call's."""
        key = _memo_key(q_cols_rad, R_world_pelvis)
        if key != self._jac_at:
            d = self._jac_data
            pin.computeJointJacobians(self.model, d, self._tilted(q_cols_rad, R_world_pelvis))
            pin.updateFramePlacements(self.model, d)
            self._jac_at = key
        return self._jac_data

    # ------------------------------------------------------------------ dynamics
    def gravity_torques(self, q_cols_rad: np.ndarray, R_world_pelvis: np.ndarray) -> np.ndarray:
        """Joint torques that hold the robot still against gravity [N·m], by column.

        Each joint's torque is that of the bodies beyond it, so only the pelvis's tilt
        matters, not where it stands. A tick asks for the sensed configuration more than
        once (gravity compensation, each gripping hand's wrench) beside the plan's: the
        last two configurations' torques are kept, and a copy is returned.
        """
        key = _memo_key(q_cols_rad, R_world_pelvis)
        for known, g in self._gravity_memo:
            if known == key:
                return g.copy()
        g = pin.computeGeneralizedGravity(self.model, self.data,
                                          self._tilted(q_cols_rad, R_world_pelvis))
        out = np.zeros(len(JOINT_NAMES))
        out[self._have] = g[self._v_cols]
        self._gravity_memo = [(key, out), *self._gravity_memo[:1]]
        return out.copy()

    def wrench_torques(self, q_cols_rad: np.ndarray, R_world_pelvis: np.ndarray, limb: str,
                       force_world_n: np.ndarray, moment_world_nm: np.ndarray | None = None
                       ) -> np.ndarray:
        """``Jᵀ w`` by column [N·m]: the generalized force of a wrench (a force
        ``force_world_n`` and a moment ``moment_world_nm``, world frame) applied at
        ``limb``'s end frame (its palm or sole), the pelvis tilted by ``R_world_pelvis``."""
        d = self._kinematics_at(q_cols_rad, R_world_pelvis)
        fid = self._frame_id[self.chains[limb].frame]
        J = pin.getFrameJacobian(self.model, d, fid, pin.LOCAL_WORLD_ALIGNED)
        jt = J[:3].T @ np.asarray(force_world_n, dtype=float)
        if moment_world_nm is not None:
            jt = jt + J[3:].T @ np.asarray(moment_world_nm, dtype=float)
        out = np.zeros(len(JOINT_NAMES))
        out[self._have] = jt[self._v_cols]
        return out

    def wrench_feedforward_nm(self, q_cols_rad: np.ndarray, R_world_pelvis: np.ndarray,
                              limb: str, force_world_n: np.ndarray,
                              moment_world_nm: np.ndarray | None = None,
                              columns: list[int] | None = None) -> np.ndarray:
        """Feed-forward torques by column [N·m] that make the environment push ``limb``'s
        end frame with the wrench (force, moment; world frame) when the limb is held:
        ``−Jᵀw`` on ``columns`` (the limb's joints when None), zero elsewhere."""
        torque = self.wrench_torques(q_cols_rad, R_world_pelvis, limb, force_world_n,
                                     moment_world_nm)
        cols = list(self.chains[limb].columns) if columns is None else columns
        out = np.zeros(len(JOINT_NAMES))
        out[cols] = -torque[cols]
        return out

    def hand_wrench(self, q_cols_rad: np.ndarray, R_world_pelvis: np.ndarray, hand: str,
                    torque_nm: np.ndarray) -> np.ndarray:
        """The environment's wrench on ``hand``'s palm, ``(f [N], m [N·m])`` about the
        palm frame's origin (the grip centre), world frame, from the arm's joint torques
        ``torque_nm`` (by column, as the motor currents give them).

        Held still, an arm's joints carry gravity and the hand's load: ``τ = g − Jᵀw``
        (pinocchio's sign: ``Jᵀw`` is what the wrench adds). The arm's joints (seven on
        the DRC-Hubo) over-determine the six components; the least-squares ``w`` of
        ``Jᵀw = g − τ`` is the estimate. It ignores the arm's inertia, small in a
        climb's slow moves.
        """
        cols = np.asarray(self.chains[hand].columns)
        key = _memo_key(q_cols_rad, R_world_pelvis) + np.asarray(
            torque_nm, dtype=float)[cols].tobytes()
        known = self._wrench_memo.get(hand)
        if known is not None and known[0] == key:
            return known[1].copy()
        d = self._kinematics_at(q_cols_rad, R_world_pelvis)
        J = pin.getFrameJacobian(self.model, d, self._frame_id[self.chains[hand].frame],
                                 pin.LOCAL_WORLD_ALIGNED)[:, self._v_of_col[cols]]
        held = self.gravity_torques(q_cols_rad, R_world_pelvis)[cols] - torque_nm[cols]
        wrench = np.linalg.lstsq(J.T, held, rcond=None)[0]
        self._wrench_memo[hand] = (key, wrench)
        return wrench.copy()

    def _sole_columns(self, q_cols_rad: np.ndarray, R_world_pelvis: np.ndarray,
                      joint_cols: int | np.ndarray, foot: str):
        """(kinematics, the columns ``joint_cols`` of ``foot``'s sole Jacobian (6, k),
        world-aligned), the pelvis tilted by ``R_world_pelvis``."""
        d = self._kinematics_at(q_cols_rad, R_world_pelvis)
        sole = self._frame_id[self.chains[foot].frame]
        jacobian = pin.getFrameJacobian(self.model, d, sole, pin.LOCAL_WORLD_ALIGNED)
        return d, jacobian[:, self._v_of_col[joint_cols]]

    def stance_moment_gradient(self, q_cols_rad: np.ndarray, R_world_pelvis: np.ndarray,
                               joint_cols: np.ndarray, foot: str) -> np.ndarray:
        """∂τ/∂m [N·m/N·m]: how the torques of leg joints ``joint_cols`` change with a
        moment m (world frame) of the environment on a hand, when the stance foot
        ``foot`` (a limb name) takes its reaction; (k, 3).

        The foot's wrench changes by ``−(0, m)``, and a leg joint's torque is
        ``g − Jᵀw`` over its foot's wrench: ∂τ/∂m = b, the angular part of the joint's
        column of the sole's Jacobian (a pure moment has no lever arm).
        """
        return self._sole_columns(q_cols_rad, R_world_pelvis, np.asarray(joint_cols),
                                  foot)[1][3:].T

    def stance_torque_gradient(self, q_cols_rad: np.ndarray, R_world_pelvis: np.ndarray,
                               joint_cols: int | np.ndarray, foot: str, hand: str
                               ) -> np.ndarray:
        """∂τ/∂f [N·m/N]: how the torque of leg joint ``joint_cols`` changes with a
        force f (world frame) of the environment on ``hand``'s palm, when the stance
        foot ``foot`` (a limb name) takes its reaction; (3,) for one column, (k, 3) for
        an array of k columns.

        The foot's wrench changes by ``−(f, r × f)`` about its sole (r from sole to palm),
        and a leg joint's torque is ``g − Jᵀw`` over its foot's wrench: ∂τ/∂f = a + b × r,
        with (a, b) the joint's column of the sole's Jacobian.
        """
        d, column = self._sole_columns(q_cols_rad, R_world_pelvis, joint_cols, foot)
        sole = self._frame_id[self.chains[foot].frame]
        palm = self._frame_id[self.chains[hand].frame]
        r = d.oMf[palm].translation - d.oMf[sole].translation
        a, b = column[:3], column[3:]
        b_cross_r = np.array([b[1] * r[2] - b[2] * r[1], b[2] * r[0] - b[0] * r[2],
                              b[0] * r[1] - b[1] * r[0]])  # column by column
        return (a + b_cross_r).T

    def com_m(self, q_cols_rad: np.ndarray, T_world_pelvis: np.ndarray) -> np.ndarray:
        """Whole-body centre of mass in the world [m]."""
        return np.array(pin.centerOfMass(self.model, self.data,
                                         self.configuration(q_cols_rad, T_world_pelvis)))

    # ------------------------------------------------------------------ kinematics
    def frame_in_pelvis(self, q_cols_rad: np.ndarray, frame: str) -> np.ndarray:
        """T_pelvis_frame (4, 4) at the given joint angles."""
        return self.frames_in_pelvis(q_cols_rad, (frame,))[frame]

    def frames_in_pelvis(self, q_cols_rad: np.ndarray, frames: tuple[str, ...]
                         ) -> dict[str, np.ndarray]:
        """T_pelvis_frame (4, 4) of each named frame, from one forward kinematics."""
        pin.framesForwardKinematics(self.model, self.data, self.configuration(q_cols_rad))
        return {f: self.data.oMf[self._frame_id[f]].homogeneous.copy() for f in frames}

    def limb_correction(self, q_cols_rad: np.ndarray, chain: LimbChain,
                        shift_pelvis_m: np.ndarray, turn_pelvis: np.ndarray | None = None,
                        iterations: int = 20, damping: float = 1e-3
                        ) -> tuple[np.ndarray, float]:
        """Joint offsets of ``chain`` that move its end frame by ``shift_pelvis_m`` (pelvis
        frame) and turn it by the rotation ``turn_pelvis`` (pelvis frame; none when None),
        the rest of the body fixed.

        Damped least squares on the chain's joints within their limits.

        Returns:
            ``(dq_cols_rad, residual_m)``: offsets by column (zero off the chain), and how
            far the end frame stays from the shifted target [m].
        """
        m, d = self.model, self.data
        fid = self._frame_id[chain.frame]
        cols = np.array(chain.columns)
        q_cols = np.asarray(q_cols_rad, dtype=float).copy()
        T0 = self.frame_in_pelvis(q_cols, chain.frame)
        R_target = T0[:3, :3] if turn_pelvis is None else turn_pelvis @ T0[:3, :3]
        target = pin.SE3(R_target, T0[:3, 3] + np.asarray(shift_pelvis_m, dtype=float))
        vcols = self._v_of_col[cols]
        err = np.zeros(6)
        for _ in range(iterations):
            q = self.configuration(q_cols)
            pin.framesForwardKinematics(m, d, q)
            current = d.oMf[fid]
            err[:3] = target.translation - current.translation
            err[3:] = pin.log3(target.rotation @ current.rotation.T)
            if np.linalg.norm(err[:3]) < 1e-4 and np.linalg.norm(err[3:]) < 1e-3:
                break
            J = pin.computeFrameJacobian(m, d, q, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
            Jc = J[:, vcols]
            step = Jc.T @ np.linalg.solve(Jc @ Jc.T + damping * np.eye(6), err)
            q_cols[cols] = np.clip(q_cols[cols] + step, self.lower_rad[cols],
                                   self.upper_rad[cols])
        dq = np.zeros(len(JOINT_NAMES))
        dq[cols] = q_cols[cols] - np.asarray(q_cols_rad)[cols]
        residual = float(np.linalg.norm(
            target.translation - self.frame_in_pelvis(q_cols, chain.frame)[:3, 3]))
        return dq, residual
