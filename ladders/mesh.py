"""Ladder surface mesh (trimesh) for viewing and export (STL, OBJ, GLB, ...)."""

from __future__ import annotations

import logging
import os
from pathlib import Path

import trimesh

from ladders.geometry import LadderGeometry, Solid
from ladders.spec import LadderSpec

logger = logging.getLogger(__name__)

#: Facets around a cylinder's circumference.
CYLINDER_SECTIONS = 32


def solid_mesh(solid: Solid, sections: int = CYLINDER_SECTIONS) -> trimesh.Trimesh:
    """A closed mesh of one primitive, in the world frame.

    Args:
        solid: The primitive.
        sections: Facets around a cylinder (the mesh is inscribed in the true cylinder).
    """
    if solid.kind == "box":
        return trimesh.creation.box(extents=2.0 * solid.half_extents_m,
                                    transform=solid.T_world_solid)
    return trimesh.creation.cylinder(radius=solid.radius_m, height=2.0 * solid.half_length_m,
                                     sections=sections, transform=solid.T_world_solid)


def ladder_mesh(spec: LadderSpec | LadderGeometry) -> trimesh.Trimesh:
    """One mesh of the whole ladder (rungs, rails, stringers) in the world frame [m].

    The pieces are concatenated, not boolean-unioned: each stays a closed shell, so the
    mesh volume is the sum of the pieces' volumes.
    """
    geometry = spec if isinstance(spec, LadderGeometry) else LadderGeometry(spec)
    return trimesh.util.concatenate([solid_mesh(s) for s in geometry.solids])


def export_ladder_mesh(spec: LadderSpec | LadderGeometry, path: str | os.PathLike[str]) -> Path:
    """Write the ladder mesh; the format follows the suffix (``.glb``, ``.stl``, ``.obj``...).

    Returns:
        The path written.
    """
    out = Path(path)
    ladder_mesh(spec).export(out)
    logger.info("wrote ladder mesh %s", out)
    return out


__all__ = ["CYLINDER_SECTIONS", "export_ladder_mesh", "ladder_mesh", "solid_mesh"]
