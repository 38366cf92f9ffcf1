"""Ladder collision objects for coal (the planner's collision checker)."""

from __future__ import annotations

import coal

from ladders.geometry import LadderGeometry, Solid
from ladders.spec import LadderSpec


def solid_collision_geometry(solid: Solid) -> coal.CollisionGeometry:
    """The coal shape of one primitive (in its own frame).

    coal.Box takes full side lengths; coal.Cylinder takes (radius, full length) with the
    axis along local z, as `Solid` does.
    """
    if solid.kind == "box":
        return coal.Box(*(2.0 * solid.half_extents_m))
    return coal.Cylinder(solid.radius_m, 2.0 * solid.half_length_m)


def ladder_collision_objects(
        spec: LadderSpec | LadderGeometry) -> list[tuple[str, coal.CollisionGeometry,
                                                          coal.Transform3s]]:
    """Every ladder piece as ``(name, shape, T_world_shape)`` for coal queries.

    Names match the MJCF geoms: ``rung_0..``, ``rail_left``, ``rail_right``,
    ``stringer_left``, ``stringer_right``.
    """
    geometry = spec if isinstance(spec, LadderGeometry) else LadderGeometry(spec)
    return [(s.name, solid_collision_geometry(s),
             coal.Transform3s(s.R_world_solid.copy(), s.centre_m.copy()))
            for s in geometry.solids]


__all__ = ["ladder_collision_objects", "solid_collision_geometry"]
