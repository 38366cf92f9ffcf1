"""Static stability of a stance: CoM support region and joint-torque feasibility.

Two tests, both on linearised Coulomb friction cones (thesis §6.3.1, μ = 0.4):

1. `support_region` — the set of horizontal CoM positions (x, y) for which gravity can be
   balanced by contact forces inside the friction cones, for non-coplanar contacts
   (Bretl & Lall 2008, "Testing static equilibrium for legged robots"). The equilibrium
   equations are linear in the cone coefficients λ and in the CoM's (x, y), so the region
   is the projection of a polytope onto (x, y); it is computed by the iterative LP method
   (inner and outer polygons refined until their area gap is small). Computed once per
   stance; `SupportRegion.margin` is then a cheap per-configuration test.
2. `torque_feasibility` — with hands gripping, the CoM test alone lets much pass: a
   hand can pull hard enough to hold a CoM far from the feet. This LP balances the
   generalized gravity of a configuration with contact wrenches, exactly on the
   free-flyer rows, and minimises the worst joint-torque ratio max_j |τ_j| / τmax_j.

Contacts (`ladders.contact_model`, issue 22): a foot is point contacts at the corners of
its contact patch, in friction cones; a hand with grip limits (``Hold.limits``, a
`ladders.contact_model.HandLimits`) is a 6-D wrench about its palm frame inside the
linearised grip capacity, the same limits the MuJoCo latch lets go at. Among equally good
load shares the LP takes the one that loads the grips least (`GRIP_LOAD_COST`).

The CoM region is exactly the set of CoM positions for which the free-flyer rows of the
torque LP are feasible (same contacts, same cones), so a configuration whose CoM lies
outside the region can skip the torque LP (`check_stability` does).

Frames: world x forward, y left, z up; gravity along −z. Forces are those the environment
applies to the robot [N].

Size: the support region and the torque LP share the contact model's linearised
cones and wrench bases; they are the candidates for two modules (support_region,
torque_lp) once the contact model (issue 22) settles.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
from scipy.optimize import linprog

from ladders.contact_model import FootPatch, HandLimits
from planner.contacts import LIMB_FRAME, Hold, Stance
from robot.constants import GRAVITY_M_S2
from robot.errors import HuboLadderError
from robot.vocabulary import Limb

log = logging.getLogger(__name__)

__all__ = [
    "StabilityConfig",
    "StabilityError",
    "StabilityReport",
    "SupportRegion",
    "TorqueCheck",
    "check_stability",
    "default_config",
    "friction_cone_edges",
    "support_region",
    "torque_feasibility",
    "torque_limits_by_joint",
    "GRIP_LOAD_COST",
    "OBJECTIVES",
]

#: Cost of a hand's wrench in the torque LP, per unit of its use of the grip (each
#: component as a share of its radial or bending capacity), against 1 per unit of the
#: worst joint ratio. The min-max optimum leaves the share of the load between grips and
#: feet free (only the worst joint counts); without a cost HiGHS returns any vertex of
#: that face, often a grip at its limit. The compliant arms give less than the LP asks
#: (`planner.statics.arm_capacity`), so among equal optima the least-loaded grip is the
#: plan the robot follows best. Small enough to move the optimum's ratio by < 0.005.
GRIP_LOAD_COST = 1e-3
#: What `torque_feasibility` minimises: the worst joint ratio (the planner's test), or the
#: worst grip utilisation with the joints within their limits (check-plan's contact check).
OBJECTIVES = ("torque", "contact")


class StabilityError(HuboLadderError):
    """An LP of the stability test failed for a reason other than infeasibility."""


@dataclass(frozen=True)
class StabilityConfig:
    """Tunables of the stability tests.

    Attributes:
        cone_edges: edges k of each linearised friction cone (inner pyramid).
        box_half_m: the CoM LPs are capped to a square of this half-side around the
            contacts' centroid [m]; contacts that can pull (hands) make the region
            unbounded, and it is then clipped to this square.
        area_tol_m2: stop refining when outer − inner area < this [m²] ...
        area_rel_tol: ... or < this fraction of the inner area.
        edge_tol_m: an LP point less than this beyond an inner edge closes the edge [m].
        max_lps: hard cap on LPs per region (a warning is logged when reached).
        force_max_weights: upper bound of each cone coefficient, in body weights; only
            keeps the torque LP bounded when contacts can squeeze each other.
    """

    cone_edges: int = 8
    box_half_m: float = 5.0
    area_tol_m2: float = 1e-4
    area_rel_tol: float = 0.01
    edge_tol_m: float = 1e-5
    max_lps: int = 60
    force_max_weights: float = 20.0


def default_config() -> StabilityConfig:
    """The default `StabilityConfig` (k = 8 cone edges, ±5 m box, 1e-4 m² or 1 % gap)."""
    return StabilityConfig()


# --------------------------------------------------------------------------------------
# Friction cones


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
def _cone_edges_cached(normals_bytes: bytes, mu: float, k: int) -> np.ndarray:
    """`friction_cone_edges` of a hold's normals, memoised: the torque LP runs on every
    interpolated configuration of a stance whose cones never change."""
    edges = friction_cone_edges(np.frombuffer(normals_bytes).reshape(-1, 3), mu, k)
    edges.setflags(write=False)
    return edges


# --------------------------------------------------------------------------------------
# CoM support region


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


def _skew(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def _split_wrench_basis(offset_m: np.ndarray) -> np.ndarray:
    """(6, 12): a wrench (force, torque about a point ``offset_m`` from the moment origin)
    as the difference of two non-negative 6-vectors, mapped to (force, moment about the
    origin)."""
    w = np.eye(6)
    w[3:, :3] = _skew(offset_m)
    return np.hstack([w, -w])


def _grip_rows(limits: HandLimits, weight_n: float) -> tuple[np.ndarray, np.ndarray]:
    """A grip's halfspaces on its split wrench variables (body weights): (m, 12), (m,)."""
    a, b = limits.halfspaces()
    return np.hstack([a, -a]), b / weight_n


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
            a_eq[:, cols] = _split_wrench_basis(p - origin)
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
    cones, grip_holds = _cone_and_grip_holds(stance)
    weight_n = mass_kg * g
    points = np.vstack([h.points_m for h in cones]) if cones else np.zeros((0, 3))
    normals = np.vstack([h.normals for h in cones]) if cones else np.zeros((0, 3))
    mu = np.concatenate([np.full(len(h.points_m), h.friction) for h in cones]) if cones \
        else np.zeros(0)
    edges = friction_cone_edges(normals, mu, cfg.cone_edges) if cones \
        else np.zeros((0, cfg.cone_edges, 3))
    grips = tuple((h.T_world_frame[:3, 3], *_grip_rows(h.limits, weight_n))
                  for h in grip_holds)
    lp = _ProjectionLP(np.asarray(points, float), edges, cfg.box_half_m, grips,
                       cfg.force_max_weights)

    # Initial probes, counter-clockwise; consecutive equal points are merged, keeping the
    # range of directions [d_in, d_out] each vertex is known to be optimal for.
    verts: list[np.ndarray] = []
    d_in: list[np.ndarray] = []
    d_out: list[np.ndarray] = []
    for ang in (0.0, 0.5 * np.pi, np.pi, 1.5 * np.pi):
        d = np.array([math.cos(ang), math.sin(ang)])
        c = lp.solve(d)
        if c is None:
            region = SupportRegion(np.zeros((0, 2)), lp_count=lp.count)
            log.debug("support region of %r: %r", stance, region)
            return region
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
    exact = [False] * len(verts)  # exact[i]: edge verts[i] → verts[i+1] is on the boundary

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

    verts = _drop_collinear(verts, cfg.edge_tol_m)
    v = np.asarray(verts)
    clipped = bool(np.any(np.abs(v - lp.center) >= cfg.box_half_m - 1e-6))
    region = SupportRegion(v, area_m2=abs(_polygon_area(verts)), gap_m2=gap, clipped=clipped,
                           lp_count=lp.count)
    log.debug("support region of %r: %r", stance, region)
    return region


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


