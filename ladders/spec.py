"""`LadderSpec`: the validated description of one ladder and of where it stands.

Frames (fixed; the planner depends on them):

- World frame = the robot's start frame: x forward, y left, z up, floor at z = 0.
- Ladder frame L: origin on the floor at the ladder's lateral centre, where the line
  through the rung top-surface centres (the *rung line*) meets the floor. x_L points
  up-ladder (away from the robot), z_L up. ``placement_*`` is the pose of L in the world.
- Rung i (0-based) has its top-surface centre at height
  ``h_i = first_rung_height_m + i * rung_spacing_m`` and at ``x_L = h_i / tan(slope)``.
- The handrail axes lie ``rail_height_m`` vertically above the rung line, at
  ``y_L = ±rail_spacing_m / 2``.

Every field has one allowed range, in `FIELD_RULES`. A spec that breaks a range or a
cross-field rule raises `LadderSpecError` naming the field, the value and the range.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, fields
from typing import Any

from robot.errors import LadderSpecError

#: Stringer (side rail holding the rungs) cross-section, fixed for every ladder [m].
STRINGER_WIDTH_M = 0.03  # lateral, along y_L
STRINGER_DEPTH_M = 0.12  # perpendicular to the rung line, in the x_L–z_L plane
#: Thickness of a top landing's slab [m], fixed like the stringers: the planner and the
#: simulator only meet its top surface and front edge.
LANDING_THICKNESS_M = 0.05

RUNG_SHAPES = ("box", "cylinder")
_NAME_PATTERN = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]{0,63}")


@dataclass(frozen=True)
class FieldRule:
    """The allowed values of one `LadderSpec` field.

    Attributes:
        kind: ``"float"``, ``"int"``, ``"str"`` or ``"bool"``.
        low: Smallest allowed value (numbers only), inclusive.
        high: Largest allowed value (numbers only), inclusive.
        unit: Unit shown in messages and tables (``""`` for none).
        choices: Allowed strings (``rung_shape``), or empty.
        doc: One-line meaning, shown by ``python -m ladders show``.
        optional: None is allowed (a part the ladder may not have: its landing).
    """

    kind: str
    low: float | None = None
    high: float | None = None
    unit: str = ""
    choices: tuple[str, ...] = ()
    doc: str = ""
    optional: bool = False

    def describe(self) -> str:
        """The allowed range as text, e.g. ``[30, 90] deg``."""
        if self.choices:
            return "one of " + ", ".join(repr(c) for c in self.choices)
        if self.kind == "bool":
            return "true or false"
        if self.low is None:
            return "a name of 1-64 letters, digits, '_', '.', '-'"
        unit = f" {self.unit}" if self.unit else ""
        kind = "integer in " if self.kind == "int" else ""
        return f"{kind}[{self.low:g}, {self.high:g}]{unit}"


#: The one table of allowed ranges. Bounds are what a ladder can physically be (30° is the
#: shallowest thing still called a ladder, a stair below it), not what a robot can climb:
#: whether this robot reaches a ladder's rungs and rails is the planner's pre-check's
#: question (`planner.reachability`).
FIELD_RULES: dict[str, FieldRule] = {
    "name": FieldRule("str", doc="ladder name (used for output file names)"),
    "slope_deg": FieldRule("float", 30.0, 90.0, "deg", doc="inclination from the floor"),
    "num_rungs": FieldRule("int", 1, 30, doc="number of rungs"),
    "rung_spacing_m": FieldRule("float", 0.10, 1.00, "m", doc="vertical distance between rungs"),
    "first_rung_height_m": FieldRule("float", 0.05, 1.00, "m",
                                     doc="top of the first rung above the floor"),
    "rung_width_m": FieldRule("float", 0.20, 2.00, "m", doc="rung length along y_L"),
    "rung_depth_m": FieldRule("float", 0.01, 0.40, "m",
                              doc="tread depth along x_L (cylinder: diameter)"),
    "rung_thickness_m": FieldRule("float", 0.005, 0.10, "m",
                                  doc="vertical thickness (box rungs only)"),
    "rung_shape": FieldRule("str", choices=RUNG_SHAPES, doc="rung cross-section"),
    "rail_spacing_m": FieldRule("float", 0.30, 3.00, "m", doc="distance between rail axes"),
    "rail_height_m": FieldRule("float", 0.30, 1.50, "m",
                               doc="rail axis height above the rung line"),
    "rail_radius_m": FieldRule("float", 0.005, 0.08, "m", doc="handrail radius"),
    "friction": FieldRule("float", 0.05, 2.0, doc="Coulomb friction coefficient of the ladder"),
    "placement_x_m": FieldRule("float", -10.0, 10.0, "m", doc="ladder frame origin, world x"),
    "placement_y_m": FieldRule("float", -10.0, 10.0, "m", doc="ladder frame origin, world y"),
    "placement_yaw_rad": FieldRule("float", -math.pi, math.pi, "rad",
                                   doc="ladder frame yaw about world z"),
    "landing_height_m": FieldRule("float", 0.05, 1.00, "m", optional=True,
                                  doc="landing top above the top rung's top"),
    "landing_depth_m": FieldRule("float", 0.30, 5.00, "m", optional=True,
                                 doc="landing depth along x_L from its front edge"),
    "landing_width_m": FieldRule("float", 0.30, 5.00, "m", optional=True,
                                 doc="landing width along y_L, centred on the ladder"),
    "landing_handrails": FieldRule("bool", optional=True,
                                   doc="the rails go on over the landing as handrails"),
}
#: The landing's fields: a ladder has all of them or none.
LANDING_FIELDS = ("landing_height_m", "landing_depth_m", "landing_width_m",
                  "landing_handrails")


class LadderFieldError(LadderSpecError):
    """One field of a ladder spec is wrong.

    Attributes:
        field: The `LadderSpec` field name(s) at fault; the first one is the main one.
        reason: The message without the field prefix (the loader adds file and line).
    """

    def __init__(self, fields_: tuple[str, ...], reason: str):
        self.fields = fields_
        self.reason = reason
        super().__init__(f"field '{fields_[0]}' {reason}")


def check_field(field: str, value: Any) -> Any:
    """Check one field value against `FIELD_RULES`.

    Args:
        field: A `LadderSpec` field name.
        value: The value as given (ints are accepted for float fields).

    Returns:
        The value converted to its canonical type (float, int or str).

    Raises:
        LadderFieldError: Wrong type or outside the allowed range.
    """
    rule = FIELD_RULES[field]
    allowed = rule.describe()
    if value is None and rule.optional:
        return None
    if rule.kind == "bool":
        if not isinstance(value, bool):
            raise LadderFieldError((field,), f"= {value!r} is not {allowed}")
        return value
    if rule.kind == "str":
        if not isinstance(value, str):
            raise LadderFieldError((field,), f"= {value!r} is a {type(value).__name__}, "
                                   f"expected a string: {allowed}")
        ok = value in rule.choices if rule.choices else _NAME_PATTERN.fullmatch(value)
        if not ok:
            raise LadderFieldError((field,), f"= {value!r} is not allowed: {allowed}")
        return value
    # bool is an int subclass: `true` in a YAML file is not a number.
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise LadderFieldError((field,), f"= {value!r} is a {type(value).__name__}, "
                               f"expected a number: {allowed}")
    if rule.kind == "int" and not isinstance(value, int):
        raise LadderFieldError((field,), f"= {value!r} is not an integer: {allowed}")
    if not math.isfinite(value) or not rule.low <= value <= rule.high:
        raise LadderFieldError((field,), f"= {value!r} is out of range: {allowed}")
    return int(value) if rule.kind == "int" else float(value)


@dataclass(frozen=True, kw_only=True)
class LadderSpec:
    """A ladder (thesis Table 6.1 parameters) and its placement in the world frame.

    Every field is checked on construction against `FIELD_RULES` and the cross-field
    rules of `check_cross_fields`; violations raise `LadderSpecError`.

    Attributes:
        name: Ladder name, also used for output file names.
        slope_deg: Inclination of the rung line from the floor [deg].
        num_rungs: Number of rungs.
        rung_spacing_m: Vertical distance between consecutive rung tops [m].
        first_rung_height_m: Height of the first rung's top surface [m].
        rung_width_m: Rung length along y_L [m].
        rung_depth_m: Tread depth along x_L [m]; the diameter of cylinder rungs.
        rung_thickness_m: Vertical thickness of box rungs [m] (unused for cylinders).
        rung_shape: ``"box"`` or ``"cylinder"``.
        rail_spacing_m: Lateral distance between the two rail axes [m].
        rail_height_m: Vertical height of the rail axes above the rung line [m].
        rail_radius_m: Handrail radius [m].
        friction: Coulomb friction coefficient of rungs, rails and stringers [-].
        placement_x_m: World x of the ladder frame origin [m].
        placement_y_m: World y of the ladder frame origin [m].
        placement_yaw_rad: Yaw of the ladder frame about world z [rad].
        landing_height_m: Height of the top landing's top surface above the top rung's
            top [m], or None: no landing.
        landing_depth_m: Landing depth along x_L, from its front edge [m] (or None).
        landing_width_m: Landing width along y_L, centred on the ladder [m] (or None).
        landing_handrails: Whether the rails go on over the landing as handrails (or
            None without a landing).
    """

    name: str
    slope_deg: float
    num_rungs: int
    rung_spacing_m: float
    first_rung_height_m: float
    rung_width_m: float
    rung_depth_m: float
    rung_thickness_m: float
    rung_shape: str = "box"
    rail_spacing_m: float
    rail_height_m: float
    rail_radius_m: float
    friction: float = 0.4
    placement_x_m: float = 0.0
    placement_y_m: float = 0.0
    placement_yaw_rad: float = 0.0
    landing_height_m: float | None = None
    landing_depth_m: float | None = None
    landing_width_m: float | None = None
    landing_handrails: bool | None = None

    def __post_init__(self) -> None:
        for f in fields(self):
            # Frozen: canonicalise types (60 -> 60.0) through object.__setattr__.
            object.__setattr__(self, f.name, check_field(f.name, getattr(self, f.name)))
        check_cross_fields(self)

    @property
    def slope_rad(self) -> float:
        """Inclination of the rung line from the floor [rad]."""
        return math.radians(self.slope_deg)

    @property
    def top_rung_height_m(self) -> float:
        """Height of the top rung's top surface [m]."""
        return self.rung_height_m(self.num_rungs - 1)

    @property
    def has_landing(self) -> bool:
        """Whether the ladder leads to a top landing."""
        return self.landing_height_m is not None

    def rung_height_m(self, i: int) -> float:
        """Height h_i of rung ``i``'s top surface above the floor [m] (any integer i)."""
        return self.first_rung_height_m + i * self.rung_spacing_m

    def rung_run_m(self, i: int) -> float:
        """Horizontal distance d_i of rung ``i``'s top centre from the L origin along x_L [m]."""
        return self.run_at_height_m(self.rung_height_m(i))

    def run_at_height_m(self, height_m: float) -> float:
        """Horizontal distance along x_L of the rung line's point ``height_m`` above the
        floor [m]."""
        return height_m * math.cos(self.slope_rad) / math.sin(self.slope_rad)

    def as_dict(self) -> dict[str, Any]:
        """All fields as a flat ``{field: value}`` dict (for JSON sidecars)."""
        return {f.name: getattr(self, f.name) for f in fields(self)}


