"""The one error type of the command line: what a subcommand raises for a user-facing failure."""

from __future__ import annotations


class CommandError(Exception):
    """A user-facing failure: printed as one line, exit status 2."""
