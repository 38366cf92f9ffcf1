"""Perturbations of a batch run: what ``--perturb`` means and how each draw is made.

``--perturb placement=0.03,yaw=0.05,rung=0.01,friction=0.3:0.5,battery=44:50``

==========  ======================  =====================================================
key         draw                    applied to
==========  ======================  =====================================================
placement   dx, dy ~ U(±value) [m]  the simulated ladder's pose (validate-plan's
                                    ``--placement-error``); the plan is unchanged
yaw         dyaw ~ U(±value) [rad]  the same placement error
rung        δ ~ U(±value) [m]       the simulated ladder's ``rung_spacing_m`` (rung i
                                    moves by i·δ): a ladder built off-spec; the plan
                                    still steps on the nominal rungs
friction    μ ~ U(lo, hi) [-]       the simulated ladder's friction (rungs, rails)
battery     V ~ U(lo, hi) [V]       the board model's battery voltage (PWM torque)
==========  ======================  =====================================================

Nothing is applied to planning: a plan is made once per (ladder, seed) for the nominal
ladder, as a robot would plan from a survey, and then meets the perturbed ladder.

Every draw is a pure function of (ladder, seed, strategy, draw index): a SeedSequence
from a SHA-256 of those four, and the five quantities are always drawn in the same
order, so enabling one perturbation does not change the values of another. Unperturbed
quantities take the nominal value (no placement error, the ladder's friction, 48 V).
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
from dataclasses import dataclass

import numpy as np

from ladders.spec import FIELD_RULES, LadderSpec
from robot.errors import InputError, parse_finite
from robot.motors import DEFAULT_BATTERY_V

__all__ = ["PERTURB_KEYS", "Draw", "PerturbSpec", "draw", "parse_perturb"]

#: key → (kind, allowed range, unit, meaning) for messages.
PERTURB_KEYS: dict[str, tuple[str, float, float, str]] = {
    "placement": ("half-width", 0.0, 1.0, "m"),
    "yaw": ("half-width", 0.0, math.pi / 2, "rad"),
    "rung": ("half-width", 0.0, 0.2, "m"),
    "friction": ("range", FIELD_RULES["friction"].low, FIELD_RULES["friction"].high, ""),
    "battery": ("range", 10.0, 60.0, "V"),
}


@dataclass(frozen=True)
class PerturbSpec:
    """What to perturb (None: not perturbed).

    Attributes:
        placement_m: dx, dy half-width [m].
        yaw_rad: dyaw half-width [rad].
        rung_m: rung-spacing error half-width [m].
        friction: (low, high) friction coefficient [-].
        battery_v: (low, high) battery voltage [V].
    """

    placement_m: float | None = None
    yaw_rad: float | None = None
    rung_m: float | None = None
    friction: tuple[float, float] | None = None
    battery_v: tuple[float, float] | None = None

    def __bool__(self) -> bool:
        return any(v is not None for v in dataclasses.astuple(self))

    def to_json(self) -> dict:
        return dataclasses.asdict(self)

    def check_ladder(self, ladder: LadderSpec) -> None:
        """Raise InputError when a rung-spacing error could leave the spec's range."""
        if self.rung_m is None:
            return
        rule = FIELD_RULES["rung_spacing_m"]
        lo, hi = ladder.rung_spacing_m - self.rung_m, ladder.rung_spacing_m + self.rung_m
        if lo < rule.low or hi > rule.high:
            raise InputError(f"--perturb rung={self.rung_m:g}: ladder '{ladder.name}' has "
                             f"rung_spacing_m {ladder.rung_spacing_m:g}, so draws would span "
                             f"[{lo:g}, {hi:g}] m; rung spacing must stay in "
                             f"{rule.describe()}")


