"""Collisions and clearance on many lines of a plan, with coal only where needed
(check-plan's pass).

`planner.configuration.collision.CollisionModel` asks coal about all its ~700 pairs on
every call: 50–100 µs a line for the collision flag and 250 µs for the clearance, most
of check-plan's time on a climb of 300,000 lines once the torque LP was batched
(`planner.verify.torque_lines`). Most pairs are far apart on most lines, and a cheap
lower bound of their distance says so:

- every shape is enclosed in a capsule (a segment and a radius: a capsule is its own, a
  cylinder's has its radius, a box's runs along its longest side with the half-diagonal
  of the other two as radius, a sphere's has no length); the floor is the half-space
  z ≤ 0;
- over a window of `WINDOW_LINES` lines, each robot shape's swept sphere (its capsule's
  midpoints and their spread, plus its half-length and radius) bounds every pair's
  distance on the whole window at once;
- on the windows where that bound does not clear a pair, the capsules' distance (segment
  to segment, minus the radii) bounds it line by line.

A pair whose bound exceeds `CLEAR_MARGIN_M` cannot collide on that line; coal checks the
others, one pair at a time, exactly as `CollisionModel.in_collision` would. The
clearance (the smallest distance over the active pairs, and which pair) asks coal for
the pairs in the order of their bounds, until the next bound exceeds the smallest
distance found. The flag and the clearance are therefore `CollisionModel`'s, to rounding
(tests/test_collision_lines.py).
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import NamedTuple

import numpy as np

from planner.configuration.collision import LIMB_END_LINKS, CollisionModel
from planner.verify.batch_kinematics import JointPoses

__all__ = ["CLEAR_MARGIN_M", "LineCollisions", "CollisionLines", "segment_distance"]

#: Lines whose swept spheres bound a pair at once.
WINDOW_LINES = 32
#: Distances within this of the smallest are equal to it: the first pair is named [m].
PAIR_TIE_M = 1e-9
#: A pair whose lower bound exceeds its security margin by this is clear [m] (coal's
#: own tolerances are far below it).
CLEAR_MARGIN_M = 1e-6


class LineCollisions(NamedTuple):
    """Collision flags and clearances of a batch of lines.

    Attributes:
        hit: (L,) some active pair collides.
        clearance_m: (L,) the smallest distance over the active pairs [m], where asked
            for or hit (nan elsewhere).
        pair: per line where ``clearance_m`` is set, "link/i – other" (`CollisionModel`'s
            names).
    """

    hit: np.ndarray
    clearance_m: np.ndarray
    pair: dict[int, str]


def segment_distance(p1: np.ndarray, q1: np.ndarray, p2: np.ndarray, q2: np.ndarray
                     ) -> np.ndarray:
    """Distance between segments p1–q1 and p2–q2 (arrays (..., 3)) [m] (Ericson,
    *Real-Time Collision Detection* §5.1.9, on arrays; a segment may be a point)."""
    eps = 1e-12
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a = np.einsum("...i,...i->...", d1, d1)
    e = np.einsum("...i,...i->...", d2, d2)
    f = np.einsum("...i,...i->...", d2, r)
    c = np.einsum("...i,...i->...", d1, r)
    b = np.einsum("...i,...i->...", d1, d2)
    a_ok, e_ok = a > eps, e > eps
    a_s, e_s = np.where(a_ok, a, 1.0), np.where(e_ok, e, 1.0)
    denom = a * e - b * b
    s = np.where(denom > eps * np.maximum(a * e, eps),
                 np.clip((b * f - c * e) / np.where(denom > 0, denom, 1.0), 0.0, 1.0), 0.0)
    s = np.where(e_ok, s, np.clip(-c / a_s, 0.0, 1.0))
    t = np.where(e_ok, (b * s + f) / e_s, 0.0)
    s = np.where(t < 0.0, np.clip(-c / a_s, 0.0, 1.0),
                 np.where(t > 1.0, np.clip((b - c) / a_s, 0.0, 1.0), s))
    t = np.clip(t, 0.0, 1.0)
    s = np.where(a_ok, s, 0.0)
    t = np.where(a_ok, t, np.where(e_ok, np.clip(f / e_s, 0.0, 1.0), 0.0))
    gap = (p1 + d1 * s[..., None]) - (p2 + d2 * t[..., None])
    return np.sqrt(np.einsum("...i,...i->...", gap, gap))


def _capsule(shape) -> tuple[np.ndarray, float]:
    """A shape's enclosing capsule in its own frame: (segment half-vector (3,), radius)."""
    import coal

    if isinstance(shape, coal.Capsule | coal.Cylinder):
        return np.array([0.0, 0.0, shape.halfLength]), float(shape.radius)
    if isinstance(shape, coal.Box):
        h = np.asarray(shape.halfSide, dtype=float)
        i = int(np.argmax(h))
        half = np.zeros(3)
        half[i] = h[i]
        return half, float(np.hypot(*np.delete(h, i)))
    if isinstance(shape, coal.Sphere):
        return np.zeros(3), float(shape.radius)
    raise TypeError(f"no enclosing capsule for a {type(shape).__name__}")


