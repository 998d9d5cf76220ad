"""The layout of tests/ itself: test modules share code only through :mod:`tests.support` (or
conftest.py fixtures), never by importing each other, so moving or deleting one test file
cannot break another; every folder is a package, so two folders may hold the same basename
under pytest's default import mode; and tests find their files through
:mod:`tests.support.paths`, not through their own place in the tree."""

from __future__ import annotations

import ast
import re
from pathlib import Path

from tests.support.paths import TESTS

SOURCES = sorted(TESTS.rglob("*.py"))
#: A dotted name whose last part is a test module (``tests.core.test_level``, ``test_cover``).
_TEST_MODULE = re.compile(r"(?:^|\.)test_\w+$")
#: A test module named in text (a script written to a subprocess, an env name, a docstring).
_NAMED_IN_TEXT = re.compile(r"\btests(?:\.\w+)*\.test_\w+")


def imported_test_modules(source: str) -> list[str]:
    """The test modules a Python source imports or names as ``tests....test_x``."""
    found: list[str] = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            found += [a.name for a in node.names if _TEST_MODULE.search(a.name)]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            names = [base, *(f"{base}.{a.name}" for a in node.names)]
            found += [n for n in names if _TEST_MODULE.search(n)]
    return found + _NAMED_IN_TEXT.findall(source)


def test_the_checker_catches_every_way_of_importing_a_test_module() -> None:
    caught = [
        "from tests.test_cover import instances",
        "from tests.solvers.cover.test_cover import instances",
        "from tests.solvers.cover import test_cover",
        "import tests.core.test_level as t",
        "from .test_cover import instances",
        'SCRIPT = "from tests.evaluation.test_eval_runner import FAKE"',
    ]
    for source in caught:
        assert imported_test_modules(source), source
    assert not imported_test_modules("from tests.support.scenes import SCENE\nimport pytest")


def test_no_module_of_the_tests_imports_a_test_module() -> None:
    own = Path(__file__).resolve()  # its examples above name test modules on purpose
    bad = {
        p.relative_to(TESTS).as_posix(): got
        for p in SOURCES
        if p != own and (got := imported_test_modules(p.read_text(encoding="utf-8")))
    }
    assert not bad, f"move what these share into tests/support/: {bad}"


def test_every_folder_of_the_tests_is_a_package() -> None:
    folders = {p.parent for p in SOURCES}
    assert not [f for f in folders if not (f / "__init__.py").is_file()]


def test_tests_in_folders_find_their_files_through_the_support_paths() -> None:
    nested = [p for p in SOURCES if p.parent != TESTS and p.name != "paths.py"]
    nested.remove(Path(__file__).resolve())
    own_file = re.compile(r"(?<![\w.])__file__")  # a module's own, not ``mod.__file__``
    assert not [p.name for p in nested if own_file.search(p.read_text(encoding="utf-8"))]
