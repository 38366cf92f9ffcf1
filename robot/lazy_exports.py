"""Lazy re-exports for a package ``__init__`` whose modules import heavy libraries.

A package's ``__init__`` re-exports its public names, but importing the package must not
load MuJoCo, python-can, placo or OMPL for a user who needs none of them (the daemon on
the robot, a test that reads a sidecar). `lazy_exports` gives the package a module-level
``__getattr__`` (PEP 562) that imports the defining module on first access.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from typing import Any

__all__ = ["lazy_exports"]


def lazy_exports(package: str, exports: Mapping[str, str]
                 ) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """The ``(__getattr__, __dir__)`` pair of a package that re-exports names lazily.

    Args:
        package: the package's ``__name__``.
        exports: public name → the sub-module (relative to ``package``) that defines it.
    """

    def __getattr__(name: str) -> Any:
        module = exports.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        return getattr(importlib.import_module(f"{package}.{module}"), name)

    def __dir__() -> list[str]:
        return sorted(exports)

    return __getattr__, __dir__