def rung_protrusion_m(spec: LadderSpec) -> float:
    """How far a rung reaches above the rung line, perpendicular to it [m].

    Box: the front top edge, (depth/2)·sin(slope). Cylinder (top at h_i, centre one
    radius below): R·(1 − cos(slope)).
    """
    s = spec.slope_rad
    if spec.rung_shape == "box":
        return spec.rung_depth_m / 2 * math.sin(s)
    return spec.rung_depth_m / 2 * (1.0 - math.cos(s))


def check_cross_fields(spec: LadderSpec) -> None:
    """Rules that tie several fields together.

    - Rungs must not overlap each other (box: thickness < spacing; cylinder: diameter
      < centre distance ``spacing / sin(slope)``).
    - The first rung must stand on or above the floor.
    - A landing has all of `LANDING_FIELDS` or none.
    - The rails must not pass through the rungs or stringers: either they clear the
      stringers' outer faces laterally by one rail radius, or their axes lie far enough
      above the rung line (``rail_height·cos(slope)``, perpendicular to it) to clear the
      stringers and rung edges by one rail radius. The ship ladder's rails (0.79 m)
      stand right above its stringers (rungs 0.762 m) and pass by the second rule; a
      vertical ladder only passes by the first.

    Raises:
        LadderFieldError: naming the fields involved and their values.
    """
    given = [f for f in LANDING_FIELDS if getattr(spec, f) is not None]
    if given and len(given) < len(LANDING_FIELDS):
        missing = [f for f in LANDING_FIELDS if f not in given]
        raise LadderFieldError(
            (missing[0], *given),
            f"is missing: a landing needs {', '.join(LANDING_FIELDS)} (given: "
            f"{', '.join(given)})")
    s = spec.slope_rad
    if spec.rung_shape == "box":
        if spec.rung_thickness_m >= spec.rung_spacing_m:
            raise LadderFieldError(
                ("rung_thickness_m", "rung_spacing_m"),
                f"= {spec.rung_thickness_m:g} m must be less than rung_spacing_m = "
                f"{spec.rung_spacing_m:g} m (rungs would overlap)")
        lowest = spec.rung_thickness_m
    else:
        centre_distance_m = spec.rung_spacing_m / math.sin(s)
        if spec.rung_depth_m >= centre_distance_m:
            raise LadderFieldError(
                ("rung_depth_m", "rung_spacing_m", "slope_deg"),
                f"= {spec.rung_depth_m:g} m (cylinder diameter) must be less than "
                f"rung_spacing_m / sin(slope) = {centre_distance_m:.3f} m (rungs would overlap)")
        lowest = spec.rung_depth_m
    if spec.first_rung_height_m < lowest:
        what = "rung_thickness_m" if spec.rung_shape == "box" else "rung_depth_m"
        raise LadderFieldError(
            ("first_rung_height_m", what),
            f"= {spec.first_rung_height_m:g} m puts the first rung into the floor: it must be "
            f"at least {what} = {lowest:g} m")
    rail_inner_m = spec.rail_spacing_m / 2 - spec.rail_radius_m
    body_outer_m = spec.rung_width_m / 2 + STRINGER_WIDTH_M
    if rail_inner_m >= body_outer_m:
        return
    above_line_m = spec.rail_height_m * math.cos(s) - spec.rail_radius_m
    needed_m = max(STRINGER_DEPTH_M / 2, rung_protrusion_m(spec))
    if above_line_m < needed_m:
        raise LadderFieldError(
            ("rail_spacing_m", "rung_width_m", "rail_height_m", "rail_radius_m"),
            f"= {spec.rail_spacing_m:g} m puts the rails through the rungs/stringers: with "
            f"rung_width_m = {spec.rung_width_m:g} m they must be at least "
            f"{2 * (body_outer_m + spec.rail_radius_m):.3f} m apart, or rail_height_m = "
            f"{spec.rail_height_m:g} m must lift them {needed_m:.3f} m clear of the rung line "
            f"(now {above_line_m:.3f} m at slope {spec.slope_deg:g} deg)")


__all__ = ["FIELD_RULES", "LANDING_FIELDS", "LANDING_THICKNESS_M", "RUNG_SHAPES",
           "STRINGER_DEPTH_M", "STRINGER_WIDTH_M", "FieldRule", "LadderFieldError",
           "LadderSpec", "check_cross_fields", "check_field", "rung_protrusion_m"]
