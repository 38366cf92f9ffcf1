"""The plan sidecar's reader: version 2, errors that name the field, the ladder parsed by
the spec's own rules."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest
import yaml

sys.path.insert(0, str(Path(__file__).parent))

from synthetic_plan import synthetic_plan  # noqa: E402

from ladders.loader import (  # noqa: E402
    bundled_ladder_path,
    ladder_from_mapping,
    ladder_to_mapping,
    ladder_to_yaml,
    load_ladder,
    sidecar_ladder,
)
from planner.output import write_plan  # noqa: E402
from robot.errors import InputError, LadderSpecError  # noqa: E402
from robot.plan_sidecar import (  # noqa: E402
    VERSION,
    SidecarError,
    check_line_count,
    read_sidecar,
)


@pytest.fixture(scope="module")
def document(tmp_path_factory) -> dict:
    planner, result, q0 = synthetic_plan()
    out = write_plan(result, planner, tmp_path_factory.mktemp("out") / "syn.traj", 200.0,
                     {"search_s": 1.0}, q_start=q0)
    return json.loads(out.sidecar_path.read_text())


def _read(tmp_path: Path, doc: dict | bytes):
    path = tmp_path / "x.plan.json"
    path.write_bytes(doc if isinstance(doc, bytes) else json.dumps(doc).encode())
    return read_sidecar(path)


def test_the_writer_writes_version_2_and_the_reader_reads_it(document, tmp_path):
    assert document["version"] == VERSION == 2
    sidecar = _read(tmp_path, document)
    assert sidecar_ladder(sidecar, "x").name == document["ladder"]["name"]


def test_version_1_is_refused_with_what_to_do(document, tmp_path):
    with pytest.raises(SidecarError, match="'version' is 1.*plan again with plan-ladder"):
        _read(tmp_path, {**document, "version": 1})


@pytest.mark.parametrize("field,value,words", [
    ("line_count", "many", "line_count: expected an integer ≥ 1, got 'many'"),
    ("rate_hz", "fast", "rate_hz: expected a positive number, got 'fast'"),
    ("robot", 3, "robot: expected a string, got 3"),
    ("seed", 1.5, "seed: expected an integer, got 1.5"),
    ("segments", {}, "segments: expected a list"),
])
def test_a_bad_field_is_named_with_what_was_expected(document, tmp_path, field, value, words):
    with pytest.raises(SidecarError, match=words.replace("(", r"\(")):
        _read(tmp_path, {**document, field: value})


def test_a_missing_field_and_a_bad_segment_field_are_named(document, tmp_path):
    with pytest.raises(SidecarError, match="missing field 'final_holds'"):
        _read(tmp_path, {k: v for k, v in document.items() if k != "final_holds"})
    segments = [dict(s) for s in document["segments"]]
    segments[1]["first_line"] = "x"
    with pytest.raises(SidecarError, match=r"segments\[1\].first_line: expected an integer"):
        _read(tmp_path, {**document, "segments": segments})
    segments = [dict(s) for s in document["segments"]]
    segments[0]["phase"] = "jump"
    with pytest.raises(SidecarError, match=r"segments\[0\].phase: expected one of body"):
        _read(tmp_path, {**document, "segments": segments})


def test_a_bad_hold_target_is_named(document, tmp_path):
    segments = [dict(s) for s in document["segments"]]
    limb = next(iter(segments[0]["holds"]))
    segments[0]["holds"] = {limb: {**segments[0]["holds"][limb], "target": "rung_x"}}
    with pytest.raises(SidecarError, match=rf"segments\[0\].holds.{limb}.target: hold target"):
        _read(tmp_path, {**document, "segments": segments})


def test_a_byte_that_is_not_utf8_is_reported_at_its_line_and_column(document, tmp_path):
    text = json.dumps(document, indent=1).encode()
    at = text.index(b'"robot"')
    line = text.count(b"\n", 0, at) + 1
    column = at - text.rfind(b"\n", 0, at)
    bad = text[:at + 1] + b"\xe9" + text[at + 2:]
    with pytest.raises(SidecarError, match=rf":{line}:{column + 1}: byte 0xe9 is not UTF-8"):
        _read(tmp_path, bad)


@pytest.mark.parametrize("name", ["drc", "ship", "stair"])
def test_the_ladder_mapping_is_the_yaml_layout_and_reads_back(name):
    spec = load_ladder(name)
    mapping = ladder_to_mapping(spec)
    assert mapping == yaml.safe_load(ladder_to_yaml(spec))
    assert json.dumps(mapping) == json.dumps(yaml.safe_load(bundled_ladder_path(name)
                                                            .read_text()))
    assert ladder_from_mapping(mapping, "x") == spec


def test_the_sidecar_s_ladder_is_checked_by_the_spec_s_rules():
    mapping = ladder_to_mapping(load_ladder("drc"))
    mapping["geometry"] = {**mapping["geometry"], "slope_deg": "steep"}
    mapping["rails"] = {**mapping["rails"], "colour": "red"}
    with pytest.raises(LadderSpecError) as info:
        ladder_from_mapping(mapping, "p.plan.json: field 'ladder'")
    text = str(info.value)
    assert "p.plan.json: field 'ladder': field 'geometry.slope_deg'" in text
    assert "field 'rails.colour' is unknown" in text
    with pytest.raises(LadderSpecError, match="field 'rails.spacing_m' is missing"):
        ladder_from_mapping({**mapping, "rails": {}}, "x")
    with pytest.raises(LadderSpecError, match="section 'geometry' is list"):
        ladder_from_mapping({**mapping, "geometry": []}, "x")


def test_a_trajectory_and_a_sidecar_that_count_different_lines_are_refused(document,
                                                                           tmp_path):
    sidecar = _read(tmp_path, document)
    check_line_count(tmp_path / "x.traj", sidecar.line_count, sidecar)  # agree: no error
    with pytest.raises(InputError) as err:
        check_line_count(tmp_path / "x.traj.gz", sidecar.line_count - 1, sidecar)
    words = str(err.value)
    assert f"x.traj.gz:{sidecar.line_count - 1}:" in words and "x.plan.json" in words
    assert f"says {sidecar.line_count}" in words
