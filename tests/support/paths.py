"""Folders the tests read, found from this file once, so a test's own place in tests/ does not
matter (moving a test never breaks a path)."""

from __future__ import annotations

from pathlib import Path

#: The checkout (the folder holding pyproject.toml).
ROOT = Path(__file__).resolve().parents[2]
#: The shipped level suite (levels/, installed as chaingeo.levels).
LEVELS = ROOT / "levels"
#: The tests' own files: tests/data (inputs) and tests/golden (recorded outputs).
TESTS = ROOT / "tests"
DATA = TESTS / "data"
GOLDEN = TESTS / "golden"
