"""One help formatter for every ``chain`` subcommand: each option shows its default and whether
it is required, so no help text states a default by hand (and none can go stale). The command
reference (:mod:`chaingeo.cli.reference`) reads the same two notes."""

from __future__ import annotations

import argparse
from typing import Any


def shown_default(action: argparse.Action) -> str | None:
    """The default an option (or optional positional) that takes a value falls back to, as
    text; None for flags, required options and options without one."""
    takes_value = action.nargs != 0 and not isinstance(action, argparse._SubParsersAction)
    optional = bool(action.option_strings) or action.nargs in ("?", "*")
    default = action.default
    if not (takes_value and optional) or action.required:
        return None
    if default is None or default is argparse.SUPPRESS or default == []:
        return None
    return str(default)


def is_required(action: argparse.Action) -> bool:
    """An option the command cannot run without (positionals are required by their form)."""
    return bool(action.required and action.option_strings)


class HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """``(default: X)`` and ``(required)`` after an option's help; descriptions as written."""

    def _get_help_string(self, action: argparse.Action) -> str | None:
        text = action.help or ""
        if text == argparse.SUPPRESS:
            return text
        notes = []
        if shown_default(action) is not None and "%(default)" not in text:
            notes.append("(default: %(default)s)")
        if is_required(action):
            notes.append("(required)")
        return " ".join([text, *notes]).strip() or None


class CommandParser(argparse.ArgumentParser):
    """A subcommand's parser (sub-subcommands inherit it): its ``--help`` uses
    :class:`HelpFormatter`."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("formatter_class", HelpFormatter)
        super().__init__(*args, **kwargs)
