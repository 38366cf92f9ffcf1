"""The MuJoCo scene's geoms as triangle meshes, one mesh per body, for a 3D viewer.

The viewer draws what MuJoCo simulates: the robot's capsules, boxes and spheres and the
ladder's boxes and cylinders of `ladders.scene.build_scene` (the same model
``validate-plan`` steps), each geom turned into a closed trimesh in its body's frame and
the geoms of a body concatenated. The floor plane becomes a thin square slab.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
import trimesh

__all__ = ["BodyMesh", "FLOOR_HALF_M", "body_meshes"]

#: Half side of the floor slab drawn for MuJoCo's infinite plane [m].
FLOOR_HALF_M = 1.5
#: Facets around a capsule's or cylinder's circumference (display only).
SECTIONS = 16


@dataclass(frozen=True, eq=False)
class BodyMesh:
    """One body's geoms as one mesh.

    Attributes:
        body: the body's id in the model; name: its name ("floor" for the world body,
            which holds the floor).
        vertices_m: (V, 3) vertex positions in the body frame [m].
        faces: (F, 3) triangle vertex indices.
        normals: (V, 3) unit vertex normals.
        colors: (V, 4) each vertex's geom colour, RGBA 0..255.
    """

    body: int
    name: str
    vertices_m: np.ndarray
    faces: np.ndarray
    normals: np.ndarray
    colors: np.ndarray


def _geom_mesh(model: mujoco.MjModel, g: int) -> trimesh.Trimesh | None:
    """Geom ``g`` as a mesh in its body's frame; None for a kind the scene does not use."""
    kind, size = model.geom_type[g], model.geom_size[g]
    G = mujoco.mjtGeom
    if kind == G.mjGEOM_CAPSULE:
        mesh = trimesh.creation.capsule(height=2 * size[1], radius=size[0],
                                        count=[SECTIONS, SECTIONS // 2])
    elif kind == G.mjGEOM_BOX:
        mesh = trimesh.creation.box(extents=2 * size)
    elif kind == G.mjGEOM_SPHERE:
        mesh = trimesh.creation.icosphere(subdivisions=2, radius=size[0])
    elif kind == G.mjGEOM_CYLINDER:
        mesh = trimesh.creation.cylinder(radius=size[0], height=2 * size[1], sections=SECTIONS)
    elif kind == G.mjGEOM_PLANE:
        mesh = trimesh.creation.box(extents=(2 * FLOOR_HALF_M, 2 * FLOOR_HALF_M, 0.002))
        mesh.apply_translation((0.0, 0.0, -0.001))
    else:
        return None
    T = np.eye(4)
    R = np.zeros(9)
    mujoco.mju_quat2Mat(R, model.geom_quat[g])
    T[:3, :3] = R.reshape(3, 3)
    T[:3, 3] = model.geom_pos[g]
    mesh.apply_transform(T)
    return mesh


def body_meshes(model: mujoco.MjModel) -> list[BodyMesh]:
    """Every body of ``model`` that has geoms, as one mesh in the body's frame."""
    by_body: dict[int, list[int]] = {}
    for g in range(model.ngeom):
        by_body.setdefault(int(model.geom_bodyid[g]), []).append(g)
    out = []
    for body, geoms in sorted(by_body.items()):
        pieces = [(m, model.geom_rgba[g]) for g in geoms
                  if (m := _geom_mesh(model, g)) is not None]
        if not pieces:
            continue
        mesh = trimesh.util.concatenate([m for m, _ in pieces])
        colors = np.vstack([np.tile(np.round(255 * rgba), (len(m.vertices), 1))
                            for m, rgba in pieces]).astype(np.uint8)
        out.append(BodyMesh(body, "floor" if body == 0 else model.body(body).name,
                            np.asarray(mesh.vertices, dtype=np.float32),
                            np.asarray(mesh.faces, dtype=np.uint32),
                            np.asarray(mesh.vertex_normals, dtype=np.float32), colors))
    return out
