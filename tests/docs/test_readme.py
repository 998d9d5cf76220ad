"""Every code block of the README is checked: the Python example is docs/examples/quickstart.py
and runs; each shell line is what CI runs, a `chain ... --help` that is executed, or a `chain`
command line the parser accepts; the command table lists every subcommand; links resolve."""

from __future__ import annotations

import argparse
import contextlib
import io
import re
import shlex

import pytest

from chaingeo.cli.main import build_parser
from tests.support.paths import ROOT

README = (ROOT / "README.md").read_text(encoding="utf-8")
CI = (ROOT / ".ci" / "run").read_text().splitlines()


def _blocks(lang: str) -> list[str]:
    return re.findall(rf"```{lang}\n(.*?)\n```", README, flags=re.S)


def _subcommands() -> set[str]:
    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    return set(sub.choices)


def _ci_runs(line: str) -> bool:
    """CI runs this line (its installs are --quiet; the README's show progress)."""
    return line in CI or line in {c.replace(" --quiet", "") for c in CI}


def test_ci_runs_the_readme_test_command() -> None:
    test_cmd = next(b for b in _blocks("bash") if b.startswith("python -m pytest"))
    assert test_cmd in CI


def test_the_install_line_is_ci_s() -> None:
    lines = [ln for b in _blocks("bash") for ln in b.splitlines() if "pip install" in ln]
    assert lines and all(_ci_runs(ln) for ln in lines), lines


def test_every_shell_line_is_checked() -> None:
    parser = build_parser()
    for line in (ln for b in _blocks("bash") for ln in b.splitlines()):
        args = shlex.split(line)
        if _ci_runs(line):
            continue
        assert args[0] == "chain", f"a README shell line nothing checks: {line}"
        if "--help" in args:
            out = io.StringIO()
            with contextlib.redirect_stdout(out), pytest.raises(SystemExit) as stop:
                parser.parse_args(args[1:])  # runs the help, as the shell would
            assert stop.value.code == 0 and out.getvalue().startswith("usage: chain"), line
        else:
            parser.parse_args(args[1:])  # accepted as typed (running it is a benchmark)


def test_the_python_example_is_the_quickstart_and_runs() -> None:
    quickstart = (ROOT / "docs" / "examples" / "quickstart.py").read_text(encoding="utf-8")
    assert _blocks("python") == [quickstart.rstrip("\n")]
    with contextlib.redirect_stdout(io.StringIO()):
        exec(compile(quickstart, "quickstart.py", "exec"), {"__name__": "readme"})


def test_the_command_table_lists_every_subcommand() -> None:
    rows = re.findall(r"^\| `chain ([a-z-]+)[^`]*` \|", README, flags=re.M)
    assert len(rows) == len(set(rows))
    assert set(rows) == _subcommands()


def test_links_resolve_and_the_readme_stays_short() -> None:
    targets = re.findall(r"\]\(([^)#]+)\)", README)
    local = [t for t in targets if "://" not in t]
    assert local and [t for t in local if not (ROOT / t).exists()] == []
    assert len(README.splitlines()) < 200
