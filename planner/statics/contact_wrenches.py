"""Linearised contact limits shared by the two stability LPs.

A foot's contact points push inside Coulomb friction cones, linearised as inscribed
pyramids (thesis §6.3.1): any non-negative combination of a pyramid's edges obeys
friction, so the linearisation is conservative. A hand with grip limits
(`ladders.contact_model.HandLimits`) applies a 6-D wrench about its palm frame, written
as the difference of two non-negative 6-vectors so that both LPs keep non-negative
variables, inside the grip's linearised halfspaces.

Frames: world x forward, y left, z up. Forces are those the environment applies to the
robot [N].
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ladders.contact_model import HandLimits

__all__ = ["cone_edges_cached", "friction_cone_edges", "grip_rows", "split_wrench_basis"]


def friction_cone_edges(normals: np.ndarray, mu: np.ndarray | float, k: int = 8) -> np.ndarray:
    """Edges of the inner pyramids of point-contact friction cones.

    The edge tips lie on the cone's circle of radius μ (the pyramid is inscribed), so any
    non-negative combination of edges obeys Coulomb friction: the linearisation is
    conservative.

    Args:
        normals: (n, 3) contact normals (need not be unit).
        mu: Coulomb coefficient, scalar or (n,).
        k: edges per cone (≥ 3).

    Returns:
        (n, k, 3) unit edge directions.
    """
    if k < 3:
        raise ValueError(f"a friction pyramid needs k >= 3 edges, got {k}")
    nrm = np.asarray(normals, dtype=float).reshape(-1, 3)
    nrm = nrm / np.linalg.norm(nrm, axis=1, keepdims=True)
    mu_arr = np.broadcast_to(np.asarray(mu, dtype=float), (len(nrm),))
    # Tangent basis: cross with whichever axis is least aligned with n.
    helper = np.where(np.abs(nrm[:, [0]]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    t1 = np.cross(nrm, helper)
    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    t2 = np.cross(nrm, t1)
    ang = 2.0 * np.pi * np.arange(k) / k
    tang = np.cos(ang)[None, :, None] * t1[:, None, :] + np.sin(ang)[None, :, None] * t2[:, None, :]
    edges = nrm[:, None, :] + mu_arr[:, None, None] * tang
    return edges / np.linalg.norm(edges, axis=2, keepdims=True)


@lru_cache(maxsize=4096)
def cone_edges_cached(normals_bytes: bytes, mu: float, k: int) -> np.ndarray:
    """`friction_cone_edges` of a hold's normals, memoised: the torque LP runs on every
    interpolated configuration of a stance whose cones never change."""
    edges = friction_cone_edges(np.frombuffer(normals_bytes).reshape(-1, 3), mu, k)
    edges.setflags(write=False)
    return edges


def _skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def split_wrench_basis(offset_m: np.ndarray) -> np.ndarray:
    """(6, 12): a wrench (force, torque about a point ``offset_m`` from the moment origin)
    as the difference of two non-negative 6-vectors, mapped to (force, moment about the
    origin)."""
    w = np.eye(6)
    w[3:, :3] = _skew(offset_m)
    return np.hstack([w, -w])


def grip_rows(limits: HandLimits, weight_n: float) -> tuple[np.ndarray, np.ndarray]:
    """A grip's halfspaces on its split wrench variables (body weights): (m, 12), (m,)."""
    a, b = limits.halfspaces()
    return np.hstack([a, -a]), b / weight_n
