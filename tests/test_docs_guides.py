"""Every Python block of the guides in docs/guides runs (a guide whose example breaks is a
defect), and every `chain` command they show is a real subcommand."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

from chaingeo.cli.main import build_parser

GUIDES = sorted((Path(__file__).resolve().parent.parent / "docs" / "guides").glob("*.md"))


def _blocks(path: Path, lang: str) -> list[str]:
    return re.findall(rf"```{lang}\n(.*?)\n```", path.read_text(encoding="utf-8"), flags=re.S)


@pytest.mark.parametrize("guide", GUIDES, ids=lambda p: p.stem)
def test_python_blocks_run(guide: Path) -> None:
    for block in _blocks(guide, "python"):
        exec(compile(block, str(guide), "exec"), {"__name__": "guide"})  # our own docs


@pytest.mark.parametrize("guide", GUIDES, ids=lambda p: p.stem)
def test_chain_commands_exist(guide: Path) -> None:
    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    known = set(sub.choices)
    for block in _blocks(guide, "bash"):
        for line in block.splitlines():
            if line.startswith("chain "):
                assert line.split()[1] in known, line