# --------------------------------------------------------------------------------------
# Joint-torque feasibility


def torque_limits_by_joint(robot: str = "drc-hubo") -> dict[str, float]:
    """Torque limit of every joint that has one, by joint name [N·m]."""
    from robot.joints import JOINT_NAMES
    from robot.limits import joint_limits

    lim = joint_limits(robot).torque_max_nm
    return {n: float(t) for n, t in zip(JOINT_NAMES, lim, strict=True) if t > 0}


_HIGHS = None


def _solve_min_max_lp(cost: np.ndarray, a_ub: np.ndarray, b_ub: np.ndarray, a_eq: np.ndarray,
                      b_eq: np.ndarray, upper: np.ndarray) -> tuple[str, np.ndarray | None]:
    """min cost·x s.t. a_ub x ≤ b_ub, a_eq x = b_eq, 0 ≤ x ≤ upper, with HiGHS directly.

    The torque LP runs on every interpolated configuration; scipy's ``linprog`` wrapper
    costs more than HiGHS's solve of this small dense LP (≈ 2.8 against 1.5 ms). One
    solver instance per process is reused; presolve is off (it only reformulates this
    LP, and the optimum is the same).

    Returns:
        ``("optimal", x)``, ``("infeasible", None)`` or (HiGHS's status name, None).
    """
    import highspy

    global _HIGHS
    if _HIGHS is None:
        _HIGHS = highspy.Highs()
        _HIGHS.setOptionValue("output_flag", False)
        _HIGHS.setOptionValue("presolve", "off")
    inf = highspy.kHighsInf
    a = np.vstack([a_ub, a_eq])
    lp = highspy.HighsLp()
    lp.num_col_, lp.num_row_ = a.shape[1], a.shape[0]
    lp.col_cost_ = cost
    lp.col_lower_ = np.zeros(a.shape[1])
    lp.col_upper_ = np.where(np.isinf(upper), inf, upper)
    lp.row_lower_ = np.concatenate([np.full(len(b_ub), -inf), b_eq])
    lp.row_upper_ = np.concatenate([b_ub, b_eq])
    lp.a_matrix_.format_ = highspy.MatrixFormat.kRowwise
    rows, cols = np.nonzero(a)
    lp.a_matrix_.start_ = np.concatenate([[0], np.cumsum(np.count_nonzero(a, axis=1))])
    lp.a_matrix_.index_ = cols
    lp.a_matrix_.value_ = a[rows, cols]
    _HIGHS.passModel(lp)
    _HIGHS.run()
    status = _HIGHS.getModelStatus()
    if status == highspy.HighsModelStatus.kOptimal:
        return "optimal", np.array(_HIGHS.getSolution().col_value)
    if status == highspy.HighsModelStatus.kInfeasible:
        return "infeasible", None
    return _HIGHS.modelStatusToString(status), None


