"""Cross-field rules of `LadderSpec`, checked against the geometry they protect (coal)."""

import dataclasses

import coal
import pytest

from ladders.collision import ladder_collision_objects
from ladders.loader import load_ladder
from ladders.spec import STRINGER_WIDTH_M, LadderSpecError


def _min_rail_to_body_distance_m(spec) -> float:
    """Smallest coal distance from either rail to any rung or stringer [m]."""
    objects = ladder_collision_objects(spec)
    rails = [o for o in objects if o[0].startswith("rail")]
    body = [o for o in objects if not o[0].startswith("rail")]
    best = float("inf")
    for _, g1, T1 in rails:
        for _, g2, T2 in body:
            result = coal.DistanceResult()
            coal.distance(g1, T1, g2, T2, coal.DistanceRequest(), result)
            best = min(best, result.min_distance)
    return best


@pytest.mark.parametrize("name", ["drc", "ship", "stair"])
def test_bundled_rails_clear_rungs_and_stringers(name):
    # The ship's rails (0.79 m) stand above its stringers (rungs 0.762 m): they pass
    # because they are high above the rung line, and coal agrees.
    assert _min_rail_to_body_distance_m(load_ladder(name)) > 0.01


def _vertical_drc(rail_spacing_m: float):
    return dataclasses.replace(load_ladder("drc"), slope_deg=90.0, rail_spacing_m=rail_spacing_m)


def test_vertical_ladder_rails_must_clear_the_stringers_laterally():
    drc = load_ladder("drc")
    clear_m = 2 * (drc.rung_width_m / 2 + STRINGER_WIDTH_M + drc.rail_radius_m)
    ok = _vertical_drc(clear_m + 0.002)
    assert _min_rail_to_body_distance_m(ok) == pytest.approx(0.001, abs=1e-6)
    with pytest.raises(LadderSpecError, match=r"field 'rail_spacing_m' = 0\.9\d* .*rung_width_m"):
        _vertical_drc(clear_m - 0.002)


def test_box_rungs_thicker_than_the_spacing_are_refused():
    with pytest.raises(LadderSpecError, match="field 'rung_thickness_m' = 0.1 .*rung_spacing_m"):
        dataclasses.replace(load_ladder("drc"), rung_spacing_m=0.1, rung_thickness_m=0.1)


def test_cylinder_rungs_that_would_overlap_are_refused():
    drc = load_ladder("drc")
    spec = dataclasses.replace(drc, rung_shape="cylinder", rung_depth_m=0.05)
    assert spec.rung_shape == "cylinder"
    with pytest.raises(LadderSpecError, match="field 'rung_depth_m' = 0.4 .*sin\\(slope\\)"):
        dataclasses.replace(drc, rung_shape="cylinder", rung_depth_m=0.4, rung_spacing_m=0.3)


def test_first_rung_below_its_own_thickness_is_refused():
    with pytest.raises(LadderSpecError,
                       match="field 'first_rung_height_m' = 0.05 .*into the floor"):
        dataclasses.replace(load_ladder("drc"), first_rung_height_m=0.05, rung_thickness_m=0.08)
