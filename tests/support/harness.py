"""What the harness tests share: small stacking levels played through the fake environment, a
level folder for ``chain eval``, and an OpenAI-compatible agent pointed at the fake server."""

from __future__ import annotations

import json
from pathlib import Path

from chaingeo.cli.main import main
from chaingeo.core.geometry import Shape
from chaingeo.core.level import Level, save_level, stacking_level
from chaingeo.evaluation.agents.base import AgentSpec
from chaingeo.evaluation.episode import ProtocolConfig
from chaingeo.evaluation.usage import PriceTable

#: The protocol over the fake environment (:mod:`tests.support.fake_env`).
FAKE = ProtocolConfig(env="tests.support.fake_env")
#: The key the fake server expects; no log or error may show it.
KEY = "sk-fake-key-do-not-log-0123456789"
#: A well-formed chat request body.
GOOD_BODY = {
    "model": "m",
    "messages": [
        {"role": "system", "content": "s"},
        {"role": "user", "content": [{"type": "text", "text": "u"}]},
    ],
    "temperature": 0.6,
    "top_p": 0.95,
}


def fake_levels(n: int, pieces: int = 4) -> list[Level]:
    """``n`` one-row stacking levels of ``pieces`` unit cubes, difficulties in turn."""
    cells = [Shape([(i, 0, 0)]) for i in range(pieces)]
    return [
        stacking_level(f"L{i:02d}", ("easy", "mid", "hard")[i % 3], (pieces, 1, 1), cells)
        for i in range(n)
    ]


def suite_folder(tmp_path: Path, n: int = 3) -> Path:
    """A level folder of :func:`fake_levels`, as ``chain eval --levels`` reads it."""
    folder = tmp_path / "levels"
    for level in fake_levels(n):
        save_level(level, folder / f"{level.id}.json")
    return folder


def chain_eval(suite: Path, out: Path, *extra: str) -> int:
    """``chain eval`` over ``suite`` into ``out``; its exit status."""
    return main(["eval", "--levels", str(suite), "--out", str(out), "--no-progress", *extra])


def openai_args(url: str) -> list[str]:
    """``chain eval`` options for the OpenAI-compatible agent at ``url`` on the fake env."""
    return ["--agent", "openai", "--model", "fake", "--base-url", url, "--env", FAKE.env]


def openai_spec(url: str, **opts: object) -> AgentSpec:
    """The OpenAI-compatible agent at ``url``, backing off quickly, with :data:`KEY`."""
    options = {"model": "fake-model", "base_url": url, "backoff_base": 0.01, "timeout": 5.0}
    options.update(opts)
    return AgentSpec("openai", options, {"api_key": KEY})


def fake_prices(tmp_path: Path) -> PriceTable:
    """A price table for ``fake-model`` (1 and 2 per million tokens)."""
    f = tmp_path / "prices.json"
    f.write_text(json.dumps({"models": {"fake-model": {"input": 1.0, "output": 2.0}}}))
    return PriceTable.load(f)
