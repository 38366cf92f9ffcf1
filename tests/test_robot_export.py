"""``python -m robot export``: the generated URDF loads in pinocchio, yourdfpy and (when
installed) ``check_urdf``; the MJCF, alone or as the ladder scene, compiles and steps in
MuJoCo; bad input exits 2 and writes nothing."""

from __future__ import annotations

import shutil
import subprocess
import sys

import mujoco
import numpy as np
import pytest

from robot.cli import main
from robot.joints import JOINT_NAMES
from robot.params import robot_params

ROBOTS = ("drc-hubo", "hubo2plus")


def _hinges(robot: str) -> set[str]:
    """The trajectory columns that are joints of this robot (Hubo2+ has no wrist roll)."""
    from robot.kinematic_tree import build_tree

    return set(build_tree(robot_params(robot)).joint_links) & set(JOINT_NAMES)


@pytest.mark.parametrize("robot", ROBOTS)
def test_urdf_loads_in_pinocchio_and_yourdfpy(robot, tmp_path, capsys):
    import pinocchio as pin
    import yourdfpy

    path = tmp_path / f"{robot}.urdf"
    assert main(["export", "--robot", robot, "--format", "urdf", "-o", str(path)]) == 0
    assert f"URDF of {robot}" in capsys.readouterr().err
    model = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    names = set(model.names) - {"universe", "root_joint"}
    assert _hinges(robot) <= names
    urdf = yourdfpy.URDF.load(str(path), load_meshes=False, build_scene_graph=True)
    assert urdf.robot.name == robot
    assert _hinges(robot) <= set(urdf.actuated_joint_names)


@pytest.mark.skipif(shutil.which("check_urdf") is None,
                    reason="check_urdf not installed (Debian: liburdfdom-tools)")
@pytest.mark.parametrize("robot", ROBOTS)
def test_urdf_passes_check_urdf(robot, tmp_path):
    path = tmp_path / f"{robot}.urdf"
    assert main(["export", "--robot", robot, "-o", str(path)]) == 0  # format from suffix
    r = subprocess.run(["check_urdf", str(path)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert f"robot name is: {robot}" in r.stdout and "Successfully Parsed XML" in r.stdout


@pytest.mark.parametrize("robot", ROBOTS)
def test_mjcf_compiles_and_stands_a_second(robot, tmp_path):
    path = tmp_path / f"{robot}.xml"
    assert main(["export", "--robot", robot, "--format", "mjcf", "-o", str(path)]) == 0
    model = mujoco.MjModel.from_xml_path(str(path))
    names = {model.actuator(i).name for i in range(model.nu)}
    assert _hinges(robot) <= names
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    for _ in range(round(1.0 / model.opt.timestep)):
        mujoco.mj_step(model, data)
    assert np.isfinite(data.qpos).all()
    assert not any(data.warning[i].number for i in range(len(data.warning)))


def test_ladder_scene_compiles_with_the_ladder_and_the_camera(tmp_path):
    path = tmp_path / "scene.xml"
    assert main(["export", "--ladder", "drc", "--format", "mjcf", "-o", str(path)]) == 0
    model = mujoco.MjModel.from_xml_path(str(path))
    assert mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "ladder") >= 0
    assert mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_CAMERA, "side") >= 0


def test_stdout_output():
    r = subprocess.run([sys.executable, "-m", "robot", "export", "--format", "urdf", "-o", "-"],
                       capture_output=True, text=True, check=True)
    assert r.stdout.startswith('<?xml version="1.0"?>') and "<robot name=\"drc-hubo\">" in r.stdout


@pytest.mark.parametrize(("args", "message"), [
    (["--ladder", "drc", "--format", "urdf"], "--ladder needs --format mjcf"),
    (["--ladder", "no-such-ladder", "--format", "mjcf"], "unknown ladder 'no-such-ladder'"),
    (["--format", "mjcf", "-o", "/no/such/dir/x.xml"], "cannot write"),
    (["-o", "model.txt"], "give --format urdf or mjcf"),
])
def test_bad_input_exits_2_and_writes_nothing(tmp_path, capsys, monkeypatch, args, message):
    monkeypatch.chdir(tmp_path)
    if "-o" not in args:
        args = [*args, "-o", "out.xml"]
    assert main(["export", *args]) == 2
    assert message in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("args", [["--robot", "atlas", "-o", "x.urdf"],
                                  ["--format", "sdf", "-o", "x.urdf"]])
def test_unknown_robot_or_format_exits_2(args, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["export", *args])
    assert exc.value.code == 2
    assert "invalid choice" in capsys.readouterr().err
