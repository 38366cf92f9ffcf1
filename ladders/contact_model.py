"""One description of every contact between a Hubo and a ladder (issue 22).

The planner's holds and torque LP (`planner.holds`, `planner.statics.stability`),
check-plan (`planner.verify.check`) and the MuJoCo grasp latch
(`daemon.sim.grasp_latch`) all read their contact limits from here, so that the planner
never plans a load that the simulated grip or foot cannot carry.

**A hand hold** is a wrench contact on a cylinder: a closed hand on a rail. Its limits
come from the grip's geometry and finger torques (`GripGeometry`), as `GripCapacity`:

======================  ====================================  ========================
load on the hand        capacity                              DRC-Hubo, μ = 0.4
======================  ====================================  ========================
radial force            ``N = n·τ_f / ℓ``                     5·5/0.06 = 417 N
bending torque          ``(τ_f/ℓ)·Σ|x_i|`` (finger couple)      9.0 N·m
force along the rail    ``μ·(2·S + F_r)``, ``S = n·τ_s / ℓ``  67 N + 0.4·F_r
torque about the rail   ``μ·(2·S + F_r)·r_rail``              1.7 N·m + 0.01 m·F_r
======================  ====================================  ========================

``F_r`` is the load across the rail (fingers and palm each press with ``S``, one of them
also with ``F_r``), ``τ_f`` a finger's torque limit (hubo-facts §5, the 5 N·m of
`robot.limits` for ``RF1``…``LF5``), ``τ_s`` its squeeze, ``ℓ`` the finger-joint-to-rail-
axis lever at the grip centre (finger joints 4.5 cm above and 4 cm beside it,
`robot.kinematic_tree`: √(0.045² + 0.04²) = 0.060 m), ``x_i`` the finger positions along
the grip axis (±36, ±18, 0 mm), ``μ`` the ladder's friction and ``r_rail`` its rail
radius. Radial force and bending pull the rail out of the fingers or pry them open: the
latch lets go (`RELEASE_LOADS`). Along and about the rail the grip slips (`SLIP_LOADS`).
The wrench is the one the rail applies to the hand, about the palm site (the grip
centre, on the rail axis), world frame.

The torque LP can take these limits as linear inequalities (`HandLimits.halfspaces`) on
the hand's 6-D wrench, a share of them or whole; check-plan takes them whole. The planner
keeps the thesis's point hold for hands (`planner.holds`): planned with the grip's limits
at a 0.8 reserve, DRC mounts climbed far less often in MuJoCo
(docs/decisions/contact-model.md). The
linearisation is conservative: the radial and bending discs are inscribed polygons, and
the friction along and about the rail counts only the radial load's component along the
*up-radial* direction (``|F_r| ≥ u·F_r``), the direction a hand carrying weight presses
the rail in.

**A foot hold** is a surface or line contact on a rung's tread (`FootPatch`): Coulomb
friction at the spec's μ, and the centre of pressure inside the patch MuJoCo forms
between a flat sole (a box) and the tread. On a box tread that is the sole ∩ tread
overlap; on a round rung (``rung_shape: cylinder``) MuJoCo's box–cylinder contact is a
line across the sole at the rung's top, so the patch has no extent along the sole
(`sole_patch_x`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from robot.kinematic_tree import FINGER_JOINT_ABOVE_GRIP_M, FINGER_JOINT_OUTSET_M

__all__ = ["FINGER_X_M", "GRIP_LOADS", "HUBO_GRIP", "RELEASE_LOADS",
           "SLIP_LOADS", "FootPatch", "GripCapacity", "GripGeometry", "HandLimits",
           "default_grip", "hand_limits", "sole_patch_x"]

#: Finger positions along the grip axis [m] (robot.kinematic_tree: −0.036 + 0.018·i).
FINGER_X_M = (-0.036, -0.018, 0.0, 0.018, 0.036)

#: Loads a closed hand gives way to by slipping on its rail (still latched), in the order
#: the latch reads them: along, about.
SLIP_LOADS = ("force along the rail", "torque about the rail")
#: Loads that pull the rail out of the fingers or pry them open: the grip lets go.
RELEASE_LOADS = ("radial force", "bending torque")
#: Every limit of a hand hold, in `GripCapacity.utilisation`'s order.
GRIP_LOADS = ("radial force", "force along the rail", "torque about the rail",
              "bending torque")

#: A foot patch narrower than this along the sole is a line contact [m].
LINE_CONTACT_M = 1e-4


@dataclass(frozen=True)
class GripGeometry:
    """A Hubo hand's grip on a rail: its fingers' strength and where they sit.

    Attributes:
        finger_torque_nm: torque limit of one finger [N·m] (hubo-facts §5).
        finger_squeeze_nm: torque each closed finger presses the rail with [N·m]: 1 N·m,
            a fifth of the limit (`daemon.sim.grasp_latch` says why neither 0 nor 5).
        finger_lever_m: finger joint to rail axis at the grip centre [m].
        finger_x_m: finger positions along the grip axis [m].
    """

    finger_torque_nm: float = 5.0
    finger_squeeze_nm: float = 1.0
    finger_lever_m: float = round(math.hypot(FINGER_JOINT_OUTSET_M,
                                             FINGER_JOINT_ABOVE_GRIP_M), 3)
    finger_x_m: tuple[float, ...] = FINGER_X_M

    def __post_init__(self) -> None:
        if not (self.finger_torque_nm > 0 and 0 <= self.finger_squeeze_nm
                <= self.finger_torque_nm and self.finger_lever_m > 0 and self.finger_x_m):
            raise ValueError(f"{self!r}: need finger torque > 0, 0 ≤ squeeze ≤ torque, "
                             "lever > 0 and at least one finger")


#: The grip of the DRC-Hubo and Hubo2+ hands. The planner, check-plan and the latch read
#: it through `default_grip` (at call time), so a change here reaches all three.
HUBO_GRIP = GripGeometry()


def default_grip() -> GripGeometry:
    """The Hubo hand's grip (`HUBO_GRIP`)."""
    return HUBO_GRIP


