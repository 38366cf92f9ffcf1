"""Sweep files: ladders spanning a parameter grid or sampled at random around a base.

A sweep file (YAML) names a base ladder and the `LadderSpec` fields to vary::

    base: drc                  # bundled ladder, or a spec file (relative to this file)
    mode: grid                 # grid (every combination) or random
    samples: 20                # random only: how many ladders
    seed: 1                    # random only: the sampling seed (default 0)
    parameters:
      slope_deg: [55, 60, 65]                            # values (random: picked uniformly)
      rung_spacing_m: {min: 0.25, max: 0.35, steps: 3}   # grid: linspace; random: U(min, max)
      rail_spacing_m: {min: 1.1, max: 1.4, steps: 2}
      rail_height_m: [0.8, 0.91]
      rung_shape: [box, cylinder]

Sweepable fields: every geometry, rail and contact field of a ladder spec
(`SWEEP_FIELDS`); the placement stays the base ladder's. Every value is checked against
the spec's range (`ladders.spec.FIELD_RULES`), and every cell against the cross-field
rules, when the file is read. Problems are reported as ``FILE:LINE: ...`` like the
ladder loader does. Cells are named ``<base>.c<index>`` (grid: row-major in the file's
parameter order).
"""

from __future__ import annotations

import dataclasses
import itertools
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from ladders.loader import YamlProblems, document_items, load_ladder, mapping_items
from ladders.spec import FIELD_RULES, LadderFieldError, LadderSpec, check_field
from robot.errors import InputError, LadderSpecError

__all__ = ["SWEEP_FIELDS", "SweepCell", "load_sweep", "parse_sweep_yaml"]

#: Fields a sweep may vary.
SWEEP_FIELDS: tuple[str, ...] = (
    "slope_deg", "num_rungs", "rung_spacing_m", "first_rung_height_m", "rung_width_m",
    "rung_depth_m", "rung_thickness_m", "rung_shape", "rail_spacing_m", "rail_height_m",
    "rail_radius_m", "friction")
_TOP_KEYS = ("base", "mode", "samples", "seed", "parameters")
#: Largest number of cells a sweep may expand to (each cell is a plan per seed).
MAX_CELLS = 10_000


@dataclass(frozen=True)
class SweepCell:
    """One ladder of a sweep.

    Attributes:
        name: ``<base>.c<index>``, the cell's ladder key.
        spec: the ladder (its ``name`` is the cell name).
        params: the swept field values of this cell.
    """

    name: str
    spec: LadderSpec
    params: dict[str, Any]


def _value(node: yaml.Node) -> Any:
    return yaml.SafeLoader("").construct_object(node, deep=True)


def _int(node: yaml.Node, what: str, low: int, high: int, problems: YamlProblems) -> int | None:
    v = _value(node)
    if isinstance(v, bool) or not isinstance(v, int) or not low <= v <= high:
        problems.add(node, f"field '{what}' = {v!r}: expected an integer in [{low}, {high}]")
        return None
    return v


