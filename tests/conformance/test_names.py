"""Names the packages keep unique or regular: a class name is defined in one module only (two
``Outcome`` classes drift apart silently), and every kernel listed in the design notes is named
after its pure-Python reference (docs/design/index.md, "Kernels and their references")."""

from __future__ import annotations

import ast
import re
from collections import defaultdict
from pathlib import Path

from tests.support.paths import ROOT

PACKAGES = ("chaingeo", "solvers", "generator")
DESIGN = ROOT / "docs" / "design" / "index.md"
#: A path in backticks in a table cell: ``chaingeo/core/turns.py``.
_PATH = re.compile(r"`((?:chaingeo|solvers|tests)/[\w/]+\.py)`")


def class_homes(sources: dict[str, str]) -> dict[str, list[str]]:
    """Each class name defined in more than one module, with those modules."""
    homes: dict[str, set[str]] = defaultdict(set)
    for name, text in sources.items():
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, ast.ClassDef):
                homes[node.name].add(name)
    return {k: sorted(v) for k, v in sorted(homes.items()) if len(v) > 1}


def package_sources() -> dict[str, str]:
    return {
        p.relative_to(ROOT).as_posix(): p.read_text(encoding="utf-8")
        for root in PACKAGES
        for p in sorted((ROOT / root).rglob("*.py"))
    }


def test_the_checker_finds_a_class_defined_in_two_modules() -> None:
    sources = {"a.py": "class Outcome:\n    pass\n", "b.py": "def f():\n    class Outcome: ...\n"}
    assert class_homes(sources) == {"Outcome": ["a.py", "b.py"]}
    assert class_homes({"a.py": "class A: ...\nclass B: ..."}) == {}


def test_no_class_name_is_defined_in_two_modules() -> None:
    twice = class_homes(package_sources())
    assert not twice, f"one class per name (merge them or name them apart): {twice}"


def kernel_pairs(markdown: str) -> list[tuple[str, list[str], list[str]]]:
    """The rows of the design notes' table: (reference, kernels, equivalence tests)."""
    section = markdown.split("## Kernels and their references", 1)[1].split("\n## ", 1)[0]
    rows = []
    for line in section.splitlines():
        cells = line.strip().strip("|").split("|")
        if len(cells) == 3 and (ref := _PATH.findall(cells[0])):
            rows.append((ref[0], _PATH.findall(cells[1]), _PATH.findall(cells[2])))
    return rows


def rule_breaks(reference: str, kernel: str, docstring: str) -> list[str]:
    """What a kernel module breaks of the naming rule for its reference."""
    stem, name = Path(reference).stem, Path(kernel).stem
    broken = []
    if not re.fullmatch(rf"{re.escape(stem)}(?:_[a-z]+)?_kernel", name):
        broken.append(f"{kernel} is not named {stem}_kernel.py or {stem}_<part>_kernel.py")
    dotted = reference.removesuffix(".py").replace("/", ".")
    if dotted not in docstring.split("\n\n", 1)[0]:
        broken.append(f"{kernel}'s first docstring paragraph does not name {dotted}")
    return broken


def test_the_rule_catches_a_kernel_named_apart() -> None:
    doc = "Fast. The reference is :mod:`chaingeo.core.turns`."
    assert not rule_breaks("chaingeo/core/turns.py", "solvers/motion/turns_sweep_kernel.py", doc)
    assert rule_breaks("chaingeo/core/turns.py", "solvers/motion/turnmoves.py", doc)
    assert rule_breaks("chaingeo/pictures/raster.py", "chaingeo/pictures/rasterjit.py", "")
    assert rule_breaks("chaingeo/core/turns.py", "solvers/motion/turns_kernel.py", "Fast.\n\nturns")


def test_every_kernel_in_the_design_notes_follows_the_naming_rule() -> None:
    pairs = kernel_pairs(DESIGN.read_text(encoding="utf-8"))
    assert len(pairs) >= 4, "the table of kernels and references was not found"
    broken = []
    for reference, kernels, tests in pairs:
        assert kernels and tests, reference
        for path in [reference, *kernels, *tests]:
            assert (ROOT / path).is_file(), f"{path} (docs/design/index.md) does not exist"
        for kernel in kernels:
            doc = ast.get_docstring(ast.parse((ROOT / kernel).read_text(encoding="utf-8")))
            broken += rule_breaks(reference, kernel, doc or "")
    assert not broken, broken
