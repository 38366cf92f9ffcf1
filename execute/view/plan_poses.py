"""The planned robot placed in the world, line by line, for display.

The 40-column file has no base pose. check-plan's verifier places the body from a foot
the sidecar says is held (`planner.verify.check.PlanVerifier.line_poses`: the sole flat on
its tread at the recorded hold); this module reuses it, then runs MuJoCo's forward
kinematics on the scene the simulation steps (`ladders.scene.build_scene`), so that every
body is where ``validate-plan``'s model would put it. The CoM and its stability margin
are the verifier's too (the support region of the holds that may balance the robot).

Lines without a held foot (the base cannot be placed) keep the last placed base pose.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import mujoco
import numpy as np
from scipy.spatial.transform import Rotation

from ladders.spec import LadderSpec
from robot.joints import JOINT_NAMES
from robot.mjcf import joint_qpos_addresses
from robot.plan_sidecar import PlanSidecar

__all__ = ["PlanKinematics", "PlanPoses", "body_poses"]

log = logging.getLogger(__name__)


@dataclass(frozen=True, eq=False)
class PlanPoses:
    """The plan's robot on a set of lines.

    Attributes:
        rows: (K,) the lines, 0-based.
        placed: (K,) a held foot placed the base on that line.
        body_pos_m: (K, nbody, 3) every body's origin in the world [m].
        body_quat_xyzw: (K, nbody, 4) every body's orientation (x, y, z, w).
        com_m: (K, 3) whole-body centre of mass [m].
        margin_m: (K,) the CoM's distance inside its support region [m] (negative:
            outside; nan where the base is not placed or ``statics`` was not asked).
    """

    rows: np.ndarray
    placed: np.ndarray
    body_pos_m: np.ndarray
    body_quat_xyzw: np.ndarray
    com_m: np.ndarray
    margin_m: np.ndarray


def body_poses(model: mujoco.MjModel, qpos: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """MuJoCo's forward kinematics on each row of ``qpos`` (K, nq): every body's position
    (K, nbody, 3) [m] and orientation (K, nbody, 4) as (x, y, z, w)."""
    data = mujoco.MjData(model)
    pos = np.empty((len(qpos), model.nbody, 3))
    quat = np.empty((len(qpos), model.nbody, 4))
    for k, q in enumerate(qpos):
        data.qpos[:] = q
        mujoco.mj_kinematics(model, data)
        pos[k] = data.xpos
        quat[k] = data.xquat
    return pos, quat[:, :, [1, 2, 3, 0]]


class PlanKinematics:
    """A plan's lines placed in the world (see the module's docstring).

    Args:
        trajectory_rad: (N, 40) the plan's lines [rad].
        sidecar: its sidecar (segments and holds).
        ladder: the ladder it climbs.
        where: the plan's name, for messages.

    Raises:
        InputError: the sidecar's segments do not cover every line.
    """

    def __init__(self, trajectory_rad: np.ndarray, sidecar: PlanSidecar, ladder: LadderSpec,
                 where: str = "plan", verifier=None):
        from ladders.scene import build_scene
        from planner.verify.check import plan_verifier
        from robot.plan_sidecar import segment_of_lines

        self.trajectory_rad = trajectory_rad
        self.sidecar = sidecar
        self.segment_of_row = segment_of_lines(sidecar, where)
        self.verifier = verifier or plan_verifier(sidecar, ladder)
        self.model = build_scene(ladder, sidecar.robot).compile()
        addresses = joint_qpos_addresses(self.model)
        self._columns = np.array([JOINT_NAMES.index(n) for n in addresses])
        self._qpos_index = np.array(list(addresses.values()))

    def poses(self, rows: np.ndarray, statics: bool = True) -> PlanPoses:
        """The robot on ``rows`` (0-based lines, any order); with ``statics``, the
        stability margin too (it computes each segment's support region once)."""
        rows = np.asarray(rows, dtype=int)
        K = len(rows)
        R = np.full((K, 3, 3), np.nan)
        p = np.full((K, 3), np.nan)
        com = np.full((K, 3), np.nan)
        margin = np.full(K, np.nan)
        segs = self.segment_of_row[rows]
        v = self.verifier
        for si in np.unique(segs):
            idx = np.flatnonzero(segs == si)
            seg = self.sidecar.segments[si]
            joint_poses, q = v.line_poses(self.trajectory_rad[rows[idx]], seg)
            if joint_poses is None:
                continue
            R[idx], p[idx] = q.R, q.p
            com[idx] = v.kin.com(joint_poses)
            if statics:
                margin[idx] = v.stance(int(si), seg).region.margin(com[idx])
        placed = ~np.isnan(p[:, 0])
        if not placed.any():
            R[:], p[:] = np.eye(3), 0.0
        else:  # a line without a held foot keeps the last placed base
            last = np.maximum.accumulate(np.where(placed, np.arange(K), -1))
            last[last < 0] = int(np.argmax(placed))
            R, p = R[last], p[last]
        qpos = np.zeros((K, self.model.nq))
        qpos[:, :3] = p
        qpos[:, 3:7] = Rotation.from_matrix(R).as_quat()[:, [3, 0, 1, 2]]
        qpos[:, self._qpos_index] = self.trajectory_rad[rows][:, self._columns]
        pos, quat = body_poses(self.model, qpos)
        return PlanPoses(rows, placed, pos, quat, com, margin)
