"""The wheel's package list is complete: pyproject lists packages by hand (the suite folder is
mapped in as chaingeo.levels), so a new sub-package must be added there; this test says so."""

from __future__ import annotations

import tomllib

from chaingeo.core.suite import suite_folder
from tests.support.paths import ROOT


def test_every_package_of_the_tree_goes_into_the_wheel() -> None:
    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]
    listed = set(config["setuptools"]["packages"])
    dirs = config["setuptools"]["package-dir"]
    assert dirs == {
        "chaingeo.levels": "levels",
        "chaingeo.solvers": "solvers",
        "chaingeo.generator": "generator",
    }
    found = {
        ".".join((package, *init.parent.relative_to(ROOT / folder).parts))
        for package, folder in (("chaingeo", "chaingeo"), *((p, d) for p, d in dirs.items()))
        if package != "chaingeo.levels"
        for init in (ROOT / folder).rglob("__init__.py")
    }
    assert found | {"chaingeo.levels"} == listed
    assert {name.split(".")[0] for name in listed} == {"chaingeo"}


def test_the_shipped_suite_is_found_as_package_data() -> None:
    assert suite_folder().resolve() == (ROOT / "levels").resolve()
    assert len(list(suite_folder("puzzle").glob("*.json"))) == 32
    assert len(list(suite_folder("stacking").glob("*.json"))) == 77