def _axis(field: str, node: yaml.Node, mode: str, problems: YamlProblems):
    """A parameter's values (grid) or sampler description (random)."""
    rule = FIELD_RULES[field]
    path = f"parameters.{field}"
    if isinstance(node, yaml.SequenceNode):
        if not node.value:
            problems.add(node, f"field '{path}' is an empty list")
            return None
        vals = []
        for item in node.value:
            try:
                vals.append(check_field(field, _value(item)))
            except LadderFieldError as exc:
                problems.add(item, f"field '{path}' {exc.reason}")
        return ("choice", vals) if len(vals) == len(node.value) else None
    if isinstance(node, yaml.MappingNode):
        if rule.kind == "str":
            problems.add(node, f"field '{path}' is a string field: give a list of values, "
                         f"{rule.describe()}")
            return None
        items = mapping_items(node, f"field '{path}'", problems) or {}
        wanted = ("min", "max", "steps") if mode == "grid" else ("min", "max")
        for key, (knode, _) in items.items():
            if key not in wanted:
                problems.add(knode, f"field '{path}.{key}' is unknown; valid keys here: "
                             f"{', '.join(wanted)}")
        ok = True
        bounds = {}
        for key in ("min", "max"):
            if key not in items:
                problems.add(node, f"field '{path}.{key}' is missing ({rule.describe()})")
                ok = False
                continue
            try:
                bounds[key] = check_field(field, _value(items[key][1]))
            except LadderFieldError as exc:
                problems.add(items[key][1], f"field '{path}.{key}' {exc.reason}")
                ok = False
        if ok and bounds["min"] > bounds["max"]:
            problems.add(node, f"field '{path}': min {bounds['min']:g} > max {bounds['max']:g}")
            ok = False
        if mode == "grid":
            if "steps" not in items:
                problems.add(node, f"field '{path}.steps' is missing (an integer in [1, 100])")
                return None
            steps = _int(items["steps"][1], f"{path}.steps", 1, 100, problems)
            if not ok or steps is None:
                return None
            vals = np.linspace(bounds["min"], bounds["max"], steps)
            if rule.kind == "int":
                vals = sorted({int(round(v)) for v in vals})
            return "choice", [v if rule.kind == "int" else float(round(v, 9)) for v in vals]
        if not ok:
            return None
        return "uniform", (bounds["min"], bounds["max"])
    problems.add(node, f"field '{path}' must be a list of values or a mapping "
                 f"{{min, max{', steps' if mode == 'grid' else ''}}}")
    return None


def parse_sweep_yaml(text: str, source: str = "<string>",
                     base_dir: str | os.PathLike[str] = ".") -> list[SweepCell]:
    """Parse and validate a sweep file and expand it into ladders.

    Args:
        text: the YAML text (layout in the module docstring).
        source: file name for messages.
        base_dir: directory a relative ``base`` spec path is resolved against.

    Returns:
        The sweep's cells, in order.

    Raises:
        InputError: ``SOURCE:LINE: ...`` naming the field and the allowed values.
    """
    problems = YamlProblems(source, InputError)
    root, top = document_items(text, problems, f"keys {', '.join(_TOP_KEYS)}")
    for key, (knode, _) in top.items():
        if key not in _TOP_KEYS:
            problems.add(knode, f"field '{key}' is unknown; valid keys: {', '.join(_TOP_KEYS)}")
    for key in ("base", "parameters"):
        if key not in top:
            problems.add(root, f"field '{key}' is missing")
    problems.raise_if_any()

    mode, samples, seed = _mode(root, top, problems)
    base = _base_ladder(top["base"][1], base_dir, problems)
    params_node = top["parameters"][1]
    params = mapping_items(params_node, "field 'parameters'", problems) or {}
    axes = _parameter_axes(params_node, params, mode, problems)
    problems.raise_if_any()
    assert base is not None

    if mode == "grid":
        combos = _grid_combos(axes, params_node, problems)
    else:
        combos = _random_combos(axes, samples or 0, seed)
    cells = _cells(base, combos, params, root, problems)
    problems.raise_if_any()
    return cells


def _mode(root: yaml.Node, top: dict, problems: YamlProblems
          ) -> tuple[str, int | None, int | None]:
    """The sweep's mode (``grid`` unless given) and, for ``random``, its sample count and
    seed (0 unless given); a grid given a count or seed is a problem."""
    mode = "grid"
    if "mode" in top:
        mode = _value(top["mode"][1])
        if mode not in ("grid", "random"):
            problems.add(top["mode"][1], f"field 'mode' = {mode!r}: one of 'grid', 'random'")
            mode = "grid"
    samples = seed = None
    if mode == "random":
        if "samples" not in top:
            problems.add(root, "field 'samples' is missing (mode random: an integer in "
                         f"[1, {MAX_CELLS}])")
        else:
            samples = _int(top["samples"][1], "samples", 1, MAX_CELLS, problems)
        seed = (_int(top["seed"][1], "seed", 0, 2**32 - 1, problems) if "seed" in top else 0)
    else:
        for key in ("samples", "seed"):
            if key in top:
                problems.add(top[key][0], f"field '{key}' is only used with mode: random")
    return mode, samples, seed


