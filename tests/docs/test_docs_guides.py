"""Every runnable Python block of the docs runs (a page whose example breaks is a defect), and
every `chain` command the pages show is a real subcommand.

The convention (docs/index.md): a block fenced ```python runs; one fenced ```py only
illustrates (it needs a model server, a GPU or minutes of CPU). A line `--8<-- "PATH"` is
pymdownx.snippets' include, as mkdocs renders it: replaced by the file, relative to the root."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

from chaingeo.cli.main import build_parser
from tests.support.paths import ROOT

PAGES = sorted((ROOT / "docs").rglob("*.md"))
SNIPPET = re.compile(r'^--8<-- "([^"]+)"$', flags=re.M)


def _fenced(text: str) -> list[tuple[str, str]]:
    """(language, body) of each fenced block, fences paired in order (a closing fence never
    opens a block)."""
    found: list[tuple[str, str]] = []
    lang: str | None = None
    body: list[str] = []
    for line in text.splitlines():
        if lang is None and line.startswith("```"):
            lang, body = line[3:].strip(), []
        elif lang is not None and line.strip() == "```":
            found.append((lang, "\n".join(body)))
            lang = None
        elif lang is not None:
            body.append(line)
    return found


def _blocks(path: Path, *langs: str) -> list[str]:
    return [body for lang, body in _fenced(path.read_text(encoding="utf-8")) if lang in langs]


def _expand(block: str) -> str:
    return SNIPPET.sub(lambda m: (ROOT / m.group(1)).read_text(encoding="utf-8"), block)


def _page_id(p: Path) -> str:
    return p.relative_to(ROOT / "docs").with_suffix("").as_posix()


RUNNABLE = [p for p in PAGES if _blocks(p, "python")]


def test_guides_and_getting_started_have_runnable_examples() -> None:
    names = {_page_id(p) for p in RUNNABLE}
    assert {"guides/training", "getting-started"} <= names


def test_fences_pair_in_order() -> None:
    text = "```python\nx = 1\n```\nchain prose\n```bash\nchain play --help\n```\n"
    assert _fenced(text) == [("python", "x = 1"), ("bash", "chain play --help")]


def test_snippets_expand() -> None:
    block = '--8<-- "docs/examples/quickstart.py"'
    assert _expand(block) == (ROOT / "docs" / "examples" / "quickstart.py").read_text()


@pytest.mark.parametrize("page", RUNNABLE, ids=_page_id)
def test_python_blocks_run(page: Path) -> None:
    for block in _blocks(page, "python"):
        exec(compile(_expand(block), str(page), "exec"), {"__name__": "docs"})  # our own docs


@pytest.mark.parametrize("page", PAGES, ids=_page_id)
def test_chain_commands_exist(page: Path) -> None:
    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    known = set(sub.choices)
    for block in _blocks(page, "bash", ""):
        for line in block.splitlines():
            words = line.split()
            if "chain" in words[:3] and not line.startswith("#"):
                command = words[words.index("chain") + 1]
                assert command in known or command.startswith("-"), line