def parse_perturb(text: str | None) -> PerturbSpec:
    """Parse ``key=value[,key=lo:hi...]`` (see the module docstring).

    Raises:
        InputError: unknown or repeated key, bad number, value outside its range; the
            message names the key and the allowed range.
    """
    if not text:
        return PerturbSpec()
    values: dict[str, object] = {}
    for item in text.split(","):
        item = item.strip()
        if not item:
            continue
        key, sep, val = item.partition("=")
        key = key.strip()
        if key not in PERTURB_KEYS or not sep:
            raise InputError(f"--perturb {item!r}: expected key=value with key one of "
                             f"{', '.join(PERTURB_KEYS)}")
        if key in values:
            raise InputError(f"--perturb: key '{key}' is given twice")
        kind, low, high, unit = PERTURB_KEYS[key]
        u = f" {unit}" if unit else ""
        if kind == "half-width":
            v = parse_finite(val, f"--perturb {key}:")
            if not 0.0 < v <= high:
                raise InputError(f"--perturb {key}={val}: allowed (0, {high:.4g}]{u} "
                                 "(a half-width: draws are uniform in ±value)")
            values[key] = v
        else:
            lo_s, colon, hi_s = val.partition(":")
            lo = parse_finite(lo_s, f"--perturb {key}:")
            hi = parse_finite(hi_s, f"--perturb {key}:") if colon else lo
            if not low <= lo <= hi <= high:
                raise InputError(f"--perturb {key}={val}: expected lo:hi (or one value) with "
                                 f"{low:g} ≤ lo ≤ hi ≤ {high:g}{u}")
            values[key] = (lo, hi)
    return PerturbSpec(placement_m=values.get("placement"), yaw_rad=values.get("yaw"),
                       rung_m=values.get("rung"), friction=values.get("friction"),
                       battery_v=values.get("battery"))


@dataclass(frozen=True)
class Draw:
    """One drawn perturbation (nominal values where not perturbed).

    Attributes:
        dx_m, dy_m, dyaw_rad: placement error of the ladder [m, m, rad].
        rung_spacing_error_m: added to the ladder's rung spacing [m].
        friction: the simulated ladder's friction, None = the ladder's own [-].
        battery_v: battery voltage [V].
    """

    dx_m: float = 0.0
    dy_m: float = 0.0
    dyaw_rad: float = 0.0
    rung_spacing_error_m: float = 0.0
    friction: float | None = None
    battery_v: float = DEFAULT_BATTERY_V

    def physical_ladder(self, ladder: LadderSpec) -> LadderSpec:
        """The ladder as built (rung spacing, friction); the placement error is applied
        by the simulation itself."""
        changes: dict[str, float] = {}
        if self.rung_spacing_error_m:
            changes["rung_spacing_m"] = ladder.rung_spacing_m + self.rung_spacing_error_m
        if self.friction is not None:
            changes["friction"] = self.friction
        return dataclasses.replace(ladder, **changes) if changes else ladder

    def to_json(self) -> dict:
        return dataclasses.asdict(self)


def _seed(ladder: str, seed: int, strategy: str, index: int) -> np.random.SeedSequence:
    digest = hashlib.sha256(f"{ladder}|{seed}|{strategy}|{index}".encode()).digest()
    return np.random.SeedSequence(int.from_bytes(digest[:16], "little"))


def draw(spec: PerturbSpec, ladder: str, seed: int, strategy: str, index: int) -> Draw:
    """The ``index``-th perturbation of (ladder, seed, strategy); deterministic.

    Args:
        spec: what to perturb.
        ladder: the ladder's key (bundled name or sweep-cell name).
        seed: the plan's seed.
        strategy: arm strategy.
        index: draw index (0-based).
    """
    u = np.random.default_rng(_seed(ladder, seed, strategy, index)).uniform(size=6)

    def sym(half: float | None, x: float) -> float:
        return 0.0 if half is None else float(half * (2.0 * x - 1.0))

    def rng(r: tuple[float, float] | None, x: float) -> float | None:
        return None if r is None else float(r[0] + (r[1] - r[0]) * x)

    battery = rng(spec.battery_v, u[5])
    return Draw(dx_m=sym(spec.placement_m, u[0]), dy_m=sym(spec.placement_m, u[1]),
                dyaw_rad=sym(spec.yaw_rad, u[2]),
                rung_spacing_error_m=sym(spec.rung_m, u[3]),
                friction=rng(spec.friction, u[4]),
                battery_v=DEFAULT_BATTERY_V if battery is None else battery)
