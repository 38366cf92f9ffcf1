"""A ladder's top landing (issue 25): the spec section, its checks, its geometry, and the
same solids in coal, MuJoCo and the side view."""

from __future__ import annotations

import dataclasses
import math

import mujoco
import numpy as np
import pytest

from ladders.cli import main as ladders_main
from ladders.collision import ladder_collision_objects
from ladders.geometry import LadderGeometry
from ladders.loader import ladder_from_mapping, ladder_to_mapping, ladder_to_yaml, load_ladder
from ladders.scene import build_scene
from ladders.spec import LANDING_THICKNESS_M

LANDING = """landing:
  height_m: 0.305
  depth_m: 1.2
  width_m: 1.0
  handrails: true
"""


def _spec_file(tmp_path, landing: str = LANDING, name: str = "withlanding"):
    text = ladder_to_yaml(load_ladder("drc")).replace("name: drc", f"name: {name}")
    path = tmp_path / f"{name}.yaml"
    path.write_text(text + landing)
    return path


def test_a_landing_loads_and_round_trips(tmp_path):
    spec = load_ladder(_spec_file(tmp_path))
    assert spec.has_landing and spec.landing_handrails is True
    assert (spec.landing_height_m, spec.landing_depth_m, spec.landing_width_m) == \
        (0.305, 1.2, 1.0)
    assert ladder_from_mapping(ladder_to_mapping(spec), "sidecar") == spec
    again = tmp_path / "again.yaml"
    again.write_text(ladder_to_yaml(spec))
    assert load_ladder(again) == spec
    # a ladder without one writes no landing section
    assert "landing" not in ladder_to_yaml(load_ladder("drc"))
    assert not load_ladder("drc").has_landing


@pytest.mark.parametrize("landing, line_of, words", [
    (LANDING.replace("height_m: 0.305", "height_m: 2.0"), "height_m: 2.0",
     ["landing.height_m", "out of range", "[0.05, 1] m"]),
    (LANDING.replace("  depth_m: 1.2\n", ""), "height_m: 0.305",  # the section's place
     ["landing.depth_m", "is missing from section 'landing'"]),
    (LANDING.replace("handrails: true", "handrails: 1"), "handrails: 1",
     ["landing.handrails", "true or false"]),
    (LANDING.replace("width_m: 1.0", "width_m: wide"), "width_m: wide", ["landing.width_m"]),
])
def test_bad_landing_fields_exit_2_naming_file_line_and_field(tmp_path, capsys, landing,
                                                               line_of, words):
    path = _spec_file(tmp_path, landing, name="bad")
    line = path.read_text().splitlines().index(
        next(t for t in path.read_text().splitlines() if t.strip() == line_of)) + 1
    assert ladders_main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    assert f"{path}:{line}:" in err
    for w in words:
        assert w in err


def test_the_landing_stands_where_the_next_tread_would_and_the_rails_reach_it(tmp_path):
    spec = load_ladder(_spec_file(tmp_path))
    geom = LadderGeometry(spec)
    names = [s.name for s in geom.landing]
    assert names == ["landing", "handrail_left", "handrail_right"]
    slab = geom.landing[0]
    lo, hi = _bounds(slab)
    top = spec.top_rung_height_m + spec.landing_height_m
    assert hi[2] == pytest.approx(top) and lo[2] == pytest.approx(top - LANDING_THICKNESS_M)
    along = top / math.tan(spec.slope_rad)
    x0 = spec.placement_x_m
    assert lo[0] == pytest.approx(x0 + along - spec.rung_depth_m / 2)
    assert hi[0] - lo[0] == pytest.approx(spec.landing_depth_m)
    assert hi[1] - lo[1] == pytest.approx(spec.landing_width_m)
    # the inclined rail ends where the handrail begins, rail_height above the landing
    _, rail_top = geom.rail_axis("left")
    hand = geom.landing[1]
    ends = [hand.centre_m + s * hand.half_extents_m[2] * hand.R_world_solid[:, 2]
            for s in (-1, 1)]
    near = min(ends, key=lambda e: e[0])
    assert np.allclose(near, rail_top, atol=1e-9)
    assert rail_top[2] == pytest.approx(top + spec.rail_height_m)
    assert max(e[0] for e in ends) == pytest.approx(hi[0])
    # without handrails only the slab; the same rails as a ladder one rung taller when
    # the landing sits one rung spacing up
    bare = dataclasses.replace(spec, landing_handrails=False)
    assert [s.name for s in LadderGeometry(bare).landing] == ["landing"]
    none = load_ladder("drc")
    assert np.allclose(LadderGeometry(none).rail_axis("left")[1],
                       LadderGeometry(bare).rail_axis("left")[1])


def _bounds(solid):
    h = solid.half_extents_m
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
    pts = (signs * h) @ solid.R_world_solid.T + solid.centre_m
    return pts.min(axis=0), pts.max(axis=0)


def test_coal_mujoco_and_the_side_view_have_the_landing(tmp_path, capsys):
    path = _spec_file(tmp_path)
    spec = load_ladder(path)
    landing_parts = {"landing", "handrail_left", "handrail_right"}
    assert landing_parts <= {name for name, _, _ in ladder_collision_objects(spec)}
    model = build_scene(spec).compile()
    assert landing_parts <= {model.geom(i).name for i in range(model.ngeom)}
    # MuJoCo's landing is the geometry's: its top surface at the landing's height
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    g = model.geom("landing").id
    top = data.geom_xpos[g][2] + model.geom_size[g][2]
    assert top == pytest.approx(spec.top_rung_height_m + spec.landing_height_m)
    assert ladders_main(["show", str(path), "--out", str(tmp_path)]) == 0
    assert (tmp_path / "withlanding.png").stat().st_size > 0
    assert "landing_height_m" in capsys.readouterr().out
