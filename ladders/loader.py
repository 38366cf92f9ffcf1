"""Ladder spec files (YAML): load with file/line error messages, dump, bundled ladders.

A spec file has a top-level ``name`` and up to five sections; units are in the key names::

    name: drc
    geometry:
      slope_deg: 60.0
      num_rungs: 9
      rung_spacing_m: 0.305
      first_rung_height_m: 0.305
      rung_width_m: 0.812
      rung_depth_m: 0.102
      rung_thickness_m: 0.032
      rung_shape: box          # optional, default box
    rails:
      spacing_m: 1.35
      height_m: 0.91
      radius_m: 0.025
    contact:                   # optional section
      friction: 0.4
    placement:                 # optional section: pose of the ladder frame in the world
      x_m: 0.16
      y_m: 0.0
      yaw_rad: 0.0
    landing:                   # optional section: a platform above the top rung
      height_m: 0.305          # its top above the top rung's top
      depth_m: 1.2             # along the ladder's x, from its front edge
      width_m: 1.2
      handrails: true          # the rails go on over it

Every problem is reported as ``FILE:LINE: field 'geometry.slope_deg' ...``.
"""

from __future__ import annotations

import logging
import os
from collections.abc import Callable
from dataclasses import MISSING, fields
from importlib import resources
from pathlib import Path
from typing import Any

import yaml

from ladders.spec import FIELD_RULES, LadderFieldError, LadderSpec, check_field
from robot.errors import InputError, LadderSpecError
from robot.plan_sidecar import PlanSidecar

logger = logging.getLogger(__name__)

#: Bundled ladders (thesis Table 6.1), addressed by name.
BUNDLED_LADDERS: tuple[str, ...] = ("drc", "ship", "stair")

#: File layout: section -> {key in the file: LadderSpec field}. ``None`` = top level.
LAYOUT: dict[str | None, dict[str, str]] = {
    None: {"name": "name"},
    "geometry": {k: k for k in ("slope_deg", "num_rungs", "rung_spacing_m",
                                "first_rung_height_m", "rung_width_m", "rung_depth_m",
                                "rung_thickness_m", "rung_shape")},
    "rails": {"spacing_m": "rail_spacing_m", "height_m": "rail_height_m",
              "radius_m": "rail_radius_m"},
    "contact": {"friction": "friction"},
    "placement": {"x_m": "placement_x_m", "y_m": "placement_y_m",
                  "yaw_rad": "placement_yaw_rad"},
    "landing": {"height_m": "landing_height_m", "depth_m": "landing_depth_m",
                "width_m": "landing_width_m", "handrails": "landing_handrails"},
}
#: Sections a ladder may leave out as a whole (a part it does not have); once given,
#: each of their keys is required.
_PART_SECTIONS = ("landing",)
#: Fields with a default in `LadderSpec` may be left out of a file.
_OPTIONAL_FIELDS = {f.name for f in fields(LadderSpec) if f.default is not MISSING}
#: LadderSpec field -> dotted path in the file, for messages.
FILE_KEYS: dict[str, str] = {
    field: (key if section is None else f"{section}.{key}")
    for section, keys in LAYOUT.items() for key, field in keys.items()
}


class YamlProblems:
    """Collects ``FILE:LINE: message`` problems of a YAML file; raises them all at once
    as one error (a `LadderSpecError` unless told otherwise), one problem per line."""

    def __init__(self, source: str, error: type[InputError] = LadderSpecError):
        self.source = source
        self.error = error
        self.items: list[tuple[int, str]] = []

    def add(self, node: yaml.Node | None, message: str) -> None:
        line = node.start_mark.line + 1 if node is not None else 1
        self.items.append((line, f"{self.source}:{line}: {message}"))

    def raise_if_any(self) -> None:
        if not self.items:
            return
        self.items.sort(key=lambda item: item[0])
        problems = [msg for _, msg in self.items]
        error = self.error("\n".join(problems))
        error.problems = problems  # type: ignore[attr-defined]
        raise error


def mapping_items(node: yaml.Node, what: str, problems: YamlProblems
                   ) -> dict[str, tuple[yaml.Node, yaml.Node]] | None:
    """The ``{key: (key node, value node)}`` of a mapping node, or None (problem noted)."""
    if not isinstance(node, yaml.MappingNode):
        kind = {yaml.ScalarNode: "a scalar", yaml.SequenceNode: "a list"}.get(type(node), "?")
        problems.add(node, f"{what} is {kind}, expected a mapping of keys to values")
        return None
    items: dict[str, tuple[yaml.Node, yaml.Node]] = {}
    for key_node, value_node in node.value:
        key = key_node.value if isinstance(key_node, yaml.ScalarNode) else None
        if not isinstance(key, str):
            problems.add(key_node, f"{what}: keys must be plain names")
        elif key in items:
            problems.add(key_node, f"{what}: key '{key}' is given twice")
        else:
            items[key] = (key_node, value_node)
    return items


