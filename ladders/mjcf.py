"""The ladder as a static MuJoCo body (mjSpec), from the same solids as mesh and coal."""

from __future__ import annotations

import mujoco
import numpy as np

from ladders.geometry import SIDES, LadderGeometry
from ladders.spec import LadderSpec
from robot.mjcf import ENV_CONAFFINITY, ENV_CONTYPE

#: Torsional and rolling friction of ladder contacts (MuJoCo's defaults).
TORSIONAL_FRICTION = 0.005
ROLLING_FRICTION = 0.0001
#: Contact priority of ladder geoms, above the robot's 0 (MuJoCo then takes the ladder's
#: friction and condim for a rung or rail contact instead of the larger of the two).
LADDER_CONTACT_PRIORITY = 1
_RGBA = {"rung": [0.85, 0.55, 0.2, 1.0], "rail": [0.75, 0.75, 0.78, 1.0],
         "stringer": [0.55, 0.45, 0.35, 1.0], "landing": [0.6, 0.4, 0.25, 1.0],
         "handrail": [0.75, 0.75, 0.78, 1.0]}


def _quat(R: np.ndarray) -> list[float]:
    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, np.ascontiguousarray(R).ravel())
    return q.tolist()


def add_ladder(mj_spec: mujoco.MjSpec, ladder: LadderSpec | LadderGeometry,
               body_name: str = "ladder") -> mujoco.MjsBody:
    """Add the ladder as a static body at its placement (body frame = ladder frame L).

    Geoms: ``rung_0..rung_{N-1}``, ``rail_left``, ``rail_right``, ``stringer_left``,
    ``stringer_right``, with the environment contact bits, ``condim`` 3 and the spec's
    friction. Sites: ``rung_{i}_top`` (top-surface centre) and ``rail_{side}_p0``/``_p1``
    (rail axis ends).

    Args:
        mj_spec: A spec from `robot.mjcf.new_spec` (it has the ``environment`` class).
        ladder: The ladder spec or its geometry.
        body_name: Name of the new body.

    Returns:
        The new body.
    """
    geometry = ladder if isinstance(ladder, LadderGeometry) else LadderGeometry(ladder)
    spec = geometry.spec
    T_ladder_world = np.linalg.inv(geometry.T_world_ladder)
    body = mj_spec.worldbody.add_body(name=body_name,
                                      pos=geometry.T_world_ladder[:3, 3].tolist(),
                                      quat=_quat(geometry.R_world_ladder))
    env_class = mj_spec.find_default("environment")
    for solid in geometry.solids:
        T_L = T_ladder_world @ solid.T_world_solid
        if solid.kind == "box":
            kind, size = mujoco.mjtGeom.mjGEOM_BOX, solid.half_extents_m.tolist()
        else:
            kind, size = mujoco.mjtGeom.mjGEOM_CYLINDER, [solid.radius_m, solid.half_length_m, 0]
        geom = body.add_geom(name=solid.name, type=kind, size=size, pos=T_L[:3, 3].tolist(),
                             quat=_quat(T_L[:3, :3]))
        if env_class is not None:
            geom.classname = env_class
        # mjSpec applies a class at creation only: set the contact bits explicitly.
        geom.contype, geom.conaffinity = ENV_CONTYPE, ENV_CONAFFINITY
        geom.condim = 3
        geom.friction = [spec.friction, TORSIONAL_FRICTION, ROLLING_FRICTION]
        # MuJoCo mixes two geoms' friction by their maximum unless one has the higher
        # priority; the ladder's μ, which the planner assumed, must govern its contacts.
        geom.priority = LADDER_CONTACT_PRIORITY
        geom.rgba = _RGBA[solid.name.split("_")[0]]
    site_size = [0.01, 0.0, 0.0]
    for i, p in enumerate(geometry.to_ladder(geometry.rung_top_centres_m)):
        body.add_site(name=f"rung_{i}_top", pos=p.tolist(), size=site_size)
    for side in SIDES:
        for end, p in zip(("p0", "p1"), geometry.rail_axis(side), strict=True):
            body.add_site(name=f"rail_{side}_{end}", pos=geometry.to_ladder(p).tolist(),
                          size=site_size)
    return body


__all__ = ["add_ladder"]
