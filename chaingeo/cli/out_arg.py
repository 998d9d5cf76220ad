"""``--out``, the one way every ``chain`` command is told where to write: a FILE where the
command writes one file, a DIR (created when missing) where it writes several. The metavar and
the first words of the help say which, the same way in every command."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any, Literal

#: What ``--out`` names, as its metavar and the start of its help.
KINDS: dict[str, tuple[str, str]] = {
    "file": ("FILE", "file:"),
    "folder": ("DIR", "folder (created when missing):"),
}


def add_out(
    p: argparse.ArgumentParser, kind: Literal["file", "folder"], what: str, **kwargs: Any
) -> argparse.Action:
    """``--out FILE`` or ``--out DIR``; ``kwargs`` go to ``add_argument`` (default, required)."""
    metavar, lead = KINDS[kind]
    kwargs.setdefault("type", Path)
    return p.add_argument("--out", metavar=metavar, help=f"{lead} {what}", **kwargs)


def out_folder(path: Path) -> Path:
    """``path`` as a folder that exists (a file there is a one-line error, not a traceback)."""
    from chaingeo.cli.errors import CommandError

    if path.exists() and not path.is_dir():
        raise CommandError(f"--out: {path} is a file; a folder is needed here")
    path.mkdir(parents=True, exist_ok=True)
    return path