def _scalar(node: yaml.Node) -> Any:
    """The Python value of a YAML node (safe constructors only)."""
    return yaml.SafeLoader("").construct_object(node, deep=True)


def _unknown_key_message(path: str, valid: list[str]) -> str:
    return f"field '{path}' is unknown; valid keys here: {', '.join(valid)}"


def document_items(text: str, problems: YamlProblems, expected: str
                   ) -> tuple[yaml.Node, dict[str, tuple[yaml.Node, yaml.Node]]]:
    """A YAML document's root node and its top-level ``{key: (key node, value node)}``.

    Raises:
        ``problems.error``: ``SOURCE:LINE: ...`` for a syntax error, an empty document
            (the message says it ``expected`` ...) or a document that is not a mapping.
    """
    source = problems.source
    try:
        root = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        line = mark.line + 1 if mark is not None else 1
        reason = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise problems.error(f"{source}:{line}: YAML syntax error: {reason}") from None
    if root is None:
        raise problems.error(f"{source}:1: the file is empty; expected {expected}")
    top = mapping_items(root, "the document", problems)
    problems.raise_if_any()
    assert top is not None
    return root, top


def parse_ladder_yaml(text: str, source: str = "<string>") -> LadderSpec:
    """Parse and validate the text of a ladder spec file.

    Args:
        text: YAML text in the layout of this module's docstring.
        source: File name used in messages.

    Returns:
        The validated spec.

    Raises:
        LadderSpecError: ``SOURCE:LINE: ...`` for YAML syntax errors, a document that is
            not a mapping, unknown/missing/duplicate keys, wrong types, out-of-range values
            and cross-field rule violations.
    """
    problems = YamlProblems(source)
    root, top = document_items(text, problems, "a ladder spec mapping with sections "
                               + ", ".join(s for s in LAYOUT if s))
    spec = _spec_from_layout(
        top, root, lambda section, node: mapping_items(node, f"section '{section}'", problems),
        _scalar, problems.add, problems.raise_if_any)
    logger.debug("loaded ladder %r from %s", spec.name, source)
    return spec


def ladder_from_mapping(doc: Any, source: str) -> LadderSpec:
    """Validate a ladder spec given as a mapping in the file layout (as a plan sidecar
    holds it), by the same rules as a spec file.

    Raises:
        LadderSpecError: ``SOURCE: field 'geometry.slope_deg' ...``, one problem per line.
    """
    problems: list[str] = []

    def add(_where: object, message: str) -> None:
        problems.append(f"{source}: {message}")

    def raise_if_any() -> None:
        if problems:
            error = LadderSpecError("\n".join(problems))
            error.problems = list(problems)  # type: ignore[attr-defined]
            raise error

    def items(what: str, value: Any) -> dict[str, tuple[str, Any]] | None:
        if not isinstance(value, dict):
            add(None, f"{what} is {type(value).__name__}, expected a mapping of keys to values")
            return None
        return {str(k): (k, v) for k, v in value.items()}

    top = items("the ladder", doc)
    raise_if_any()
    assert top is not None
    return _spec_from_layout(top, None, lambda section, value: items(f"section '{section}'",
                                                                     value),
                             lambda value: value, add, raise_if_any)


def sidecar_ladder(sidecar: PlanSidecar, source: str) -> LadderSpec:
    """The ladder spec a plan sidecar holds (field ``ladder``), checked by the spec's rules.

    Raises:
        LadderSpecError: ``SOURCE: field 'ladder': field 'geometry.slope_deg' ...``.
    """
    return ladder_from_mapping(sidecar.ladder, f"{source}: field 'ladder'")


