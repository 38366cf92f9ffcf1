"""Ladders: specs and their YAML files, bundled thesis ladders, world geometry.

Importing the package is light (numpy, PyYAML); meshes (trimesh), coal objects and MuJoCo
bodies live in ``ladders.mesh``, ``ladders.collision``, ``ladders.mjcf`` and
``ladders.scene``.
"""

from ladders.geometry import LadderGeometry, ladder_geometry
from ladders.loader import (
    bundled_ladder_path,
    dump_ladder,
    ladder_to_yaml,
    load_ladder,
    parse_ladder_yaml,
)
from ladders.spec import FIELD_RULES, LadderSpec

__all__ = ["FIELD_RULES", "LadderGeometry", "LadderSpec", "bundled_ladder_path", "dump_ladder",
           "ladder_geometry", "ladder_to_yaml", "load_ladder", "parse_ladder_yaml"]
