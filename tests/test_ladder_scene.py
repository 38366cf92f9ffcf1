"""The MuJoCo scene of each bundled ladder with the robot standing in front of it."""

import dataclasses

import mujoco
import numpy as np
import pytest

from ladders.loader import load_ladder
from ladders.scene import build_scene


@pytest.mark.parametrize("name", ["drc", "ship", "stair"])
def test_scene_holds_the_robot_standing_for_two_seconds(name):
    model = build_scene(load_ladder(name)).compile()
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_forward(model, data)
    ladder_geoms = {model.geom(i).name for i in range(model.ngeom)
                    if model.geom(i).name.startswith(("rung", "rail", "stringer"))}
    assert {"rung_0", "rail_left", "rail_right"} <= ladder_geoms
    z0 = data.qpos[2]
    for _ in range(int(2.0 / model.opt.timestep)):
        mujoco.mj_step(model, data)
        for c in data.contact[:data.ncon]:  # the robot does not touch the ladder
            names = {model.geom(c.geom1).name, model.geom(c.geom2).name}
            assert not names & ladder_geoms, names
    assert abs(data.qpos[2] - z0) < 0.01
    tilt = 2 * np.arccos(min(1.0, abs(data.qpos[3])))
    assert tilt < np.radians(1.0)
    assert all(data.warning[i].number == 0 for i in range(len(data.warning)))


def test_ladder_contacts_take_the_ladders_friction():
    """MuJoCo mixes friction by the maximum; the ladder's μ (0.3 here, the robot's geoms
    have 1.0) must be the one its contacts use, as the planner assumed."""
    ladder = load_ladder("drc")
    ladder = dataclasses.replace(ladder, friction=0.3)
    model = build_scene(ladder).compile()
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    mujoco.mj_forward(model, data)
    data.qpos[0] = data.geom_xpos[model.geom("rung_0").id][0]  # the robot inside the ladder
    mujoco.mj_forward(model, data)
    is_ladder = [model.geom(i).name.startswith(("rung", "rail", "stringer"))
                 for i in range(model.ngeom)]
    ladder_contacts = [c for c in data.contact[:data.ncon]
                       if is_ladder[c.geom1] != is_ladder[c.geom2]]
    assert ladder_contacts
    for c in ladder_contacts:
        assert c.friction[0] == pytest.approx(0.3)
