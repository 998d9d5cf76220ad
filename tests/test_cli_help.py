"""Every subcommand (and sub-subcommand) answers ``--help`` and shows its options' defaults."""

from __future__ import annotations

import argparse

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


def test_every_command_is_listed_once_without_aliases() -> None:
    top = [c[0] for c in COMMANDS if len(c) == 1]
    assert len(top) == len(set(top)) >= 12
    assert "analyze" in top and "convert" in top


@pytest.mark.parametrize("command", COMMANDS, ids=" ".join)
def test_help_answers_and_shows_defaults(
    command: tuple[str, ...], capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as done:
        main([*command, "--help"])
    assert done.value.code == 0
    text = capsys.readouterr().out
    assert text.startswith(f"usage: chain {' '.join(command)}")
    parser = build_parser()
    for name in command:
        sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
        parser = sub.choices[name]
    shown = [
        a
        for a in parser._actions
        if a.option_strings
        and a.help not in (None, argparse.SUPPRESS)
        and a.default not in (None, False, [], argparse.SUPPRESS)
    ]
    for action in shown:
        assert f"default: {action.default}" in " ".join(text.split()), action.dest