@dataclass(frozen=True)
class GripCapacity:
    """What a closed hand can carry on a rail (module docstring table).

    Attributes:
        radial_n: force across the rail that pulls it out of the fingers [N].
        bending_nm: torque across the rail that pries the fingers open [N·m].
        squeeze_n: force the closed fingers press the rail with [N].
        friction: the ladder's μ [-].
        rail_radius_m: rail radius [m].
    """

    radial_n: float
    bending_nm: float
    squeeze_n: float
    friction: float
    rail_radius_m: float

    @classmethod
    def of(cls, grip: GripGeometry, friction: float, rail_radius_m: float) -> GripCapacity:
        """The capacity of ``grip`` on a rail of ``rail_radius_m`` at friction ``friction``."""
        per_finger_n = grip.finger_torque_nm / grip.finger_lever_m
        n = len(grip.finger_x_m)
        return cls(per_finger_n * n, per_finger_n * sum(abs(x) for x in grip.finger_x_m),
                   n * grip.finger_squeeze_nm / grip.finger_lever_m, friction, rail_radius_m)

    def along_n(self, radial_load_n: float) -> float:
        """Friction along the rail under a load ``radial_load_n`` across it [N]: the
        fingers and the palm each press the rail with the squeeze, one of them also with
        the load."""
        return self.friction * (2.0 * self.squeeze_n + radial_load_n)

    def about_nm(self, radial_load_n: float) -> float:
        """Friction torque about the rail under a load ``radial_load_n`` across it [N·m]."""
        return self.along_n(radial_load_n) * self.rail_radius_m

    def utilisation(self, force_n: np.ndarray, torque_nm: np.ndarray,
                    axis: np.ndarray) -> dict[str, float]:
        """Load / capacity ratio of each of `GRIP_LOADS`; a load along or about an
        unloaded rail is infinitely over what friction holds.

        Args:
            force_n, torque_nm: the rail's wrench on the hand about the grip centre [N],
                [N·m], world frame.
            axis: unit rail direction, world frame.
        """
        fa = float(force_n @ axis)
        ta = float(torque_nm @ axis)
        radial = _norm(force_n - fa * axis)
        return {
            "radial force": radial / self.radial_n,
            "force along the rail": _ratio(abs(fa), self.along_n(radial)),
            "torque about the rail": _ratio(abs(ta), self.about_nm(radial)),
            "bending torque": _norm(torque_nm - ta * axis) / self.bending_nm,
        }


