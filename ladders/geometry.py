"""Ladder geometry in the world frame: rungs, rails, stringers and the top landing (with
its handrails) as primitive solids.

`LadderGeometry` is the one place where a `LadderSpec` turns into positions. The mesh
(trimesh), the collision objects (coal) and the MJCF body all read its `solids`, so
they cannot disagree. Everything is numpy, in metres, in the world frame (the robot's
start frame) unless a name says ``_L`` (the ladder frame).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import Literal

import numpy as np

from ladders.spec import LANDING_THICKNESS_M, STRINGER_DEPTH_M, STRINGER_WIDTH_M, LadderSpec
from robot.errors import InputError
from robot.vocabulary import SIDES

_SIDE_SIGN = {"left": 1.0, "right": -1.0}  # left = +y_L


def rot_z(angle_rad: float) -> np.ndarray:
    """The rotation by ``angle_rad`` about the z axis."""
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def wrap_rad(angle_rad: float) -> float:
    """``angle_rad`` wrapped into (−π, π]."""
    return math.atan2(math.sin(angle_rad), math.cos(angle_rad))


def _rot_y(angle_rad: float) -> np.ndarray:
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _rot_x(angle_rad: float) -> np.ndarray:
    c, s = math.cos(angle_rad), math.sin(angle_rad)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def make_transform(R: np.ndarray, p: np.ndarray) -> np.ndarray:
    """A 4×4 homogeneous transform from a rotation and a translation [m]."""
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = p
    return T


@dataclass(frozen=True, eq=False)
class Solid:
    """One primitive piece of the ladder.

    Attributes:
        name: Geom name (``rung_0``, ``rail_left``, ``stringer_right``, ...).
        kind: ``"box"`` or ``"cylinder"``; a cylinder's axis is its local z.
        T_world_solid: 4×4 pose of the solid's centre in the world frame.
        half_extents_m: Box: (x, y, z) half sizes [m]. Cylinder: (radius, radius,
            half length) [m].
    """

    name: str
    kind: Literal["box", "cylinder"]
    T_world_solid: np.ndarray
    half_extents_m: np.ndarray

    @property
    def centre_m(self) -> np.ndarray:
        """Centre in the world frame [m], shape (3,)."""
        return self.T_world_solid[:3, 3]

    @property
    def R_world_solid(self) -> np.ndarray:
        """Orientation in the world frame, shape (3, 3)."""
        return self.T_world_solid[:3, :3]

    @property
    def radius_m(self) -> float:
        """Cylinder radius [m] (cylinders only)."""
        return float(self.half_extents_m[0])

    @property
    def half_length_m(self) -> float:
        """Cylinder half length along its axis [m] (cylinders only)."""
        return float(self.half_extents_m[2])

    @property
    def volume_m3(self) -> float:
        """Exact volume of the primitive [m³]."""
        if self.kind == "box":
            return float(8.0 * np.prod(self.half_extents_m))
        return math.pi * self.radius_m**2 * 2.0 * self.half_length_m

    def __repr__(self) -> str:
        c = ", ".join(f"{v:.3f}" for v in self.centre_m)
        h = ", ".join(f"{v:.3f}" for v in self.half_extents_m)
        return f"Solid({self.name!r}, {self.kind}, centre_m=({c}), half_extents_m=({h}))"


@dataclass(frozen=True, eq=False)
class LadderGeometry:
    """World-frame geometry of a ladder described by a `LadderSpec`.

    Build it with ``LadderGeometry(spec)`` or `ladder_geometry`.

    Attributes:
        spec: The spec it was built from.
    """

    spec: LadderSpec

    # --- frames -------------------------------------------------------------------
    @cached_property
    def T_world_ladder(self) -> np.ndarray:
        """4×4 pose of the ladder frame L in the world frame (the placement)."""
        s = self.spec
        return make_transform(rot_z(s.placement_yaw_rad),
                              np.array([s.placement_x_m, s.placement_y_m, 0.0]))

    @property
    def R_world_ladder(self) -> np.ndarray:
        """Rotation of L in the world frame, shape (3, 3)."""
        return self.T_world_ladder[:3, :3]

    def to_world(self, p_L: np.ndarray) -> np.ndarray:
        """Points from the ladder frame to the world frame [m], shape (..., 3)."""
        return np.asarray(p_L, dtype=float) @ self.R_world_ladder.T + self.T_world_ladder[:3, 3]

    def to_ladder(self, p_world: np.ndarray) -> np.ndarray:
        """Points from the world frame to the ladder frame [m], shape (..., 3)."""
        return (np.asarray(p_world, dtype=float) - self.T_world_ladder[:3, 3]) @ self.R_world_ladder

    @cached_property
    def ladder_direction(self) -> np.ndarray:
        """Unit vector up the rung line in the world frame: R·(cos slope, 0, sin slope)."""
        a = self.spec.slope_rad
        return self.R_world_ladder @ np.array([math.cos(a), 0.0, math.sin(a)])

    @property
    def lateral_direction(self) -> np.ndarray:
        """Unit vector y_L (towards the left rail) in the world frame."""
        return self.R_world_ladder[:, 1].copy()

    @cached_property
    def rung_line_normal(self) -> np.ndarray:
        """Unit normal of the rung line in the x_L–z_L plane, pointing up/back towards the
        climber: R·(−sin slope, 0, cos slope)."""
        a = self.spec.slope_rad
        return self.R_world_ladder @ np.array([-math.sin(a), 0.0, math.cos(a)])

    # --- rungs --------------------------------------------------------------------
    def _rung_top_L(self, i: int) -> np.ndarray:
        return np.array([self.spec.rung_run_m(i), 0.0, self.spec.rung_height_m(i)])

    @cached_property
    def rung_top_centres_m(self) -> np.ndarray:
        """Top-surface centres of all rungs in the world frame [m], shape (N, 3)."""
        pts = np.array([self._rung_top_L(i) for i in range(self.spec.num_rungs)])
        return self.to_world(pts)

    def rung_top_point(self, i: int, lateral_m: float = 0.0, along_m: float = 0.0) -> np.ndarray:
        """A point on rung ``i``'s top surface in the world frame [m].

        Args:
            i: Rung index, 0-based.
            lateral_m: Offset along y_L from the rung centre (left positive) [m].
            along_m: Offset along x_L (up-ladder positive) [m]; the tread spans
                ±rung_depth_m/2 (the top line of a cylinder rung is at 0).

        Raises:
            InputError: ``i`` is not a rung index.
        """
        self._check_rung(i)
        return self.to_world(self._rung_top_L(i) + np.array([along_m, lateral_m, 0.0]))

    def _check_rung(self, i: int) -> None:
        if not 0 <= i < self.spec.num_rungs:
            raise InputError(f"rung index {i} out of range: ladder '{self.spec.name}' has "
                             f"rungs 0..{self.spec.num_rungs - 1}")

    @cached_property
    def rungs(self) -> tuple[Solid, ...]:
        """The rungs, ``rung_0`` at the bottom. Boxes are axis-aligned in L (horizontal
        treads); cylinders have their axis along y_L."""
        s = self.spec
        if s.rung_shape == "box":
            R_L = np.eye(3)
            half = np.array([s.rung_depth_m / 2, s.rung_width_m / 2, s.rung_thickness_m / 2])
            drop_m = s.rung_thickness_m / 2
        else:  # axis (local z) along y_L
            R_L = _rot_x(-math.pi / 2)
            r = s.rung_depth_m / 2
            half = np.array([r, r, s.rung_width_m / 2])
            drop_m = r
        R = self.R_world_ladder @ R_L
        return tuple(
            Solid(f"rung_{i}", s.rung_shape,
                  make_transform(R, self.to_world(self._rung_top_L(i) - [0.0, 0.0, drop_m])),
                  half.copy())
            for i in range(s.num_rungs))

    # --- rails --------------------------------------------------------------------
    @cached_property
    def _rail_axes(self) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        s = self.spec
        # From above the rung line's floor point to above a virtual rung N, or to above
        # where the rung line reaches the landing's top.
        end_L = self._rung_line_point_L(self.landing_top_height_m if s.has_landing
                                        else s.rung_height_m(s.num_rungs))
        out = {}
        for side in SIDES:
            offset_L = np.array([0.0, _SIDE_SIGN[side] * s.rail_spacing_m / 2, s.rail_height_m])
            out[side] = (self.to_world(offset_L), self.to_world(end_L + offset_L))
        return out

    def rail_axis(self, side: str) -> tuple[np.ndarray, np.ndarray]:
        """End points (p0 bottom, p1 top) of a rail's axis in the world frame [m].

        The rail runs from x_L = 0 to one rung spacing beyond the top rung (with a
        landing: to where the rung line reaches the landing's top), its axis
        ``rail_height_m`` vertically above the rung line.

        Args:
            side: ``"left"`` (+y_L) or ``"right"``.

        Raises:
            InputError: Unknown side.
        """
        if side not in _SIDE_SIGN:
            raise InputError(f"unknown rail side '{side}': use one of {', '.join(SIDES)}")
        p0, p1 = self._rail_axes[side]
        return p0.copy(), p1.copy()

    def rail_point_above_rung(self, side: str, i: int) -> np.ndarray:
        """The point of a rail axis vertically above rung ``i``'s top centre line [m], world.

        That is (d_i, ±rail_spacing/2, h_i + rail_height) in L.
        """
        self._check_rung(i)
        p0, _ = self.rail_axis(side)
        along_m = self.spec.rung_height_m(i) / math.sin(self.spec.slope_rad)
        return p0 + along_m * self.ladder_direction

    def closest_rail_point(self, side: str, p_world: np.ndarray) -> np.ndarray:
        """The point of a rail's axis segment closest to a world point [m].

        Args:
            side: ``"left"`` or ``"right"``.
            p_world: Query point(s) in the world frame, shape (3,) or (K, 3).

        Returns:
            Closest point(s) on the segment, same shape as ``p_world``.
        """
        p0, p1 = self.rail_axis(side)
        d = p1 - p0
        p = np.asarray(p_world, dtype=float)
        t = np.clip((p - p0) @ d / (d @ d), 0.0, 1.0)
        return p0 + np.multiply.outer(t, d)

    @cached_property
    def rails(self) -> tuple[Solid, ...]:
        """The two handrail cylinders (``rail_left``, ``rail_right``), axis = local z."""
        # Local z onto the rung line direction (cos a, 0, sin a): a rotation about y by 90° − a.
        R = self.R_world_ladder @ _rot_y(math.pi / 2 - self.spec.slope_rad)
        out = []
        for side in SIDES:
            p0, p1 = self._rail_axes[side]
            half_len = float(np.linalg.norm(p1 - p0)) / 2
            r = self.spec.rail_radius_m
            out.append(Solid(f"rail_{side}", "cylinder", make_transform(R, (p0 + p1) / 2),
                             np.array([r, r, half_len])))
        return tuple(out)

    # --- stringers ----------------------------------------------------------------
    @cached_property
    def stringers(self) -> tuple[Solid, ...]:
        """The two stringers (``stringer_left``, ``stringer_right``): boxes with local x
        along the rung line, y lateral, z along `rung_line_normal`, centred on the rung
        line, just outside the rung ends. They run from the floor point of the rung line
        to half a rung depth beyond the top rung's centre; their lower back corner dips
        into the floor by up to (depth/2)·cos(slope), as a real ladder's feet would."""
        s = self.spec
        R = self.R_world_ladder @ _rot_y(-s.slope_rad)  # local x -> (cos a, 0, sin a)
        length_m = s.top_rung_height_m / math.sin(s.slope_rad) + s.rung_depth_m / 2
        half = np.array([length_m / 2, STRINGER_WIDTH_M / 2, STRINGER_DEPTH_M / 2])
        out = []
        for side in SIDES:
            y_L = _SIDE_SIGN[side] * (s.rung_width_m / 2 + STRINGER_WIDTH_M / 2)
            a = s.slope_rad
            centre_L = np.array([length_m / 2 * math.cos(a), y_L, length_m / 2 * math.sin(a)])
            out.append(Solid(f"stringer_{side}", "box", make_transform(R, self.to_world(centre_L)),
                             half.copy()))
        return tuple(out)

    # --- landing ------------------------------------------------------------------
    def _rung_line_point_L(self, height_m: float) -> np.ndarray:
        """The rung line's point at ``height_m`` above the floor, in L [m]."""
        return np.array([self.spec.run_at_height_m(height_m), 0.0, height_m])

    @property
    def landing_top_height_m(self) -> float:
        """Height of the landing's top surface above the floor [m] (a ladder with one)."""
        return self.spec.top_rung_height_m + self.spec.landing_height_m

    @cached_property
    def landing(self) -> tuple[Solid, ...]:
        """The top landing (``landing``, a horizontal slab `LANDING_THICKNESS_M` thick)
        and, if the rails go on over it, its handrails (``handrail_left``,
        ``handrail_right``, horizontal cylinders along x_L at the rails' height above
        it); empty without a landing. The landing's front edge stands half a tread in
        front of where the rung line reaches its top, as the next tread would."""
        s = self.spec
        if not s.has_landing:
            return ()
        top = self.landing_top_height_m
        edge_x = s.run_at_height_m(top)  # where the rung line meets the landing's top
        front_x = edge_x - s.rung_depth_m / 2
        back_x = front_x + s.landing_depth_m
        half = np.array([s.landing_depth_m / 2, s.landing_width_m / 2,
                         LANDING_THICKNESS_M / 2])
        centre_L = np.array([(front_x + back_x) / 2, 0.0, top - LANDING_THICKNESS_M / 2])
        out = [Solid("landing", "box", make_transform(self.R_world_ladder,
                                                      self.to_world(centre_L)), half)]
        if s.landing_handrails:
            R = self.R_world_ladder @ _rot_y(math.pi / 2)  # local z along x_L
            r = s.rail_radius_m
            for side in SIDES:
                centre_L = np.array([(edge_x + back_x) / 2,
                                     _SIDE_SIGN[side] * s.rail_spacing_m / 2,
                                     top + s.rail_height_m])
                out.append(Solid(f"handrail_{side}", "cylinder",
                                 make_transform(R, self.to_world(centre_L)),
                                 np.array([r, r, (back_x - edge_x) / 2])))
        return tuple(out)

    # --- everything ---------------------------------------------------------------
    @property
    def solids(self) -> tuple[Solid, ...]:
        """All pieces: rungs, rails, stringers, the landing and its handrails (in that
        order)."""
        return self.rungs + self.rails + self.stringers + self.landing

    def bounds_m(self) -> np.ndarray:
        """Axis-aligned bounds of all solids in the world frame [m], shape (2, 3)."""
        corners = []
        for solid in self.solids:
            h = solid.half_extents_m
            signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
            corners.append((signs * h) @ solid.R_world_solid.T + solid.centre_m)
        pts = np.vstack(corners)
        return np.array([pts.min(axis=0), pts.max(axis=0)])

    def __repr__(self) -> str:
        return (f"LadderGeometry({self.spec.name!r}, {self.spec.num_rungs} rungs, "
                f"slope {self.spec.slope_deg:g} deg, {len(self.solids)} solids)")


def ladder_geometry(spec: LadderSpec) -> LadderGeometry:
    """World-frame geometry of ``spec`` (see `LadderGeometry`)."""
    return LadderGeometry(spec)


__all__ = ["SIDES", "LadderGeometry", "Solid", "ladder_geometry", "make_transform", "rot_z",
           "wrap_rad"]
