"""Architecture rules that must stay true: light packages, and a daemon without planners."""

import subprocess
import sys

import pytest


def _loaded_after(imports: str, modules: tuple[str, ...]) -> list[str]:
    code = (f"import sys\n{imports}\n"
            f"print(','.join(m for m in {modules!r} if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.strip()
    return [m for m in out.split(",") if m]


def test_importing_the_packages_loads_nothing_heavy():
    heavy = ("placo", "pinocchio", "ompl", "mujoco", "can", "coal", "toppra", "trimesh")
    assert _loaded_after("import robot, ladders, primitives, planner, execute, daemon",
                         heavy) == []


@pytest.mark.parametrize("module", ["daemon.loop", "daemon.backend_sim", "daemon.backend_can",
                                    "daemon.cli", "daemon.console", "execute.play_cli"])
def test_the_robot_side_never_imports_planning_libraries(module):
    assert _loaded_after(f"import {module}", ("placo", "pinocchio", "ompl", "toppra")) == []
