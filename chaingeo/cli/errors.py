"""The one error type of the command line: what a subcommand raises for a user-facing failure."""

from __future__ import annotations

from chaingeo.core.errors import ChainGeoError


class CommandError(ChainGeoError):
    """A user-facing failure: printed as one line, exit status 2."""
