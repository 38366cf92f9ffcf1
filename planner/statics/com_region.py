"""The CoM support region of a stance: where the CoM may be for static equilibrium.

The set of horizontal CoM positions (x, y) for which gravity can be balanced by contact
forces inside the linearised friction cones (thesis §6.3.1, μ = 0.4), for non-coplanar
contacts (Bretl & Lall 2008, "Testing static equilibrium for legged robots"). The
equilibrium equations are linear in the cone coefficients λ and in the CoM's (x, y), so
the region is the projection of a polytope onto (x, y); it is computed by the iterative
LP method (inner and outer polygons refined until their area gap is small). Computed once
per stance; `SupportRegion.margin` is then a cheap per-configuration test.

A hand with grip limits adds a 6-D wrench inside its grip capacity
(`planner.statics.contact_wrenches`).

The region is exactly the set of CoM positions for which the free-flyer rows of the
torque LP (`planner.statics.torque_lp`) are feasible (same contacts, same cones), so a
configuration whose CoM lies outside it can skip the torque LP
(`planner.statics.stability.check_stability` does).

Frames: world x forward, y left, z up; gravity along −z. Forces are those the environment
applies to the robot [N].
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import linprog

from ladders.contact_model import HandLimits
from planner.contacts import Hold, Stance
from planner.statics.config import StabilityConfig, StabilityError, default_config
from planner.statics.contact_wrenches import friction_cone_edges, grip_rows, split_wrench_basis
from robot.constants import GRAVITY_M_S2

log = logging.getLogger(__name__)

__all__ = ["SupportRegion", "support_region"]


@dataclass(frozen=True, eq=False)
class SupportRegion:
    """Horizontal CoM positions at which a stance is in static equilibrium.

    The polygon is the *inner* approximation from `support_region` (conservative). An
    infeasible stance gives an empty region (no vertices, margin −inf). A region of one or
    two vertices is degenerate (a point or segment); its margin is never positive.

    Attributes:
        vertices: (m, 2) polygon vertices, counter-clockwise [m].
        area_m2: inner polygon area [m²].
        gap_m2: outer minus inner area when refinement stopped [m²] (0 if exact).
        clipped: whether the region touches the LP box (it is then unbounded in truth).
        lp_count: LPs solved to build it.
    """

    vertices: np.ndarray = field(repr=False)
    area_m2: float = 0.0
    gap_m2: float = 0.0
    clipped: bool = False
    lp_count: int = 0
    _normals: np.ndarray = field(init=False, repr=False, compare=False)
    _offsets: np.ndarray = field(init=False, repr=False, compare=False)
    _edge_vec: np.ndarray = field(init=False, repr=False, compare=False)
    _edge_len2: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        v = np.asarray(self.vertices, dtype=float).reshape(-1, 2)
        v.setflags(write=False)
        object.__setattr__(self, "vertices", v)
        e = np.roll(v, -1, axis=0) - v  # edge i goes from v[i] to v[i+1]
        len2 = np.einsum("ij,ij->i", e, e)
        nrm = np.zeros_like(e)
        ok = len2 > 0
        nrm[ok] = np.column_stack([e[ok, 1], -e[ok, 0]]) / np.sqrt(len2[ok])[:, None]
        object.__setattr__(self, "_edge_vec", e)
        object.__setattr__(self, "_edge_len2", np.where(ok, len2, 1.0))
        object.__setattr__(self, "_normals", nrm)  # outward for a CCW polygon
        object.__setattr__(self, "_offsets", np.einsum("ij,ij->i", nrm, v))

    @property
    def is_empty(self) -> bool:
        return len(self.vertices) == 0

    def clockwise_vertices(self) -> np.ndarray:
        """(m, 2) vertices in clockwise order [m], as placo's
        ``add_com_polygon_constraint`` needs (counter-clockwise makes its QP infeasible)."""
        return self.vertices[::-1].copy()

    def margin(self, com: np.ndarray) -> float | np.ndarray:
        """Signed distance from the CoM to the region's boundary [m], positive inside.

        Args:
            com: CoM position [m], shape (2,) or (3,) (z ignored), or a batch (b, 2|3).

        Returns:
            A float for one CoM, else (b,) array; −inf for an empty region.
        """
        p = np.asarray(com, dtype=float)
        single = p.ndim == 1
        p = p.reshape(-1, p.shape[-1])[:, :2]
        m = len(self.vertices)
        if m == 0:
            out = np.full(len(p), -np.inf)
        else:
            # Distance to the boundary (segments), for points outside or degenerate regions.
            rel = p[:, None, :] - self.vertices[None, :, :]  # (b, m, 2)
            if m == 1:
                dist = np.linalg.norm(rel[:, 0, :], axis=1)
            else:
                t = np.einsum("bmi,mi->bm", rel, self._edge_vec) / self._edge_len2
                t = np.clip(t, 0.0, 1.0)
                d = rel - t[..., None] * self._edge_vec[None]
                dist = np.sqrt(np.einsum("bmi,bmi->bm", d, d).min(axis=1))
            out = -dist
            if m >= 3:
                inside = (self._offsets[None, :] - p @ self._normals.T).min(axis=1)
                out = np.where(inside >= 0.0, inside, out)
        return float(out[0]) if single else out

    def contains(self, com: np.ndarray, min_margin_m: float = 0.0) -> bool | np.ndarray:
        """Whether ``margin(com) >= min_margin_m`` (see `margin` for shapes)."""
        m = self.margin(com)
        return bool(m >= min_margin_m) if np.ndim(m) == 0 else m >= min_margin_m

    def __repr__(self) -> str:
        if self.is_empty:
            return f"SupportRegion(empty, lps={self.lp_count})"
        lo, hi = self.vertices.min(axis=0), self.vertices.max(axis=0)
        return (f"SupportRegion({len(self.vertices)} vertices, area={self.area_m2 * 1e4:.1f} cm², "
                f"x∈[{lo[0]:.3f}, {hi[0]:.3f}], y∈[{lo[1]:.3f}, {hi[1]:.3f}] m, "
                f"gap={self.gap_m2 * 1e4:.2f} cm², lps={self.lp_count}"
                + (", clipped to box" if self.clipped else "") + ")")


def _polygon_area(v: list[np.ndarray]) -> float:
    if len(v) < 3:
        return 0.0
    a = np.asarray(v)
    x, y = a[:, 0], a[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def _edge_gap(vi, vj, d_out_i, d_in_j, n_e) -> float:
    """Area between inner edge vi→vj and the two support lines at its ends [m²].

    inf when the support lines do not close a triangle on the edge's outer side.
    """
    mat = np.column_stack([d_out_i, d_in_j])
    det = mat[0, 0] * mat[1, 1] - mat[0, 1] * mat[1, 0]
    if abs(det) < 1e-9:
        return math.inf
    a, b = np.linalg.solve(mat, n_e)
    if a < -1e-9 or b < -1e-9:
        return math.inf
    x = np.linalg.solve(mat.T, [d_out_i @ vi, d_in_j @ vj])  # support lines' intersection
    e, r = vj - vi, x - vi
    return 0.5 * abs(e[0] * r[1] - e[1] * r[0])


def _cone_and_grip_holds(stance: Stance) -> tuple[list[Hold], list[Hold]]:
    grips = [h for h in stance.holds if isinstance(h.limits, HandLimits)]
    return [h for h in stance.holds if not isinstance(h.limits, HandLimits)], grips


class _ProjectionLP:
    """max d·c over the static-equilibrium polytope in (λ, y, c_xy), for varying d: λ the
    cone coefficients of the point contacts, y the split wrenches of the grips."""

    def __init__(self, points: np.ndarray, edges: np.ndarray, box_half_m: float,
                 grips: tuple[tuple[np.ndarray, np.ndarray, np.ndarray], ...] = (),
                 wrench_max: float = np.inf):
        n_lam = edges.shape[0] * edges.shape[1]
        n_y = 12 * len(grips)
        n = n_lam + n_y
        all_pts = np.vstack([points.reshape(-1, 3)] + [g[0][None] for g in grips])
        self.center = all_pts[:, :2].mean(axis=0)
        origin = np.array([*self.center, all_pts[:, 2].mean()])
        rel = points.reshape(-1, 3) - origin  # moments about the centroid, for conditioning
        e = edges.reshape(-1, 3)
        r = np.repeat(rel, edges.shape[1], axis=0)
        a_eq = np.zeros((6, n + 2))
        a_eq[:3, :n_lam] = e.T  # Σf = m g ẑ, forces in body weights
        a_eq[3:, :n_lam] = np.cross(r, e).T  # Σ r×f + Σ t + (c − o)×(−m g ẑ) = 0
        a_ub, b_ub = np.zeros((0, n + 2)), np.zeros(0)
        for i, (p, rows, rhs) in enumerate(grips):
            cols = slice(n_lam + 12 * i, n_lam + 12 * (i + 1))
            a_eq[:, cols] = split_wrench_basis(p - origin)
            block = np.zeros((len(rows), n + 2))
            block[:, cols] = rows
            a_ub, b_ub = np.vstack([a_ub, block]), np.concatenate([b_ub, rhs])
        a_eq[3, n + 1] = -1.0  # x row: −(c_y − o_y)
        a_eq[4, n] = 1.0  # y row: +(c_x − o_x)
        self.a_eq, self.a_ub, self.b_ub = a_eq, a_ub, b_ub
        self.b_eq = np.array([0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
        self.bounds = np.zeros((n + 2, 2))
        self.bounds[:n_lam, 1] = np.inf
        self.bounds[n_lam:n, 1] = wrench_max
        self.bounds[n:, 0] = -box_half_m
        self.bounds[n:, 1] = box_half_m
        self.box_half_m = box_half_m
        self.n_lam = n
        self.count = 0

    def solve(self, d: np.ndarray) -> np.ndarray | None:
        """The maximiser c_xy [m] (world), or None if the equilibrium is infeasible."""
        cost = np.zeros(self.n_lam + 2)
        cost[self.n_lam:] = -d
        self.count += 1
        ub = {} if not len(self.b_ub) else {"A_ub": self.a_ub, "b_ub": self.b_ub}
        res = linprog(cost, A_eq=self.a_eq, b_eq=self.b_eq, bounds=self.bounds, method="highs",
                      **ub)
        if res.status == 2:
            return None
        if res.status != 0:
            raise StabilityError(f"support-region LP in direction {d} failed: {res.message}")
        return res.x[self.n_lam:] + self.center

def support_region(stance: Stance, mass_kg: float, g: float = GRAVITY_M_S2, *,
                   config: StabilityConfig | None = None) -> SupportRegion:
    """CoM support region of a stance (Bretl & Lall 2008, iterative projection).

    Static equilibrium Σf = m g ẑ and Σ p×f + c×(−m g ẑ) = 0 with f in the linearised
    cones is linear in (λ, c_x, c_y). Its projection on (c_x, c_y) is found by LPs that
    maximise d·c: start with four directions, then repeatedly probe the outward normal of
    the inner-polygon edge with the largest gap to the outer polygon (the support lines),
    until the gap is below ``max(area_tol_m2, area_rel_tol × area)`` or every edge is
    exact. With pure friction cones the region does not depend on mass or g (both scale
    the forces only); a grip's limits (a hand hold with ``limits``) are forces, and with
    them it does.

    Contacts that can pull (a hand hold without limits) can make the region unbounded; the
    LP caps c_xy to a square of half-side ``config.box_half_m`` around the contacts'
    centroid, and the result is then flagged ``clipped``.

    Args:
        stance: the holds; ``stance.points_normals()`` gives the contacts.
        mass_kg: robot mass [kg] (positive).
        g: gravity [m/s²] (positive).
        config: tunables, `default_config()` if None.

    Returns:
        The inner polygon, counter-clockwise; empty if no CoM position is in equilibrium.
    """
    cfg = config or default_config()
    if mass_kg <= 0 or g <= 0:
        raise ValueError(f"mass_kg and g must be positive, got {mass_kg}, {g}")
    lp = _stance_projection_lp(stance, mass_kg * g, cfg)
    polygon = _initial_polygon(lp, cfg)
    if polygon is None:
        region = SupportRegion(np.zeros((0, 2)), lp_count=lp.count)
        log.debug("support region of %r: %r", stance, region)
        return region
    gap = _refine(polygon, lp, cfg, stance)

    verts = _drop_collinear(polygon.verts, cfg.edge_tol_m)
    v = np.asarray(verts)
    clipped = bool(np.any(np.abs(v - lp.center) >= cfg.box_half_m - 1e-6))
    region = SupportRegion(v, area_m2=abs(_polygon_area(verts)), gap_m2=gap, clipped=clipped,
                           lp_count=lp.count)
    log.debug("support region of %r: %r", stance, region)
    return region


def _stance_projection_lp(stance: Stance, weight_n: float,
                          cfg: StabilityConfig) -> _ProjectionLP:
    """The equilibrium LP of a stance's contacts: its feet's points in their linearised
    cones, its limited grips as split wrenches (forces in body weights of ``weight_n``)."""
    cones, grip_holds = _cone_and_grip_holds(stance)
    points = np.vstack([h.points_m for h in cones]) if cones else np.zeros((0, 3))
    normals = np.vstack([h.normals for h in cones]) if cones else np.zeros((0, 3))
    mu = np.concatenate([np.full(len(h.points_m), h.friction) for h in cones]) if cones \
        else np.zeros(0)
    edges = friction_cone_edges(normals, mu, cfg.cone_edges) if cones \
        else np.zeros((0, cfg.cone_edges, 3))
    grips = tuple((h.T_world_frame[:3, 3], *grip_rows(h.limits, weight_n))
                  for h in grip_holds)
    return _ProjectionLP(np.asarray(points, float), edges, cfg.box_half_m, grips,
                         cfg.force_max_weights)


@dataclass
class _InnerPolygon:
    """The inner approximation of the region while it is refined.

    Attributes:
        verts: vertices, counter-clockwise [m].
        d_in, d_out: per vertex, the range of LP directions [d_in, d_out] it is known to
            be the optimum of (the support lines that bound the outer polygon).
        exact: per edge ``verts[i] → verts[i+1]``, whether it is known to lie on the
            region's boundary.
    """

    verts: list[np.ndarray]
    d_in: list[np.ndarray]
    d_out: list[np.ndarray]
    exact: list[bool] = field(default_factory=list)


def _initial_polygon(lp: _ProjectionLP, cfg: StabilityConfig) -> _InnerPolygon | None:
    """The polygon of the four axis-direction probes, or None if no CoM is in equilibrium.

    Probes run counter-clockwise; consecutive equal points are merged, keeping the range
    of directions each vertex is known to be optimal for.
    """
    verts: list[np.ndarray] = []
    d_in: list[np.ndarray] = []
    d_out: list[np.ndarray] = []
    for ang in (0.0, 0.5 * np.pi, np.pi, 1.5 * np.pi):
        d = np.array([math.cos(ang), math.sin(ang)])
        c = lp.solve(d)
        if c is None:
            return None
        if verts and np.linalg.norm(c - verts[-1]) <= cfg.edge_tol_m:
            d_out[-1] = d
        else:
            verts.append(c)
            d_in.append(d)
            d_out.append(d)
    if len(verts) > 1 and np.linalg.norm(verts[-1] - verts[0]) <= cfg.edge_tol_m:
        d_in[0] = d_in.pop()
        verts.pop()
        d_out.pop()
    return _InnerPolygon(verts, d_in, d_out, [False] * len(verts))


def _refine(polygon: _InnerPolygon, lp: _ProjectionLP, cfg: StabilityConfig,
            stance: Stance) -> float:
    """Probe the outward normal of the edge with the largest gap until the outer − inner
    area is small or the LP budget is spent; ``polygon`` grows in place.

    Returns:
        The remaining gap between the outer and inner polygons [m²].
    """
    verts, d_in, d_out, exact = polygon.verts, polygon.d_in, polygon.d_out, polygon.exact
    gap = 0.0
    while len(verts) > 1:
        m = len(verts)
        gaps = np.zeros(m)
        normals_e = []
        for i in range(m):
            vi, vj = verts[i], verts[(i + 1) % m]
            e = vj - vi
            n_e = np.array([e[1], -e[0]]) / max(float(np.hypot(*e)), 1e-300)
            normals_e.append(n_e)
            if not exact[i]:
                gaps[i] = _edge_gap(vi, vj, d_out[i], d_in[(i + 1) % m], n_e)
        gap = float(gaps.sum())
        area = _polygon_area(verts)
        if gap <= max(cfg.area_tol_m2, cfg.area_rel_tol * area):
            break
        if lp.count >= cfg.max_lps:
            log.warning("support region of %r: stopped at %d LPs with a gap of %.2g m²",
                        stance, lp.count, gap)
            break
        i = int(np.argmax(gaps))
        n_e = normals_e[i]
        c = lp.solve(n_e)
        if c is None:  # cannot happen after a feasible probe, barring numerics
            raise StabilityError(f"support-region LP became infeasible for {stance!r}")
        if n_e @ (c - verts[i]) <= cfg.edge_tol_m:
            exact[i] = True
        else:
            verts.insert(i + 1, c)
            d_in.insert(i + 1, n_e)
            d_out.insert(i + 1, n_e)
            exact[i] = False
            exact.insert(i + 1, False)
    return gap


def _drop_collinear(verts: list[np.ndarray], tol_m: float) -> list[np.ndarray]:
    """Remove vertices within ``tol_m`` of the segment joining their neighbours.

    A polygon whose points all lie within ``tol_m`` of one line becomes that segment.
    """
    if len(verts) >= 3:
        a = np.asarray(verts)
        d2 = ((a[:, None, :] - a[None, :, :]) ** 2).sum(axis=2)
        i, j = np.unravel_index(int(np.argmax(d2)), d2.shape)
        if d2[i, j] == 0.0:
            return [verts[0]]
        e = a[j] - a[i]
        dist = np.abs(e[0] * (a[:, 1] - a[i, 1]) - e[1] * (a[:, 0] - a[i, 0])) / np.sqrt(d2[i, j])
        if np.all(dist <= tol_m):
            return [verts[min(i, j)], verts[max(i, j)]]
    out = list(verts)
    i = 0
    while len(out) > 3 and i < len(out):
        a, b, c = out[i - 1], out[i], out[(i + 1) % len(out)]
        e = c - a
        ln = float(np.hypot(*e))
        if ln > 0 and abs(e[0] * (b - a)[1] - e[1] * (b - a)[0]) / ln <= tol_m:
            out.pop(i)
        else:
            i += 1
    return out

