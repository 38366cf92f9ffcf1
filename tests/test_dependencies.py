"""Every pinned dependency imports in one process (placo ⇒ pin 3.8 ⇒ coal 3 is fragile)."""

import importlib.metadata as md


def test_all_dependencies_import_together():
    import can
    import coal
    import highspy
    import matplotlib
    import mujoco
    import numpy
    import ompl.base
    import ompl.geometric
    import pinocchio
    import placo
    import rich
    import scipy
    import toppra
    import trimesh
    import yaml
    import yourdfpy

    assert pinocchio.__version__ == "3.8.0"
    assert mujoco.__version__.startswith("4.0")
    assert md.version("placo") == "0.10.2"
    assert md.version("ompl") == "2.0.1"
    assert md.version("toppra") == "0.6.10"
    assert md.version("highspy") == "1.15.1"
    assert highspy.Highs() is not None
    assert coal.Box(1, 1, 1) is not None
    assert ompl.base.RealVectorStateSpace(2).getDimension() == 2
    for mod in (can, matplotlib, numpy, placo, rich, scipy, toppra, trimesh, yaml, yourdfpy):
        assert mod.__name__
