"""Ladder geometry in the world frame, meshes and coal collision objects."""

import math

import coal
import numpy as np
import pytest
import trimesh

from ladders.collision import ladder_collision_objects
from ladders.geometry import LadderGeometry
from ladders.loader import load_ladder
from ladders.mesh import export_ladder_mesh, ladder_mesh


def test_drc_rungs_and_rails_where_hand_computation_puts_them():
    spec = load_ladder("drc")
    geom = LadderGeometry(spec)
    t60 = math.tan(math.radians(60))
    for i in (0, 4, 8):
        h = 0.305 + 0.305 * i
        np.testing.assert_allclose(geom.rung_top_centres_m[i], [0.16 + h / t60, 0.0, h],
                                   atol=1e-12)
    p = geom.rail_point_above_rung("left", 3)
    h3 = 0.305 * 4
    np.testing.assert_allclose(p, [0.16 + h3 / t60, 0.675, h3 + 0.91], atol=1e-12)
    np.testing.assert_allclose(geom.ladder_direction, [0.5, 0.0, math.sqrt(3) / 2], atol=1e-12)


def test_placement_moves_and_turns_everything():
    from dataclasses import replace

    spec = replace(load_ladder("drc"), placement_x_m=1.0, placement_y_m=-0.5,
                   placement_yaw_rad=math.pi / 2)
    geom = LadderGeometry(spec)
    c0 = geom.rung_top_centres_m[0]
    d0 = 0.305 / math.tan(math.radians(60))
    np.testing.assert_allclose(c0, [1.0, -0.5 + d0, 0.305], atol=1e-12)
    np.testing.assert_allclose(geom.to_ladder(geom.to_world([0.3, 0.2, 0.1])), [0.3, 0.2, 0.1])


def test_coal_distance_above_a_rung_top():
    spec = load_ladder("drc")
    geom = LadderGeometry(spec)
    objects = {name: (shape, tf) for name, shape, tf in ladder_collision_objects(spec)}
    assert {"rung_0", "rail_left", "rail_right", "stringer_left"} <= set(objects)
    shape, tf = objects["rung_2"]
    radius = 0.02
    above = geom.rung_top_centres_m[2] + [0.0, 0.0, 0.05]
    req, res = coal.DistanceRequest(), coal.DistanceResult()
    d = coal.distance(coal.Sphere(radius), coal.Transform3s(np.eye(3), above), shape, tf,
                      req, res)
    assert d == pytest.approx(0.05 - radius, abs=1e-9)
    shape, tf = objects["rail_right"]
    on_axis = geom.rail_point_above_rung("right", 2)
    d = coal.distance(coal.Sphere(radius), coal.Transform3s(np.eye(3), on_axis + [0, 0, 0.1]),
                      shape, tf, req, coal.DistanceResult())
    # 10 cm straight up from the axis of a rail inclined 60°: 0.1·cos 60° from the axis.
    assert d == pytest.approx(0.1 * 0.5 - spec.rail_radius_m - radius, abs=1e-6)


@pytest.mark.parametrize("ext", ["stl", "obj", "glb"])
def test_mesh_exports(tmp_path, ext):
    spec = load_ladder("ship")
    mesh = ladder_mesh(spec)
    assert mesh.is_volume or len(mesh.faces) > 0
    lo, hi = mesh.bounds
    assert hi[2] > spec.rung_height_m(spec.num_rungs - 1) and lo[2] < 0.05
    path = export_ladder_mesh(spec, tmp_path / f"ship.{ext}")
    back = trimesh.load(path, force="mesh")
    assert len(back.faces) > 0