def _ratio(load: float, capacity: float) -> float:
    if capacity > 0.0:
        return load / capacity
    return math.inf if load > 0.0 else 0.0


def _norm(v: np.ndarray) -> float:
    """``float(np.linalg.norm(v))`` of a 1-D float64 vector without its overhead (the
    latch calls this every tick)."""
    return math.sqrt(v.dot(v))


@dataclass(frozen=True, eq=False)
class HandLimits:
    """The limits of one hand hold: the grip's capacity on a rail along ``axis``, of
    which ``share`` may be used (1 in check-plan).

    Attributes:
        capacity: the grip's capacity on this rail.
        axis: (3,) unit rail direction, world frame.
        share: share of the capacity a wrench may use [-].
    """

    capacity: GripCapacity
    axis: np.ndarray
    share: float = 1.0

    def rail_frame(self) -> np.ndarray:
        """(3, 3) columns: the rail axis, the up-radial direction ``u`` (the radial part
        of world up; any radial direction on a vertical rail) and ``axis × u``."""
        a = np.asarray(self.axis, dtype=float)
        a = a / np.linalg.norm(a)
        up = np.array([0.0, 0.0, 1.0])
        u = up - (up @ a) * a
        if np.linalg.norm(u) < 1e-6:
            u = np.array([1.0, 0.0, 0.0]) - a[0] * a
        u /= np.linalg.norm(u)
        return np.column_stack([a, u, np.cross(a, u)])

    def halfspaces(self, polygon_sides: int = 8) -> tuple[np.ndarray, np.ndarray]:
        """The limits as ``A @ [f; t] <= b`` on the hand's wrench (world frame, [N],
        [N·m]), an inner (conservative) linearisation (module docstring).

        Returns:
            ``A`` (2·polygon_sides + 4, 6) and ``b`` [N or N·m].
        """
        cap, rho = self.capacity, self.share
        k = polygon_sides
        ang = (2.0 * np.arange(k) + 1.0) * np.pi / k
        disc = np.column_stack([np.cos(ang), np.sin(ang)])
        inscribed = math.cos(math.pi / k)
        rows, rhs = [], []
        for i in range(k):  # force across the rail
            rows.append([0.0, *disc[i], 0.0, 0.0, 0.0])
            rhs.append(rho * cap.radial_n * inscribed)
        for i in range(k):  # bending torque
            rows.append([0.0, 0.0, 0.0, 0.0, *disc[i]])
            rhs.append(rho * cap.bending_nm * inscribed)
        mu, r = cap.friction, cap.rail_radius_m
        for sign in (1.0, -1.0):  # |f_a| ≤ ρ μ (2S + u·f_r)
            rows.append([sign, -rho * mu, 0.0, 0.0, 0.0, 0.0])
            rhs.append(rho * mu * 2.0 * cap.squeeze_n)
        for sign in (1.0, -1.0):  # |t_a| ≤ ρ μ r (2S + u·f_r)
            rows.append([0.0, -rho * mu * r, 0.0, sign, 0.0, 0.0])
            rhs.append(rho * mu * r * 2.0 * cap.squeeze_n)
        R = self.rail_frame()
        to_rail = np.zeros((6, 6))
        to_rail[:3, :3] = to_rail[3:, 3:] = R.T
        return np.asarray(rows) @ to_rail, np.asarray(rhs)

    def utilisation(self, force_n: np.ndarray, torque_nm: np.ndarray) -> dict[str, float]:
        """Each of `GRIP_LOADS` as a share of the whole capacity (what the latch reads)."""
        return self.capacity.utilisation(np.asarray(force_n, float),
                                         np.asarray(torque_nm, float), self.rail_frame()[:, 0])

    def __repr__(self) -> str:
        c = self.capacity
        return (f"HandLimits(radial {c.radial_n:.0f} N, bending {c.bending_nm:.1f} N·m, along "
                f"{c.along_n(0.0):.0f} N + {c.friction:g}·F_r, about {c.about_nm(0.0):.2f} N·m "
                f"+ {c.friction * c.rail_radius_m:.3g} m·F_r; share {self.share:g})")


