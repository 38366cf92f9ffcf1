"""Holds and stances: which limb touches what, through which point contacts (thesis §6.3.1).

A foot hold is the part of the sole resting on a rung: the corners of its contact patch
(`ladders.contact_model.FootPatch`), each a point contact pushing up with Coulomb
friction μ. A hand hold is a palm closed on a rail: a wrench contact whose limits are the
grip's (`ladders.contact_model.HandLimits`). A hand hold without limits is the thesis's
point hold: one contact that pushes up and one that pulls the hand towards the ladder,
both with friction μ (the CoM tests of `planner.statics.com_region` still take it).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from ladders.contact_model import FootPatch, HandLimits
from robot.vocabulary import LIMBS, Limb  # noqa: F401  (LIMBS re-exported)

#: Operational frame of each limb in the robot model.
LIMB_FRAME = {"left_hand": "L_palm", "right_hand": "R_palm", "left_foot": "L_sole",
              "right_foot": "R_sole"}
#: The hands' limb names: `Hold.is_hand` is asked hundreds of thousands of times a search.
_HANDS = frozenset(limb.value for limb in Limb if limb.is_hand)


@dataclass(frozen=True)
class Hold:
    """One limb's contact with the environment.

    Attributes:
        limb: one of ``LIMBS``.
        target: what is held, e.g. ``"floor"``, ``"rung 3"``, ``"rail left"``.
        T_world_frame: (4, 4) pose the limb's frame must take [m].
        points_m: (k, 3) contact points in the world frame [m].
        normals: (k, 3) unit contact normals (force on the robot pushes along them).
        friction: Coulomb coefficient μ of every contact.
        limits: the contact's limits (`ladders.contact_model`): a hand's grip, which
            replaces its points in the torque LP, or the foot's patch the points are the
            corners of; None for a bare set of point contacts.
    """

    limb: str
    target: str
    T_world_frame: np.ndarray = field(repr=False)
    points_m: np.ndarray = field(repr=False)
    normals: np.ndarray = field(repr=False)
    friction: float = 0.4
    limits: HandLimits | FootPatch | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        Limb(self.limb)  # a ValueError naming an unknown limb

    @property
    def frame(self) -> str:
        return LIMB_FRAME[self.limb]

    @property
    def is_hand(self) -> bool:
        return self.limb in _HANDS

    @cached_property
    def points_in_frame_m(self) -> np.ndarray:
        """The contact points in the coordinates of the limb frame at its hold [m]: a
        search's torque LPs place them thousands of times."""
        t_inv = np.linalg.inv(self.T_world_frame)
        return self.points_m @ t_inv[:3, :3].T + t_inv[:3, 3]

    def __repr__(self) -> str:
        p = self.T_world_frame[:3, 3]
        return f"Hold({self.limb} on {self.target} at [{p[0]:.3f}, {p[1]:.3f}, {p[2]:.3f}])"


@dataclass(frozen=True)
class Stance:
    """A set of 2–4 holds, at most one per limb."""

    holds: tuple[Hold, ...]

    def __post_init__(self) -> None:
        limbs = [h.limb for h in self.holds]
        if len(set(limbs)) != len(limbs):
            raise ValueError(f"a stance holds each limb at most once, got {limbs}")
        if not 1 <= len(limbs) <= 4:
            raise ValueError(f"a stance has 1–4 holds, got {len(limbs)}")

    def hold(self, limb: str) -> Hold | None:
        for h in self.holds:
            if h.limb == limb:
                return h
        return None

    @property
    def limbs(self) -> tuple[str, ...]:
        return tuple(h.limb for h in self.holds)

    def points_normals(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """All contact points (n,3), normals (n,3) and friction coefficients (n,)."""
        pts = np.vstack([h.points_m for h in self.holds])
        nrm = np.vstack([h.normals for h in self.holds])
        mu = np.concatenate([np.full(len(h.points_m), h.friction) for h in self.holds])
        return pts, nrm, mu

    def without(self, limb: str) -> Stance:
        return Stance(tuple(h for h in self.holds if h.limb != limb))

    def with_hold(self, hold: Hold) -> Stance:
        return Stance(tuple(h for h in self.holds if h.limb != hold.limb) + (hold,))

    def __repr__(self) -> str:
        return "Stance(" + ", ".join(f"{h.limb}@{h.target}" for h in self.holds) + ")"