def _spec_from_layout(top: dict[str, tuple[Any, Any]], root: Any,
                      section_items: Callable[[str, Any], dict[str, tuple[Any, Any]] | None],
                      value_of: Callable[[Any], Any], add: Callable[[Any, str], None],
                      raise_if_any: Callable[[], None]) -> LadderSpec:
    """The spec of a document in the file layout, whatever it was read from.

    Args:
        top: the document's top level, key → (where the key is, where its value is).
        root: where the document is (for problems of the whole document).
        section_items: a section's entries like ``top``, or None (problem added).
        value_of: the Python value at a value's place.
        add: records a problem at a place.
        raise_if_any: raises the problems recorded so far, if any.
    """
    values: dict[str, Any] = {}
    places: dict[str, Any] = {}
    valid_top = [k for k in LAYOUT[None]] + [s for s in LAYOUT if s]
    for key, (key_place, _) in top.items():
        if key not in valid_top:
            add(key_place, _unknown_key_message(key, valid_top))
    for section, keys in LAYOUT.items():
        if section is None:
            entries: dict[str, tuple[Any, Any]] | None = top
            anchor = root
        elif section in top:
            anchor = top[section][1]
            entries = section_items(section, anchor)
        else:
            anchor, entries = root, {}
        if entries is None:
            continue
        for key, (key_place, _) in entries.items():
            if section is not None and key not in keys:
                add(key_place, _unknown_key_message(f"{section}.{key}", list(keys)))
        for key, field in keys.items():
            path = FILE_KEYS[field]
            if key not in entries:
                if field not in _OPTIONAL_FIELDS or (section in _PART_SECTIONS
                                                     and section in top):
                    where = f"section '{section}'" if section else "the top level"
                    add(anchor, f"field '{path}' is missing from {where} "
                        f"(required, {FIELD_RULES[field].describe()})")
                continue
            value_place = entries[key][1]
            places[field] = value_place
            try:
                values[field] = check_field(field, value_of(value_place))
            except LadderFieldError as exc:
                add(value_place, f"field '{path}' {exc.reason}")
            except yaml.YAMLError as exc:
                add(value_place, f"field '{path}': {exc}")
    raise_if_any()
    try:
        return LadderSpec(**values)
    except LadderFieldError as exc:
        field = exc.fields[0]
        add(places.get(field, root), f"field '{FILE_KEYS[field]}' {exc.reason}")
        raise_if_any()
        raise  # pragma: no cover - raise_if_any always raises here


def bundled_ladder_path(name: str) -> Path:
    """Path of a bundled ladder's spec file.

    Raises:
        LadderSpecError: ``name`` is not a bundled ladder; the message lists the valid ones.
    """
    if name not in BUNDLED_LADDERS:
        raise LadderSpecError(f"unknown ladder '{name}': bundled ladders are "
                              f"{', '.join(BUNDLED_LADDERS)} (or give a path to a .yaml file)")
    return Path(str(resources.files("ladders") / "specs" / f"{name}.yaml"))


def load_ladder(name_or_path: str | os.PathLike[str]) -> LadderSpec:
    """Load a bundled ladder by name or a spec file by path.

    Args:
        name_or_path: ``"drc"``, ``"ship"``, ``"stair"``, or a path to a YAML spec. A
            string counts as a path when it contains a path separator or ends in
            ``.yaml``/``.yml``.

    Returns:
        The validated spec.

    Raises:
        LadderSpecError: Unknown bundled name, unreadable file, or an invalid spec
            (``FILE:LINE: ...``).
    """
    text_arg = os.fspath(name_or_path)
    is_path = (not isinstance(name_or_path, str) or os.sep in text_arg or "/" in text_arg
               or text_arg.endswith((".yaml", ".yml")))
    path = Path(text_arg) if is_path else bundled_ladder_path(text_arg)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise LadderSpecError(f"{path}: cannot read ladder spec: {reason}") from None
    return parse_ladder_yaml(text, str(path))


def ladder_to_mapping(spec: LadderSpec) -> dict[str, Any]:
    """The spec as a mapping in the file layout (what a plan sidecar holds);
    `ladder_from_mapping` reads it back to an equal spec."""
    doc: dict[str, Any] = {}
    for section, keys in LAYOUT.items():
        entries = {key: getattr(spec, field) for key, field in keys.items()}
        if section in _PART_SECTIONS and all(v is None for v in entries.values()):
            continue
        if section is None:
            doc.update(entries)
        else:
            doc[section] = entries
    return doc


def ladder_to_yaml(spec: LadderSpec) -> str:
    """The spec as YAML text in the file layout (floats written exactly, so it round-trips)."""
    doc = ladder_to_mapping(spec)
    header = (f"# Ladder spec '{spec.name}' (hubo-ladder). Units are in the key names.\n"
              "# placement = pose of the ladder frame (floor, rung line, lateral centre) in the\n"
              "# robot's start frame.\n")
    return header + yaml.safe_dump(doc, sort_keys=False, default_flow_style=False)


def dump_ladder(spec: LadderSpec, path: str | os.PathLike[str]) -> Path:
    """Write ``spec`` to a YAML file that `load_ladder` reads back to an equal spec.

    Returns:
        The path written.
    """
    out = Path(path)
    out.write_text(ladder_to_yaml(spec), encoding="utf-8")
    logger.info("wrote ladder spec %s", out)
    return out


__all__ = ["BUNDLED_LADDERS", "FILE_KEYS", "LAYOUT", "bundled_ladder_path", "dump_ladder",
           "ladder_from_mapping", "ladder_to_mapping", "ladder_to_yaml", "load_ladder",
           "parse_ladder_yaml", "sidecar_ladder"]