def hand_limits(friction: float, rail_radius_m: float, axis: np.ndarray,
                share: float = 1.0, grip: GripGeometry | None = None) -> HandLimits:
    """The limits of a hand closed on a rail along ``axis`` (world), with ``grip`` (the
    Hubo hand's, `default_grip`, if None)."""
    cap = GripCapacity.of(grip or default_grip(), friction, rail_radius_m)
    a = np.asarray(axis, dtype=float)
    return HandLimits(cap, a / np.linalg.norm(a), share)


@dataclass(frozen=True)
class FootPatch:
    """Where a sole's centre of pressure can lie, and its friction.

    Attributes:
        x_range_m: (x0, x1) of the patch along the sole (sole frame x) [m]; equal ends
            for a line contact.
        half_width_m: half the patch across the sole (sole frame y) [m].
        friction: Coulomb μ the foot may use [-].
    """

    x_range_m: tuple[float, float]
    half_width_m: float
    friction: float

    @property
    def is_line(self) -> bool:
        """A line across the sole (a round rung): no centre-of-pressure range along it."""
        return self.x_range_m[1] - self.x_range_m[0] <= LINE_CONTACT_M

    def shrunk(self, margin_m: float) -> FootPatch:
        """The patch ``margin_m`` inside its sides (along x only where it is wider than
        twice that)."""
        x0, x1 = self.x_range_m
        if x1 - x0 > 2 * margin_m:
            x0, x1 = x0 + margin_m, x1 - margin_m
        return FootPatch((x0, x1), self.half_width_m - margin_m, self.friction)

    def corners(self) -> np.ndarray:
        """(4, 3) corners of the patch in the sole frame [m]."""
        (x0, x1), hy = self.x_range_m, self.half_width_m
        return np.array([[x1, hy, 0], [x1, -hy, 0], [x0, -hy, 0], [x0, hy, 0]], dtype=float)

    def utilisation(self, force_sole: np.ndarray, cop_sole_m: np.ndarray) -> dict[str, float]:
        """Friction use ``|f_t| / (μ f_n)`` and the centre of pressure's offset from the
        patch's middle as a share of its half extent, along and across the sole (a line
        patch counts 5 mm along)."""
        f = np.asarray(force_sole, float)
        fn = float(f[2])
        ft = float(np.hypot(f[0], f[1]))
        (x0, x1) = self.x_range_m
        half_x = max((x1 - x0) / 2, 0.005)
        return {
            "friction": _ratio(ft, self.friction * max(fn, 0.0)),
            "CoP along the sole": abs(float(cop_sole_m[0]) - (x0 + x1) / 2) / half_x,
            "CoP across the sole": abs(float(cop_sole_m[1])) / self.half_width_m,
        }


def sole_patch_x(rung_shape: str, tread_half_depth_m: float, tread_centre_x_m: float,
                 foot_length_m: float) -> tuple[float, float] | None:
    """The sole's contact patch along its length (sole-frame x) on a rung [m], or None
    when the sole misses the rung.

    Args:
        rung_shape: ``"box"`` (a flat tread: the sole ∩ tread overlap) or ``"cylinder"``
            (a round rung: a line across the sole at the rung's top, where MuJoCo's
            box–cylinder contact forms).
        tread_half_depth_m: half the tread's depth (box) [m].
        tread_centre_x_m: the tread's centre (a cylinder's top line) in the sole frame [m].
        foot_length_m: sole length [m].
    """
    hl = foot_length_m / 2
    c = float(tread_centre_x_m)
    if rung_shape == "cylinder":
        return (c, c) if -hl <= c <= hl else None
    if rung_shape != "box":
        raise ValueError(f"unknown rung shape {rung_shape!r}; use 'box' or 'cylinder'")
    x0, x1 = max(-hl, c - tread_half_depth_m), min(hl, c + tread_half_depth_m)
    return (x0, x1) if x1 >= x0 else None