class CollisionLines:
    """A `CollisionModel`'s checks on batches of lines.

    Args:
        collision: the model (its geometry, pairs and coal data are used as they are).
    """

    def __init__(self, collision: CollisionModel):
        import coal

        self.collision = collision
        geom = collision.geom
        objs = geom.geometryObjects
        n = collision.n_robot
        self.n_robot = n
        self.parent = np.array([objs[i].parentJoint for i in range(n)])
        self.R_place = np.array([objs[i].placement.rotation for i in range(n)])
        self.p_place = np.array([objs[i].placement.translation for i in range(n)])
        caps = [_capsule(objs[i].geometry) for i in range(n)]
        self.half = np.array([c[0] for c in caps])  # (n, 3) in each shape's frame
        self.radius = np.array([c[1] for c in caps])
        self.reach = np.linalg.norm(self.half, axis=1) + self.radius
        # Environment: static capsules, and the floor (a half-space) apart.
        n_env = len(objs) - n
        self.env_a, self.env_b = np.zeros((n_env, 3)), np.zeros((n_env, 3))
        self.env_radius = np.zeros(n_env)
        self.env_floor = np.zeros(n_env, dtype=bool)
        for e in range(n_env):
            obj = objs[n + e]
            if isinstance(obj.geometry, coal.Halfspace):
                if not np.allclose(obj.placement.rotation @ obj.geometry.n, [0, 0, 1]) or \
                        abs(obj.geometry.d + obj.placement.translation[2]) > 1e-12:
                    raise ValueError(f"{obj.name}: only the floor z <= 0 is a half-space here")
                self.env_floor[e] = True
                continue
            half, r = _capsule(obj.geometry)
            c, R = obj.placement.translation, obj.placement.rotation
            self.env_a[e], self.env_b[e] = c - R @ half, c + R @ half
            self.env_radius[e] = r
        pairs = geom.collisionPairs
        self.first = np.array([cp.first for cp in pairs])
        self.second = np.array([cp.second for cp in pairs])
        # Each pair's kind: robot–robot, robot–environment capsule, robot–floor.
        self.is_env = self.second >= n
        self.env = np.where(self.is_env, self.second - n, 0)  # its environment object
        self.to_floor = self.is_env & self.env_floor[self.env]
        self.to_capsule = self.is_env & ~self.to_floor
        self.margin = np.array([collision.gdata.collisionRequests[k].security_margin
                                for k in range(len(pairs))])
        self.names = [(objs[cp.first].name, objs[cp.second].name) for cp in pairs]

    # ----------------------------------------------------------------- pair activity
    def active(self, contacts: dict[str, str]) -> np.ndarray:
        """(pairs,) which pairs `CollisionModel.allow` leaves active for ``contacts``: the
        self pairs, and the environment pairs (`CollisionModel.env_pair_index`, after
        them) but those of a limb's end links and what it holds."""
        allowed = {(link, target) for limb, target in contacts.items()
                   for link in LIMB_END_LINKS[limb]}
        col = self.collision
        out = np.ones(len(self.first), dtype=bool)
        out[col.n_self_pairs:] = [pair not in allowed for pair in col.env_pair_index]
        return out

    # ----------------------------------------------------------------- bounds
    def _capsules(self, poses: JointPoses) -> tuple[np.ndarray, np.ndarray]:
        """World segment ends of every robot shape's capsule: (L, n, 3) twice."""
        R_j, p_j = poses.R[:, self.parent], poses.p[:, self.parent]
        centre = p_j + np.einsum("lnij,nj->lni", R_j, self.p_place)
        axis = np.einsum("lnij,njk,nk->lni", R_j, self.R_place, self.half)
        return centre - axis, centre + axis

    def _pair_bound(self, a: np.ndarray, b: np.ndarray, lines: np.ndarray, k: np.ndarray
                    ) -> np.ndarray:
        """Lower bound of pair ``k[i]``'s distance on line ``lines[i]``, from the capsule
        ends a, b (L, n, 3)."""
        f, s, e = self.first[k], self.second[k], self.env[k]
        a1, b1 = a[lines, f], b[lines, f]
        out = np.empty(len(k))
        rob, cap, floor = ~self.is_env[k], self.to_capsule[k], self.to_floor[k]
        if rob.any():
            lr, sr = lines[rob], s[rob]
            out[rob] = (segment_distance(a1[rob], b1[rob], a[lr, sr], b[lr, sr])
                        - self.radius[f[rob]] - self.radius[sr])
        if cap.any():
            out[cap] = segment_distance(a1[cap], b1[cap], self.env_a[e[cap]], self.env_b[e[cap]]
                                        ) - self.radius[f[cap]] - self.env_radius[e[cap]]
        if floor.any():
            out[floor] = np.minimum(a1[floor, 2], b1[floor, 2]) - self.radius[f[floor]]
        return out

    def _window_bounds(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """(windows, pairs) lower bound of every pair's distance over each window."""
        L = len(a)
        n_win = -(-L // WINDOW_LINES)
        pad = n_win * WINDOW_LINES - L
        mid = (a + b) / 2
        if pad:
            mid = np.concatenate([mid, np.repeat(mid[-1:], pad, axis=0)])
        mid = mid.reshape(n_win, WINDOW_LINES, self.n_robot, 3)
        centre = (mid.max(axis=1) + mid.min(axis=1)) / 2
        spread = np.linalg.norm(mid - centre[:, None], axis=3).max(axis=1)
        R = spread + self.reach  # (windows, n) swept sphere radii
        f, s, e = self.first, self.second, self.env
        out = np.empty((n_win, len(f)))
        rob, cap, floor = ~self.is_env, self.to_capsule, self.to_floor
        out[:, rob] = (np.linalg.norm(centre[:, f[rob]] - centre[:, s[rob]], axis=2)
                       - R[:, f[rob]] - R[:, s[rob]])
        c = centre[:, f[cap]]
        out[:, cap] = (segment_distance(c, c, self.env_a[e[cap]], self.env_b[e[cap]])
                       - R[:, f[cap]] - self.env_radius[e[cap]])
        out[:, floor] = centre[:, f[floor], 2] - R[:, f[floor]]
        return out

    # ----------------------------------------------------------------- the checks
    def check(self, poses: JointPoses, q, active: np.ndarray,
              clearance: Iterable[int]) -> LineCollisions:
        """The collision flag of every line, and the clearance of ``clearance`` lines
        (indices into the batch) and of every line that collides.

        Args:
            poses: the lines' joint poses in the world.
            q: the same configurations for pinocchio, by line (``q[i]``: (nq,), free
                flyer first; `planner.verify.batch_kinematics.PinConfigurations`).
            active: (pairs,) the pairs checked (`active`).
            clearance: the lines whose clearance is measured.
        """
        import pinocchio as pin

        L = len(poses.p)
        a, b = self._capsules(poses)
        win = self._window_bounds(a, b)  # (windows, pairs)
        need = self.margin + CLEAR_MARGIN_M
        w_idx, k_idx = np.nonzero((win <= need) & active)
        # Per line, the pairs their window could not clear, and their capsule bounds.
        lines = (w_idx[:, None] * WINDOW_LINES + np.arange(WINDOW_LINES)).ravel()
        ks = np.repeat(k_idx, WINDOW_LINES)
        keep = lines < L
        order = np.argsort(lines[keep], kind="stable")
        lines, ks = lines[keep][order], ks[keep][order]  # by line
        lb = self._pair_bound(a, b, lines, ks)
        doubt = lb <= need[ks]
        hit = np.zeros(L, dtype=bool)
        col = self.collision
        model, data, geom, gdata = col.kin.model, col.kin.data, col.geom, col.gdata
        d_lines, d_pairs = lines[doubt], ks[doubt]
        for line in np.unique(d_lines):
            lo, hi = np.searchsorted(d_lines, [line, line + 1])
            pin.updateGeometryPlacements(model, data, geom, gdata, q[line])
            hit[line] = any(pin.computeCollision(geom, gdata, int(k)) for k in d_pairs[lo:hi])
        clear = np.full(L, np.nan)
        pair: dict[int, str] = {}
        wanted = sorted(set(int(i) for i in clearance) | set(np.flatnonzero(hit).tolist()))
        if wanted:
            bound = win[np.array(wanted) // WINDOW_LINES]  # (wanted, pairs)
            bound[:, ~active] = np.inf
            for w, line in enumerate(wanted):
                lo, hi = np.searchsorted(lines, [line, line + 1])
                bound[w, ks[lo:hi]] = lb[lo:hi]
                clear[line], pair[line] = self._clearance(q[line], bound[w])
        return LineCollisions(hit, clear, pair)

    def _clearance(self, q: np.ndarray, bound: np.ndarray) -> tuple[float, str]:
        """The smallest distance over the pairs with a finite ``bound`` (pairs,) and which
        pair: coal on the pairs in the order of their bounds, until no bound is lower."""
        import pinocchio as pin

        col = self.collision
        pin.updateGeometryPlacements(col.kin.model, col.kin.data, col.geom, col.gdata, q)
        found: list[tuple[float, int]] = []
        best = np.inf
        for k in np.argsort(bound, kind="stable"):
            if bound[k] > best + PAIR_TIE_M or not np.isfinite(bound[k]):
                break
            d = float(pin.computeDistance(col.geom, col.gdata, int(k)).min_distance)
            found.append((d, int(k)))
            best = min(best, d)
        if not found:
            return np.inf, ""
        # Pairs as near as the nearest but for rounding (a hand's mirror image, fingers
        # side by side): the first in the model's pair order.
        best_k = min(k for d, k in found if d <= best + PAIR_TIE_M)
        return best, " – ".join(self.names[best_k])