@dataclass(frozen=True, eq=False)
class TorqueCheck:
    """Result of `torque_feasibility`.

    Attributes:
        feasible: the equilibrium LP is feasible and ``max_ratio <= 1`` (and, for the
            ``contact`` objective, every grip within its limits).
        equilibrium: contact wrenches within the contacts' limits can balance gravity
            (free-flyer rows; with the ``contact`` objective, with the joints within
            their limits too).
        max_ratio: max_j |τ_j| / τmax_j of the solution (the minimum over contact
            wrenches for the ``torque`` objective; inf if no equilibrium).
        worst_joint: joint reaching ``max_ratio`` ("" if no equilibrium).
        forces_n: per limb, (k, 3) world-frame forces on the robot at the hold's points
            [N]; a grip's is (1, 3), at its palm frame.
        joint_names: actuated joints, in pinocchio velocity order.
        torques_nm: (len(joint_names),) joint torques holding the configuration [N·m].
        wrenches: per limb, the (force [N], torque [N·m]) the hold applies to the robot
            about its limb frame's origin (palm or sole), world frame.
        contact_use: per limb whose hold has limits, each limit's use: a grip's
            `ladders.contact_model.GRIP_LOADS` as shares of its whole capacity, a foot's
            friction and centre of pressure (`ladders.contact_model.FootPatch.utilisation`).
        objective: what the LP minimised (`OBJECTIVES`).
        grip_share: for the ``contact`` objective, the LP's bound on the grips' use
            (≥ every grip's linearised use).
    """

    feasible: bool
    equilibrium: bool
    max_ratio: float
    worst_joint: str
    forces_n: dict[str, np.ndarray] = field(default_factory=dict, repr=False)
    joint_names: tuple[str, ...] = field(default=(), repr=False)
    torques_nm: np.ndarray = field(default_factory=lambda: np.zeros(0), repr=False)
    wrenches: dict[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict,
                                                               repr=False)
    contact_use: dict[str, dict[str, float]] = field(default_factory=dict, repr=False)
    objective: str = "torque"
    grip_share: float = math.nan

    def torque(self, joint: str) -> float:
        """Torque of one joint [N·m]."""
        return float(self.torques_nm[self.joint_names.index(joint)])

    def worst_contact(self, hands_only: bool = False) -> tuple[str, str, float]:
        """(limb, limit, use) of the most used contact limit (of the grips only, if
        ``hands_only``); ("", "", 0) if none."""
        best = ("", "", 0.0)
        for limb, use in self.contact_use.items():
            if hands_only and not Limb(limb).is_hand:
                continue
            for load, u in use.items():
                if u > best[2]:
                    best = (limb, load, u)
        return best

    def __repr__(self) -> str:
        if not self.equilibrium:
            return "TorqueCheck(infeasible: no contact forces balance gravity)"
        loads = ", ".join(f"{limb} {np.linalg.norm(f.sum(axis=0)):.0f} N"
                          for limb, f in self.forces_n.items())
        verdict = "feasible" if self.feasible else "INFEASIBLE"
        limb, load, use = self.worst_contact()
        grip = f"; {limb} {load} {use:.2f} of its limit" if limb else ""
        return (f"TorqueCheck({verdict}, max |τ|/τmax = {self.max_ratio:.3f} at "
                f"{self.worst_joint}, {self.torque(self.worst_joint):+.1f} N·m; {loads}{grip})")


