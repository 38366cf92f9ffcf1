"""Shared test hygiene: a command run in-process with ``-v`` sets the root logger's level
and handler for the rest of the process (`logging.basicConfig(force=True)`, as a CLI
should); each test gets the logging it started with back, so that one test's verbosity
does not print into another's captured output."""

from __future__ import annotations

import logging

import pytest


@pytest.fixture(autouse=True)
def _restore_root_logging():
    root = logging.getLogger()
    level, handlers = root.level, list(root.handlers)
    yield
    root.setLevel(level)
    root.handlers[:] = handlers
