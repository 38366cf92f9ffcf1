"""The robot's kinematics on many lines at once, in numpy (check-plan's pass over a plan).

pinocchio computes one configuration per call. A DRC climb has 300,000 lines, and one
Python call per line for each quantity (placements, CoM, gravity, Jacobians) cost
more than the checks themselves. `BatchKinematics` walks the same pinocchio model (a
free-flyer root and revolute joints) over a batch of lines with numpy, and gives what
pinocchio's ``forwardKinematics``, ``centerOfMass``, ``computeGeneralizedGravity`` and
``getFrameJacobian(..., LOCAL_WORLD_ALIGNED)`` give, to rounding
(tests/test_batch_kinematics.py compares them).

Shapes: ``L`` lines, ``J`` joints of the model (0 the universe, 1 the free flyer),
``nv`` velocity dimensions (6 free-flyer ones in the base frame, then one per joint).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["BatchKinematics", "JointPoses", "PinConfigurations"]


class JointPoses(NamedTuple):
    """Every joint frame of the model on ``L`` lines, in the world (or the base's frame).

    Attributes:
        R: (L, J, 3, 3) rotations.
        p: (L, J, 3) origins [m].
    """

    R: np.ndarray
    p: np.ndarray

    def frame(self, parent: int, R_joint_frame: np.ndarray, p_joint_frame: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray]:
        """A frame fixed to joint ``parent`` at (R, p) in it: (L, 3, 3), (L, 3)."""
        R_j, p_j = self.R[:, parent], self.p[:, parent]
        return R_j @ R_joint_frame, p_j + R_j @ p_joint_frame

    def subset(self, idx: np.ndarray) -> JointPoses:
        """The lines ``idx`` of this batch."""
        return JointPoses(self.R[idx], self.p[idx])


class PinConfigurations:
    """pinocchio configurations of a batch of lines, built on demand (the few lines that
    coal or a per-line LP needs).

    Args:
        q: (L, nq) the configurations with the free flyer's 7 unset.
        R_world_base: (L, 3, 3) the base's rotation on each line.
        p_world_base: (L, 3) its position [m].
    """

    def __init__(self, q: np.ndarray, R_world_base: np.ndarray, p_world_base: np.ndarray):
        self.q, self.R, self.p = q, R_world_base, p_world_base

    def __len__(self) -> int:
        return len(self.q)

    def __getitem__(self, i: int) -> np.ndarray:
        import pinocchio as pin

        q = self.q[i].copy()
        q[:3] = self.p[i]
        q[3:7] = pin.Quaternion(self.R[i]).coeffs()  # x y z w
        return q

    def subset(self, idx: np.ndarray) -> PinConfigurations:
        """The lines ``idx`` of this batch."""
        return PinConfigurations(self.q[idx], self.R[idx], self.p[idx])


def _cross_matrix(axis: np.ndarray) -> np.ndarray:
    x, y, z = axis
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


class BatchKinematics:
    """Kinematics of one pinocchio model (free-flyer root, revolute joints) on many lines.

    Args:
        model: the pinocchio model; every joint after the free flyer has one degree of
            freedom about a fixed axis (RX, RY, RZ or revolute unaligned).
    """

    def __init__(self, model):
        self.model = model
        n = model.njoints
        self.parent = np.array(model.parents, dtype=int)
        self.R_place = np.array([model.jointPlacements[j].rotation for j in range(n)])
        self.p_place = np.array([model.jointPlacements[j].translation for j in range(n)])
        self.axis = np.zeros((n, 3))
        for j in range(2, n):
            short = model.joints[j].shortname()
            if short in ("JointModelRX", "JointModelRY", "JointModelRZ"):
                self.axis[j, "XYZ".index(short[-1])] = 1.0
            elif short == "JointModelRevoluteUnaligned":
                self.axis[j] = model.joints[j].extract().axis
            else:
                raise ValueError(f"joint {model.names[j]} is a {short}; only revolute joints "
                                 "after the free flyer are supported")
        self._K = np.array([_cross_matrix(a) for a in self.axis])
        self._K2 = self._K @ self._K
        self.idx_q = np.array([model.joints[j].idx_q for j in range(n)])
        self.idx_v = np.array([model.joints[j].idx_v for j in range(n)])
        self.mass = np.array([model.inertias[j].mass for j in range(n)])
        self.lever = np.array([model.inertias[j].lever for j in range(n)])
        self.total_mass = float(self.mass.sum())
        self.gravity = np.array(model.gravity.linear, dtype=float)
        # Each joint's chain from the free flyer's child down to itself.
        self.support = [[]] * n
        for j in range(2, n):
            self.support[j] = self.support[self.parent[j]] + [j] if self.parent[j] > 1 \
                else [j]
        self._subtree_mass = self.mass.copy()  # each joint's subtree's mass [kg]
        for j in range(n - 1, 1, -1):
            self._subtree_mass[self.parent[j]] += self._subtree_mass[j]

    # ----------------------------------------------------------------- placements
    def joint_poses(self, q: np.ndarray, R_world_base: np.ndarray | None = None,
                    p_world_base: np.ndarray | None = None, upto: int | None = None
                    ) -> JointPoses:
        """Every joint frame in the world.

        Args:
            q: (L, nq) configurations (pinocchio order; the free flyer's 7 are ignored).
            R_world_base, p_world_base: (L, 3, 3), (L, 3) the base's pose on each line
                (the origin if None).
            upto: only the joints from the base to this one (the others are left unset).
        """
        L, n = len(q), len(self.parent)
        R = np.empty((L, n, 3, 3))
        p = np.empty((L, n, 3))
        R[:, 0], p[:, 0] = np.eye(3), 0.0
        R[:, 1] = np.eye(3) if R_world_base is None else R_world_base
        p[:, 1] = 0.0 if p_world_base is None else p_world_base
        for j in (range(2, n) if upto is None else self.support[upto]):
            a = self.parent[j]
            angle = q[:, self.idx_q[j]]
            # R_a R_place (I + sin K + (1 − cos) K²), as three products with constant
            # matrices (one BLAS call each on the stacked rows) and two scalings.
            rows = R[:, a].reshape(3 * L, 3)
            P = rows @ self.R_place[j]
            p[:, j] = p[:, a] + (rows @ self.p_place[j]).reshape(L, 3)
            R[:, j] = (P + np.sin(angle).repeat(3)[:, None] * (P @ self._K[j])
                       + (1.0 - np.cos(angle)).repeat(3)[:, None] * (P @ self._K2[j])
                       ).reshape(L, 3, 3)
        return JointPoses(R, p)

    # ----------------------------------------------------------------- mass
    def _body_coms(self, poses: JointPoses) -> np.ndarray:
        """(L, J, 3) world centre of mass of each joint's body."""
        return poses.p + (poses.R * self.lever[None, :, None, :]).sum(axis=3)

    def com(self, poses: JointPoses) -> np.ndarray:
        """(L, 3) whole-body centre of mass [m]."""
        return np.einsum("j,lji->li", self.mass, self._body_coms(poses)) / self.total_mass

    def _axes(self, poses: JointPoses, joints) -> np.ndarray:
        """(L, len(joints), 3) the joints' axes in the world."""
        return (poses.R[:, joints] * self.axis[joints][None, :, None, :]).sum(axis=3)

    def gravity_torques(self, poses: JointPoses) -> np.ndarray:
        """(L, nv) pinocchio's generalized gravity: the free flyer's wrench (base frame)
        and each joint's torque holding the configuration still [N, N·m]."""
        L, n = poses.p.shape[:2]
        # Σ m c over each joint's subtree, children into parents (joint by joint: one
        # product with a subtree matrix is a BLAS call that threads, and loses to the
        # loop when the other core is busy).
        moment = (self.mass[:, None, None]
                  * self._body_coms(poses).transpose(1, 0, 2)).copy()  # (J, L, 3)
        for j in range(n - 1, 1, -1):
            moment[self.parent[j]] += moment[j]
        moment = moment.transpose(1, 0, 2)
        # About each joint's origin: r × (m g) summed over its subtree, on its axis.
        arm = moment - self._subtree_mass[None, :, None] * poses.p
        torque = -np.cross(arm, self.gravity)  # (L, J, 3) [N·m], world
        out = np.empty((L, self.model.nv))
        R_b = poses.R[:, 1]
        force = -self._subtree_mass[1] * self.gravity
        out[:, :3] = force @ R_b  # Rᵀ f, line by line
        out[:, 3:6] = np.einsum("lji,lj->li", R_b, torque[:, 1])
        joints = np.arange(2, n)
        out[:, self.idx_v[2:]] = (self._axes(poses, joints) * torque[:, 2:]).sum(axis=2)
        return out

    # ----------------------------------------------------------------- Jacobians
    def frame_jacobian(self, poses: JointPoses, parent: int, p_frame: np.ndarray
                       ) -> np.ndarray:
        """(L, 6, nv) the LOCAL_WORLD_ALIGNED Jacobian of a frame of joint ``parent``
        whose origin is at ``p_frame`` (L, 3): linear rows, then angular."""
        L = len(p_frame)
        J = np.zeros((L, 6, self.model.nv))
        R_b = poses.R[:, 1]
        J[:, :3, :3] = R_b
        J[:, :3, 3:6] = np.cross(np.swapaxes(R_b, 1, 2), (p_frame - poses.p[:, 1])[:, None, :]
                                 ).swapaxes(1, 2)
        J[:, 3:, 3:6] = R_b
        chain = self.support[parent]
        if chain:
            axes = self._axes(poses, chain)
            lin = np.cross(axes, p_frame[:, None, :] - poses.p[:, chain])
            cols = self.idx_v[chain]
            J[:, :3, cols] = lin.swapaxes(1, 2)
            J[:, 3:, cols] = axes.swapaxes(1, 2)
        return J