#: `_actuated` per model and limits: (model, result), keyed by the model's id and the
#: limits' items. The torque LP runs ~13,000 times a rung on a handful of limit tables,
#: and walking the model's joints took a tenth of its time.
_ACTUATED: dict[tuple[int, frozenset], tuple[object, tuple]] = {}


def _cross_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Row-wise ``a × b`` of (n, 3) arrays: `np.cross`'s arithmetic without its axis
    handling, which cost more than the products on the torque LP's few rows."""
    out = np.empty_like(b)
    out[:, 0] = a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1]
    out[:, 1] = a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2]
    out[:, 2] = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]
    return out


def _actuated(model, torque_max_nm_by_joint: Mapping[str, float]):
    """Names, velocity indices, limits of the model's actuated (1-dof) joints and the
    model's weight [N] (memoised per model and limits)."""
    key = (id(model), frozenset(torque_max_nm_by_joint.items()))
    hit = _ACTUATED.get(key)
    if hit is not None and hit[0] is model:
        return hit[1]
    result = _walk_actuated(model, torque_max_nm_by_joint)
    _ACTUATED[key] = (model, result)
    return result


def _walk_actuated(model, torque_max_nm_by_joint: Mapping[str, float]):
    names, idx, tmax, missing = [], [], [], []
    for j in range(1, model.njoints):
        if model.joints[j].nv != 1:  # the free flyer
            continue
        name = model.names[j]
        lim = torque_max_nm_by_joint.get(name)
        if lim is None or lim <= 0:
            missing.append(name)
            continue
        names.append(name)
        idx.append(model.joints[j].idx_v)
        tmax.append(float(lim))
    if missing:
        raise HuboLadderError(
            f"no positive torque limit for joints {missing}; limits given for "
            f"{sorted(torque_max_nm_by_joint)}")
    weight_n = float(sum(model.inertias[j].mass for j in range(model.njoints))
                     * np.linalg.norm(model.gravity.linear))
    idx_a, tmax_a = np.array(idx), np.array(tmax)
    idx_a.setflags(write=False)
    tmax_a.setflags(write=False)
    return tuple(names), idx_a, tmax_a, weight_n


