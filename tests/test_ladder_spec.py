"""Ladder specs: bundled thesis values, and every error names its field (and line)."""

import pytest
import yaml

from ladders.loader import LAYOUT, dump_ladder, ladder_to_yaml, load_ladder, parse_ladder_yaml
from ladders.spec import FIELD_RULES
from robot.errors import InputError, LadderSpecError

TABLE_6_1 = {  # thesis Table 6.1 (hubo-facts §6)
    "stair": dict(slope_deg=40, num_rungs=4, rail_spacing_m=1.27, rail_height_m=0.99,
                  rung_spacing_m=0.203, first_rung_height_m=0.172, rung_width_m=1.22,
                  rung_depth_m=0.25, rung_thickness_m=0.04),
    "ship": dict(slope_deg=58.1, num_rungs=6, rail_spacing_m=0.79, rail_height_m=1.02,
                 rung_spacing_m=0.254, first_rung_height_m=0.264, rung_width_m=0.762,
                 rung_depth_m=0.178, rung_thickness_m=0.038),
    "drc": dict(slope_deg=60, num_rungs=9, rail_spacing_m=1.35, rail_height_m=0.91,
                rung_spacing_m=0.305, first_rung_height_m=0.305, rung_width_m=0.812,
                rung_depth_m=0.102, rung_thickness_m=0.032),
}
FILE_KEY = {field: (f"{section}.{key}" if section else key)
            for section, keys in LAYOUT.items() for key, field in keys.items()}


@pytest.mark.parametrize("name", sorted(TABLE_6_1))
def test_bundled_ladders_are_table_6_1(name):
    spec = load_ladder(name)
    for field, value in TABLE_6_1[name].items():
        assert getattr(spec, field) == pytest.approx(value), field
    assert spec.friction == 0.4


def _doc(name="drc"):
    return yaml.safe_load(ladder_to_yaml(load_ladder(name)))


def _set(doc, path, value):
    node = doc
    *parents, leaf = path.split(".")
    for p in parents:
        node = node.setdefault(p, {})  # an optional section (the landing) may be absent
    if value is _DELETE:
        del node[leaf]
    else:
        node[leaf] = value


_DELETE = object()
NUMERIC = [f for f, r in FIELD_RULES.items() if r.kind in ("float", "int")]


@pytest.mark.parametrize("field", NUMERIC)
def test_out_of_range_names_field_value_and_range(field):
    rule = FIELD_RULES[field]
    doc = _doc()
    _set(doc, FILE_KEY[field], rule.high * 2 + 100)
    with pytest.raises(LadderSpecError) as err:
        parse_ladder_yaml(yaml.safe_dump(doc), "bad.yaml")
    msg = str(err.value)
    assert f"'{FILE_KEY[field]}'" in msg and rule.describe() in msg and "bad.yaml:" in msg


@pytest.mark.parametrize("field", NUMERIC)
def test_wrong_type_names_the_field(field):
    doc = _doc()
    _set(doc, FILE_KEY[field], "steep")
    with pytest.raises(LadderSpecError, match=f"'{FILE_KEY[field]}'"):
        parse_ladder_yaml(yaml.safe_dump(doc), "bad.yaml")


@pytest.mark.parametrize("field", [f for f, rule in FIELD_RULES.items()
                                   if f not in ("friction", "rung_shape") and
                                   not f.startswith("placement") and not rule.optional])
def test_missing_required_field_is_named(field):
    doc = _doc()
    _set(doc, FILE_KEY[field], _DELETE)
    with pytest.raises(LadderSpecError, match=f"field '{FILE_KEY[field]}' is missing"):
        parse_ladder_yaml(yaml.safe_dump(doc), "bad.yaml")


def test_unknown_field_is_named_with_its_line():
    text = ladder_to_yaml(load_ladder("drc")).replace("rails:\n", "rails:\n  colour: red\n")
    line = text.splitlines().index("  colour: red") + 1
    with pytest.raises(LadderSpecError) as err:
        parse_ladder_yaml(text, "bad.yaml")
    assert f"bad.yaml:{line}:" in str(err.value) and "colour" in str(err.value)


def test_rung_shape_choices_and_yaml_syntax_errors():
    doc = _doc()
    doc["geometry"]["rung_shape"] = "hexagon"
    with pytest.raises(LadderSpecError, match="geometry.rung_shape.*'box', 'cylinder'"):
        parse_ladder_yaml(yaml.safe_dump(doc), "bad.yaml")
    with pytest.raises(LadderSpecError, match=r"bad.yaml:3: YAML syntax error"):
        parse_ladder_yaml("name: x\ngeometry: [unclosed\n", "bad.yaml")


def test_unknown_bundled_name_lists_the_valid_ones():
    with pytest.raises(InputError, match="drc, ship, stair"):
        load_ladder("everest")


@pytest.mark.parametrize("name", sorted(TABLE_6_1))
def test_dump_and_load_round_trip(tmp_path, name):
    spec = load_ladder(name)
    path = dump_ladder(spec, tmp_path / f"{name}.yaml")
    assert load_ladder(path) == spec
