"""Every subcommand (and sub-subcommand) answers ``--help``, shows the default of every option
that has one and marks the required ones; no command is listed under an internal alias."""

from __future__ import annotations

import argparse
import re

import pytest

from chaingeo.cli.main import build_parser, main


def _commands(
    parser: argparse.ArgumentParser, prefix: tuple[str, ...] = ()
) -> list[tuple[str, ...]]:
    out = []
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                out.append((*prefix, name))
                out.extend(_commands(sub, (*prefix, name)))
    return out


COMMANDS = _commands(build_parser())


def _parser(command: tuple[str, ...]) -> argparse.ArgumentParser:
    parser = build_parser()
    for name in command:
        sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
        parser = sub.choices[name]
    return parser


def _help(command: tuple[str, ...], capsys: pytest.CaptureFixture[str]) -> str:
    with pytest.raises(SystemExit) as done:
        main([*command, "--help"])
    assert done.value.code == 0
    return capsys.readouterr().out


def test_every_command_is_listed_once_without_aliases(capsys: pytest.CaptureFixture[str]) -> None:
    top = [c[0] for c in COMMANDS if len(c) == 1]
    assert len(top) == len(set(top)) >= 12
    assert "analyze" in top and "convert" in top and "import" in top
    assert "import_model" not in top
    listing = _help((), capsys)
    # argparse lists an alias as "name (alias)" in the command column
    assert not re.search(r"^\s{4}[a-z-]+ \(", listing, re.MULTILINE), listing
    for command in {c[:-1] for c in COMMANDS if len(c) > 1}:
        assert not re.search(r"^\s{4}[a-z0-9-]+ \(", _help(command, capsys), re.MULTILINE)


def _takes_a_default(action: argparse.Action) -> bool:
    """An option that takes a value and falls back to one when not given."""
    return bool(
        action.option_strings
        and action.nargs != 0
        and not action.required
        and action.help != argparse.SUPPRESS
        and action.default not in (None, [], argparse.SUPPRESS)
    )


@pytest.mark.parametrize("command", COMMANDS, ids=" ".join)
def test_help_answers_shows_defaults_and_marks_required_options(
    command: tuple[str, ...], capsys: pytest.CaptureFixture[str]
) -> None:
    text = _help(command, capsys)
    assert text.startswith(f"usage: chain {' '.join(command)}")
    flat = " ".join(text.split())
    for action in _command_actions(command):
        if _takes_a_default(action):
            assert f"(default: {action.default})" in flat, action.dest
        if action.required and action.option_strings:
            own = " ".join((action.help or "").split())
            assert f"{own} (required)" in flat, action.dest
    # a default stated by hand beside the formatter's would say it twice, or differently
    assert not re.search(r"\(default [^:]", flat), flat


def _command_actions(command: tuple[str, ...]) -> list[argparse.Action]:
    return list(_parser(command)._actions)


@pytest.mark.parametrize(
    ("command", "shown"),
    [
        (("eval",), "(default: 1)"),  # --jobs
        (("import",), "time cap of each analysis (default: 120.0)"),  # --seconds
        (("analyze",), "(default: 2000000)"),  # --max-states
        (("eval",), "(default: 0)"),  # --seed: a zero default is a default too
        (("generate", "stacking"), "required: --box and --mode, or --config"),
        (("convert",), "direction (required: one of)"),
        (("video",), "(required)"),
        (("cover",), "(required)"),
    ],
)
def test_known_defaults_and_requirements_are_shown(
    command: tuple[str, ...], shown: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert shown in " ".join(_help(command, capsys).split())


def test_version_is_chaingeos(capsys: pytest.CaptureFixture[str]) -> None:
    from importlib.metadata import version

    with pytest.raises(SystemExit) as done:
        main(["--version"])
    assert done.value.code == 0
    assert capsys.readouterr().out == f"chain {version('chaingeo')}\n"