def torque_feasibility(model, data, q: np.ndarray, stance: Stance,
                       torque_max_nm_by_joint: Mapping[str, float],
                       frame_ids: Mapping[str, int] | None = None, *,
                       config: StabilityConfig | None = None,
                       objective: str = "torque") -> TorqueCheck:
    """Can the joints hold configuration q on the stance's contacts? (one LP)

    Static equilibrium g(q) = Sᵀτ + Σ Jᵀ w: the free-flyer rows (first 6) are met exactly
    by contact wrenches w, each inside its contact's limits: point forces in the
    linearised cones at a hold's points, or for a hold with grip limits
    (`ladders.contact_model.HandLimits`) a 6-D wrench about its limb frame inside the
    grip's halfspaces. With ``objective="torque"`` the LP minimises t = max_j |τ_j| /
    τmax_j over the actuated joints (epigraph form), plus `GRIP_LOAD_COST` per unit of
    grip use; with ``"contact"`` it keeps every |τ_j| ≤ τmax_j and minimises s, the
    share of their halfspaces' bounds the grips use (check-plan's contact-wrench check).

    Each hold's contact points are rigidly attached to its limb frame: their offsets in
    the frame are taken from the hold (``inv(T_world_frame) @ p``) and placed with the
    frame's pose at q, so a configuration that misses its hold slightly still gets the
    right lever arms. Normals, and therefore friction cones, stay those of the hold
    (world frame), as does a grip's rail axis. The point Jacobian is the frame's
    LOCAL_WORLD_ALIGNED Jacobian shifted to the point, so J_pᵀ f = J_vᵀ f + J_ωᵀ (r × f).

    Args:
        model: pinocchio model with a free-flyer root (gravity from ``model.gravity``).
        data: its pinocchio data (overwritten: kinematics, Jacobians, gravity).
        q: (model.nq,) configuration, free flyer first.
        stance: the holds in contact.
        torque_max_nm_by_joint: torque limit of every actuated joint of the model, by
            name [N·m] (see `torque_limits_by_joint`).
        frame_ids: frame id per limb; looked up from ``LIMB_FRAME`` if None.
        config: tunables, `default_config()` if None.
        objective: one of `OBJECTIVES`.

    Returns:
        The check; ``feasible`` iff the equilibrium is feasible and max ratio ≤ 1.
    """
    import pinocchio as pin

    if objective not in OBJECTIVES:
        raise ValueError(f"unknown objective {objective!r}; use one of {OBJECTIVES}")
    cfg = config or default_config()
    names, v_idx, tmax, weight_n = _actuated(model, torque_max_nm_by_joint)

    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    grav = pin.computeGeneralizedGravity(model, data, q) / weight_n

    cols, parts, grip_rows, cost_parts = [], [], [], []
    for hold in stance.holds:
        if frame_ids is not None and hold.limb in frame_ids:
            fid = frame_ids[hold.limb]
        else:
            fname = LIMB_FRAME[hold.limb]
            if not model.existFrame(fname):
                raise HuboLadderError(f"frame {fname!r} of {hold.limb} is not in the model")
            fid = model.getFrameId(fname)
        o_m_f = data.oMf[fid]
        jac = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
        if isinstance(hold.limits, HandLimits):
            cols.append(jac.T @ _split_wrench_basis(np.zeros(3)))  # (nv, 12)
            rows, rhs = _grip_rows(hold.limits, weight_n)
            grip_rows.append((len(parts), rows, rhs))
            cap = hold.limits.capacity
            per = np.array([cap.radial_n] * 3 + [cap.bending_nm] * 3)
            cost_parts.append(np.tile(GRIP_LOAD_COST * weight_n / per, 2))
            parts.append((hold, o_m_f.rotation.copy(), None, None))
            continue
        t_inv = np.linalg.inv(hold.T_world_frame)
        pts_local = hold.points_m @ t_inv[:3, :3].T + t_inv[:3, 3]
        r = pts_local @ o_m_f.rotation.T  # world-frame offsets from the frame origin [m]
        e = _cone_edges_cached(np.ascontiguousarray(hold.normals, dtype=float).tobytes(),
                               float(hold.friction), cfg.cone_edges)  # (m, k, 3)
        k = e.shape[1]
        e_flat = e.reshape(-1, 3)
        wrench = np.vstack([e_flat.T, _cross_rows(np.repeat(r, k, axis=0), e_flat).T])
        cols.append(jac.T @ wrench)  # (nv, m k), per unit weight
        cost_parts.append(np.zeros(e_flat.shape[0]))
        parts.append((hold, o_m_f.rotation.copy(), e, r))
    gmat = np.hstack(cols)
    n_c = gmat.shape[1]
    starts = np.concatenate([[0], np.cumsum([c.shape[1] for c in cols])])

    # Variables [contacts (body weights), t or s]. τ/W = g_a/W − G_a x.
    g_a, gm_a = grav[v_idx], gmat[v_idx]
    tm = (tmax / weight_n)[:, None]
    if objective == "torque":  # |τ_j| ≤ t τmax_j; grips A y ≤ b
        a_ub = np.block([[gm_a, -tm], [-gm_a, -tm]])
        b_ub = np.concatenate([g_a, -g_a])
    else:  # |τ_j| ≤ τmax_j; grips A y ≤ s b
        a_ub = np.block([[gm_a, np.zeros_like(tm)], [-gm_a, np.zeros_like(tm)]])
        b_ub = np.concatenate([g_a + tm[:, 0], -g_a + tm[:, 0]])
    for i, rows, rhs in grip_rows:
        block = np.zeros((len(rows), n_c + 1))
        block[:, starts[i]:starts[i + 1]] = rows
        if objective == "torque":
            b_ub = np.concatenate([b_ub, rhs])
        else:
            block[:, n_c] = -rhs
            b_ub = np.concatenate([b_ub, np.zeros(len(rhs))])
        a_ub = np.vstack([a_ub, block])
    a_eq = np.hstack([gmat[:6], np.zeros((6, 1))])
    b_eq = grav[:6]
    upper = np.full(n_c + 1, cfg.force_max_weights)
    upper[n_c] = np.inf
    cost = np.concatenate(cost_parts + [[1.0]])
    status, x = _solve_min_max_lp(cost, a_ub, b_ub, a_eq, b_eq, upper)
    if status == "infeasible":
        return TorqueCheck(False, False, math.inf, "", joint_names=names, objective=objective)
    if status != "optimal":
        raise StabilityError(f"torque LP failed for {stance!r}: HiGHS status {status}")

    tau = (g_a - gm_a @ x[:n_c]) * weight_n
    ratios = np.abs(tau) / tmax
    worst = int(np.argmax(ratios))
    forces, wrenches, use = {}, {}, {}
    for i, (hold, rot, e, r) in enumerate(parts):
        xi = x[starts[i]:starts[i + 1]]
        if e is None:  # a grip: its split wrench
            w = (xi[:6] - xi[6:]) * weight_n
            force, torque = w[:3], w[3:]
            forces[hold.limb] = force[None, :]
            use[hold.limb] = hold.limits.utilisation(force, torque)
        else:
            m, k = e.shape[:2]
            f = np.einsum("mk,mki->mi", xi.reshape(m, k), e) * weight_n
            forces[hold.limb] = f
            force, torque = f.sum(axis=0), _cross_rows(r, f).sum(axis=0)
            if isinstance(hold.limits, FootPatch):
                use[hold.limb] = _foot_use(hold.limits, rot, force, torque)
        wrenches[hold.limb] = (force, torque)
    max_ratio = float(ratios[worst])
    share = float(x[n_c]) if objective == "contact" else math.nan
    feasible = max_ratio <= 1.0 + 1e-9 and (objective == "torque" or share <= 1.0 + 1e-9)
    return TorqueCheck(feasible, True, max_ratio, names[worst], forces, names, tau,
                       wrenches, use, objective, share)


