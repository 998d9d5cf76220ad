"""Every exception the project defines is a ChainGeoError (keeping its builtin base), and the
``chain`` command turns any of them into one line and exit status 2."""

from __future__ import annotations

import argparse
import importlib
import inspect
import pkgutil

import pytest

import chaingeo
import chaingeo.generator
import chaingeo.solvers
from chaingeo.cli.main import main
from chaingeo.core.errors import ChainGeoError
from chaingeo.core.level_reader import LevelError
from chaingeo.core.limits import LimitError
from chaingeo.solvers.cover.search import CoverLimitError

PACKAGES = ("chaingeo",)


def _defined_exceptions() -> dict[str, type[Exception]]:
    """Every Exception subclass a module of the project defines, by qualified name (the two
    mapped folders are walked on their own: an editable install's chaingeo.__path__ lacks them)."""
    out: dict[str, type[Exception]] = {}
    for package in (chaingeo, chaingeo.generator, chaingeo.solvers):
        names = [m.name for m in pkgutil.walk_packages(package.__path__, package.__name__ + ".")]
        for name in [package.__name__, *names]:
            try:
                module = importlib.import_module(name)
            except ModuleNotFoundError as e:  # an optional extra not installed, not our bug
                if (e.name or "").split(".")[0] in PACKAGES:
                    raise
                continue
            for obj in vars(module).values():
                if inspect.isclass(obj) and issubclass(obj, Exception) and obj.__module__ == name:
                    out[f"{name}.{obj.__qualname__}"] = obj
    return out


def test_every_exception_defined_in_the_project_is_a_chaingeo_error() -> None:
    found = _defined_exceptions()
    assert len(found) >= 40  # the walk reaches every subpackage, not just the top
    assert "chaingeo.solvers.cover.search.CoverLimitError" in found
    assert sorted(n for n, e in found.items() if not issubclass(e, ChainGeoError)) == []


@pytest.mark.parametrize(
    ("error", "builtin"),
    [(LevelError, ValueError), (LimitError, ValueError), (CoverLimitError, RuntimeError)],
)
def test_errors_keep_their_builtin_base(error: type[Exception], builtin: type[Exception]) -> None:
    assert issubclass(error, ChainGeoError) and issubclass(error, builtin)


class _Boom(ChainGeoError, RuntimeError):
    """Not a ValueError: caught only as a ChainGeoError."""


def test_the_command_line_reports_any_chaingeo_error_in_one_line(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    def run(args: argparse.Namespace) -> int:
        raise _Boom("the reason\u2014in one line")

    monkeypatch.setattr("chaingeo.cli.commands.bench.run", run)
    assert main(["bench", "turns"]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == "chain bench: error: the reason\u2014in one line\n"


def test_the_command_line_lets_a_bug_through(monkeypatch: pytest.MonkeyPatch) -> None:
    def run(args: argparse.Namespace) -> int:
        raise RuntimeError("a bug, with its traceback")

    monkeypatch.setattr("chaingeo.cli.commands.bench.run", run)
    with pytest.raises(RuntimeError, match="a bug"):
        main(["bench", "turns"])
