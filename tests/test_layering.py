"""Architecture rules that must stay true: light packages, floors that import only downwards,
a daemon without planners, and the simulated world kept to the sim backend and `execute`."""

import ast
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("robot", "ladders", "primitives", "planner", "execute", "daemon")
#: Package → the project packages it may import (docs/architecture.md, "Packages").
MAY_IMPORT = {
    "robot": set(),
    "ladders": {"robot"},
    "primitives": {"robot", "ladders"},
    "planner": {"robot", "ladders", "primitives"},
    "execute": {"robot", "ladders", "primitives", "planner", "daemon"},
    "daemon": {"robot", "ladders"},
}
PLANNING_LIBRARIES = ("placo", "pinocchio", "pin", "ompl", "toppra", "coal", "highspy")


def _modules() -> dict[str, Path]:
    """Dotted module name → file, for every module of the six packages."""
    out = {}
    for pkg in PACKAGES:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            parts = path.relative_to(ROOT).with_suffix("").parts
            out[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return out


def _imports(path: Path) -> set[str]:
    """Every module a file imports, at the top or inside a function."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found.add(node.module)
            found.update(f"{node.module}.{a.name}" for a in node.names)
    return found


IMPORTS = {name: _imports(path) for name, path in _modules().items()}


def _top(module: str) -> str:
    return module.split(".")[0]


def _within(module: str, package: str) -> bool:
    return module == package or module.startswith(package + ".")


def test_importing_the_packages_loads_nothing_heavy():
    heavy = ("placo", "pinocchio", "ompl", "mujoco", "can", "coal", "toppra", "trimesh")
    code = ("import sys\nimport robot, ladders, primitives, planner, execute, daemon\n"
            "import daemon.sim, daemon.can, execute.play, execute.validate, execute.batch\n"
            "import planner.statics, planner.configuration, planner.paths, planner.verify\n"
            f"print(','.join(m for m in {heavy!r} if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == ""


@pytest.mark.parametrize("module", ["daemon.loop", "daemon.sim.backend", "daemon.can.backend",
                                    "daemon.cli", "daemon.console", "execute.play.cli",
                                    "daemon.station.cli", "daemon.station.page"])
def test_the_robot_side_never_imports_planning_libraries(module):
    code = (f"import sys\nimport {module}\n"
            "print(','.join(m for m in ('placo', 'pinocchio', 'ompl', 'toppra') "
            "if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.strip()
    assert out == ""


#: Command lines that sit above their package's floor: module → the modules it may import.
#: ``python -m robot export --ladder`` writes the ladder scene (`ladders.scene`).
COMMAND_EXCEPTIONS = {"robot.cli": {"ladders", "ladders.loader", "ladders.scene",
                                    "ladders.loader.load_ladder", "ladders.scene.build_scene"}}


def test_each_package_imports_only_the_floors_below_it():
    wrong = [(m, i) for m, imports in IMPORTS.items() for i in imports
             if _top(i) in PACKAGES and _top(i) != _top(m) and _top(i) not in MAY_IMPORT[_top(m)]
             and i not in COMMAND_EXCEPTIONS.get(m, ())]
    assert wrong == []


def test_the_robot_library_imports_nothing_above_it():
    """Only the ``python -m robot`` command reaches into `ladders`, inside ``--ladder``."""
    wrong = [(m, i) for m, imports in IMPORTS.items() if _within(m, "robot")
             and m not in COMMAND_EXCEPTIONS for i in imports
             if _top(i) in PACKAGES and _top(i) != "robot"]
    assert wrong == []


def test_the_daemon_never_imports_execute_or_a_planning_library():
    wrong = [(m, i) for m, imports in IMPORTS.items() if _within(m, "daemon") for i in imports
             if _top(i) in ("execute", "planner", "primitives", *PLANNING_LIBRARIES)]
    assert wrong == []


#: Outside `daemon.sim`, the daemon's modules that build a sim scene: ``hubo-daemon
#: --ladder`` loads the ladder; hubo-init's head camera renders the sim daemon's scene.
SCENE_BUILDERS = ("daemon.cli", "daemon.station.head_camera")


def test_the_daemon_uses_ladders_only_in_the_simulated_world():
    """The sim backend places the robot before a ladder; ``hubo-daemon --ladder`` loads it;
    ``hubo-init --camera sim`` builds the same scene to render the head camera."""
    wrong = [(m, i) for m, imports in IMPORTS.items()
             if _within(m, "daemon") and not _within(m, "daemon.sim")
             and m not in SCENE_BUILDERS for i in imports if _top(i) == "ladders"]
    assert wrong == []


def test_the_simulated_world_is_imported_only_by_the_sim_backend_and_execute():
    """Outside `daemon.sim` and `execute`, only ``hubo-daemon`` may reach into it, and only
    through the sim backend (to start it)."""
    wrong = []
    for m, imports in IMPORTS.items():
        if _within(m, "daemon.sim") or _within(m, "execute"):
            continue
        for i in imports:
            if not _within(i, "daemon.sim"):
                continue
            if m == "daemon.cli" and _within(i, "daemon.sim.backend"):
                continue
            wrong.append((m, i))
    assert wrong == []


def test_the_can_and_sim_backends_do_not_import_each_other():
    wrong = [(m, i) for m, imports in IMPORTS.items() for i in imports
             if (_within(m, "daemon.sim") and _within(i, "daemon.can"))
             or (_within(m, "daemon.can") and _within(i, "daemon.sim"))]
    assert wrong == []