def _foot_use(patch: FootPatch, R_world_sole: np.ndarray, force: np.ndarray,
              torque: np.ndarray) -> dict[str, float]:
    """A sole's friction and centre-of-pressure use of its patch, from its wrench about
    the sole frame's origin (world frame)."""
    f_l, t_l = R_world_sole.T @ force, R_world_sole.T @ torque
    fz = float(f_l[2])
    if fz <= 1e-6:  # an unloaded sole: no friction, no centre of pressure to place
        return dict.fromkeys(patch.utilisation(np.array([0.0, 0.0, 1.0]), np.zeros(2)), 0.0)
    return patch.utilisation(f_l, np.array([-t_l[1] / fz, t_l[0] / fz]))


# --------------------------------------------------------------------------------------
# Both


@dataclass(frozen=True, eq=False)
class StabilityReport:
    """CoM margin and (if the CoM passed) the torque check of one configuration.

    Attributes:
        com_m: (3,) whole-body CoM [m].
        margin_m: signed distance of the CoM to the support region's boundary [m].
        torque: the torque check, or None when skipped because the CoM test failed.
        min_margin_m: the margin the CoM had to reach [m].
    """

    com_m: np.ndarray = field(repr=False)
    margin_m: float
    torque: TorqueCheck | None
    min_margin_m: float = 0.0

    @property
    def stable(self) -> bool:
        return (self.margin_m >= self.min_margin_m and self.torque is not None
                and self.torque.feasible)

    def __repr__(self) -> str:
        tq = repr(self.torque) if self.torque is not None else "torque check skipped"
        return (f"StabilityReport({'stable' if self.stable else 'UNSTABLE'}, CoM margin "
                f"{self.margin_m * 100:.1f} cm (need {self.min_margin_m * 100:.1f}), {tq})")


def check_stability(model, data, q: np.ndarray, stance: Stance, region: SupportRegion,
                    torque_max_nm_by_joint: Mapping[str, float], *, min_margin_m: float = 0.0,
                    frame_ids: Mapping[str, int] | None = None,
                    config: StabilityConfig | None = None) -> StabilityReport:
    """CoM-in-region test, then (only if it passes) the torque LP.

    Args:
        model, data: pinocchio model and data (data is overwritten).
        q: (model.nq,) configuration.
        stance: the holds in contact (the one ``region`` was computed for).
        region: ``support_region(stance, ...)``.
        torque_max_nm_by_joint: torque limits by joint name [N·m].
        min_margin_m: required CoM margin [m].
        frame_ids: frame id per limb, looked up if None.
        config: tunables for the torque LP.
    """
    import pinocchio as pin

    com = np.array(pin.centerOfMass(model, data, q))
    margin = region.margin(com)
    torque = None
    if margin >= min_margin_m:
        torque = torque_feasibility(model, data, q, stance, torque_max_nm_by_joint, frame_ids,
                                    config=config)
    return StabilityReport(com, float(margin), torque, min_margin_m)