def _base_ladder(base_node: yaml.Node, base_dir: str | os.PathLike[str],
                 problems: YamlProblems) -> LadderSpec | None:
    """The ladder the sweep varies: a bundled name, or a spec file relative to
    ``base_dir``; None (and a problem) if it cannot be loaded."""
    base_name = _value(base_node)
    if not isinstance(base_name, str):
        problems.add(base_node, f"field 'base' = {base_name!r}: a bundled ladder name or a "
                     "spec file path")
        return None
    arg = base_name
    if ("/" in arg or arg.endswith((".yaml", ".yml"))) and not os.path.isabs(arg):
        arg = str(Path(base_dir) / arg)
    try:
        return load_ladder(arg)
    except LadderSpecError as exc:
        problems.add(base_node, f"field 'base': {exc}")
        return None


def _parameter_axes(params_node: yaml.Node, params: dict, mode: str,
                    problems: YamlProblems) -> dict[str, tuple[str, Any]]:
    """Each swept field's axis (`_axis`), in the file's order; only `SWEEP_FIELDS`."""
    if not params and isinstance(params_node, yaml.MappingNode):
        problems.add(params_node, "field 'parameters' is empty; sweep at least one "
                     f"of {', '.join(SWEEP_FIELDS)}")
    axes: dict[str, tuple[str, Any]] = {}
    for field, (knode, vnode) in params.items():
        if field not in SWEEP_FIELDS:
            problems.add(knode, f"field 'parameters.{field}' cannot be swept; sweepable: "
                         f"{', '.join(SWEEP_FIELDS)}")
            continue
        axis = _axis(field, vnode, mode, problems)
        if axis is not None:
            axes[field] = axis
    return axes


def _grid_combos(axes: dict[str, tuple[str, Any]], params_node: yaml.Node,
                 problems: YamlProblems) -> list[dict[str, Any]]:
    """Every combination of the axes' values, row-major in the file's parameter order
    (at most `MAX_CELLS`)."""
    names = list(axes)
    total = int(np.prod([len(axes[f][1]) for f in names]))
    if total > MAX_CELLS:
        problems.add(params_node, f"the grid has {total} cells; at most "
                     f"{MAX_CELLS} are allowed")
        problems.raise_if_any()
    return [dict(zip(names, values, strict=True))
            for values in itertools.product(*(axes[f][1] for f in names))]


def _random_combos(axes: dict[str, tuple[str, Any]], samples: int,
                   seed: int | None) -> list[dict[str, Any]]:
    """``samples`` combinations drawn with ``seed``: a listed value uniformly, a range
    from U(min, max) (rounded for an integer field)."""
    rng = np.random.default_rng(seed)
    combos: list[dict[str, Any]] = []
    for _ in range(samples):
        combo: dict[str, Any] = {}
        for f in axes:
            kind, spec = axes[f]
            if kind == "choice":
                v = spec[int(rng.integers(len(spec)))]
            else:
                v = float(rng.uniform(*spec))
                if FIELD_RULES[f].kind == "int":
                    v = int(round(v))
            combo[f] = v
        combos.append(combo)
    return combos


def _cells(base: LadderSpec, combos: list[dict[str, Any]], params: dict, root: yaml.Node,
           problems: YamlProblems) -> list[SweepCell]:
    """The base ladder with each combination, named ``<base>.c<index>``; a combination
    that breaks a cross-field rule is a problem at its first parameter."""
    width = max(3, len(str(len(combos) - 1)))
    cells = []
    for i, combo in enumerate(combos):
        name = f"{base.name}.c{i:0{width}d}"
        try:
            spec = dataclasses.replace(base, name=name, **combo)
        except LadderSpecError as exc:
            where = params[next(iter(combo))][0] if combo else root
            problems.add(where, f"cell {name} ({_describe(combo)}) is not a valid ladder: "
                         f"{exc}")
            continue
        cells.append(SweepCell(name, spec, combo))
    return cells


def _describe(combo: dict[str, Any]) -> str:
    return ", ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}"
                     for k, v in combo.items())


def load_sweep(path: str | os.PathLike[str]) -> list[SweepCell]:
    """Read a sweep file; see `parse_sweep_yaml`.

    Raises:
        InputError: unreadable file, or ``FILE:LINE: ...`` for a bad sweep.
    """
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"{p}: cannot read sweep file: "
                         f"{getattr(exc, 'strerror', None) or exc}") from None
    return parse_sweep_yaml(text, str(p), p.parent)
