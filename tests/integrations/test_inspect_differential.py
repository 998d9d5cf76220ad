"""The differential check: one scripted model through ``chain eval`` and through the inspect_ai
task gives the same success, steps and NormDist on every level.

The script (seeded) wastes turns with unreadable replies and rejected actions and sometimes
gives up half way, so the levels' outcomes differ. It is played three ways: ``chain eval``'s
OpenAI agent against the project's fake server on 127.0.0.1, inspect_ai's ``mockllm`` with the
same replies as scripted outputs, and inspect_ai's OpenAI-compatible provider (``openai-api``)
against the fake server.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

pytest.importorskip("inspect_ai")
pytest.importorskip("openai")

from inspect_ai import eval as inspect_eval
from inspect_ai.log import EvalLog
from inspect_ai.model import ModelOutput, ModelUsage, get_model

from chaingeo.core.level import Level
from chaingeo.core.suite import load_level
from chaingeo.evaluation.agents.baselines import oracle_plan
from chaingeo.evaluation.episode import Outcome, ProtocolConfig
from chaingeo.evaluation.logs import RunLog
from chaingeo.evaluation.runner import RunConfig, evaluate
from chaingeo.integrations.inspect.task import chain
from tests.support.fake_openai import Script, fake_openai, reply
from tests.support.harness import openai_spec

LEVELS = (
    "stacking-2x2x2-easy-s101-000000",
    "stacking-2x2x3-easy-s103-000000",
    "puzzle-easy-01-luban-3-piece",
)
SEED = 33


def _script(level: Level, rng: np.random.Generator) -> list[str]:
    """The oracle's plan with wasted turns in between, and (sometimes) giving up half way."""
    out: list[str] = []
    for action in oracle_plan(level):
        roll = rng.random()
        if roll < 0.25:
            out.append("Let me look at the pieces first.")  # no action: unreadable
        elif roll < 0.5:
            out.append("<action>pickup nobody</action>")  # read, rejected
        out.append(f"<action>{action}</action>")
    if rng.random() < 0.4:
        out = [*out[: len(out) // 2], "<action>finish</action>"]
    return out


def _scripts() -> dict[str, list[str]]:
    rng = np.random.default_rng(np.random.SeedSequence([SEED]))
    return {i: _script(load_level(i), rng) for i in LEVELS}


def _figures(o: Outcome) -> tuple[bool, int, float | None]:
    norm = (o.steps - o.optimal_steps) / max(1, o.optimal_steps) if o.success else None
    return o.success, o.steps, norm


Figures = tuple[bool, int, float | None]


def _chain_eval(scripts: dict[str, list[str]], tmp: Path) -> dict[str, Figures]:
    """``chain eval``'s loop (one process, levels in order) against the fake server."""
    script = Script([reply(r) for replies in scripts.values() for r in replies])
    run = tmp / "chain"
    with fake_openai(script) as url:
        evaluate(
            [load_level(i) for i in scripts],
            openai_spec(url, images=False),
            run,
            ProtocolConfig(),
            RunConfig(progress=False),
        )
    assert script.problems == []
    return {r["level_id"]: _figures(Outcome.from_record(r)) for r in RunLog(run).records()}


def _inspect_figures(log: EvalLog) -> dict[str, Figures]:
    assert log.status == "success" and log.samples is not None
    out = {}
    for sample in log.samples:
        assert sample.scores is not None
        meta = sample.scores["success"].metadata or {}
        out[str(sample.id)] = (bool(meta["solved"]), int(meta["steps"]), meta["normdist"])
    return out


def _mock(scripts: dict[str, list[str]]) -> Any:
    usage = ModelUsage(input_tokens=100, output_tokens=20, total_tokens=120)
    outputs = [
        ModelOutput.from_content("mockllm", r).model_copy(update={"usage": usage})
        for replies in scripts.values()
        for r in replies
    ]
    return get_model("mockllm/model", custom_outputs=outputs, memoize=False)


def _inspect(scripts: dict[str, list[str]], model: Any, tmp: Path, **kwargs: Any) -> EvalLog:
    """The task over the scripted levels, one sample at a time in id order (the script's)."""
    [log] = inspect_eval(
        chain(levels=list(scripts), images="off"),
        model=model,
        log_dir=str(tmp / "logs"),
        display="none",
        max_samples=1,
        **kwargs,
    )
    return log


def test_chain_eval_and_inspect_agree_level_by_level(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("LOCAL_API_KEY", "sk-local-fake")  # openai-api/local/...: its key
    scripts = dict(sorted(_scripts().items()))  # the task's sample order
    want = _chain_eval(scripts, tmp_path)
    assert sorted(want) == sorted(LEVELS)
    assert _inspect_figures(_inspect(scripts, _mock(scripts), tmp_path)) == want
    script = Script([reply(r) for replies in scripts.values() for r in replies])
    with fake_openai(script) as url:
        log = _inspect(
            scripts,
            "openai-api/local/fake-model",
            tmp_path,
            model_base_url=url,
            temperature=0.6,
            top_p=0.95,
        )
    assert script.problems == []
    assert _inspect_figures(log) == want
    # inspect_ai counted the server's tokens: 100 in, 20 out per request
    assert log.stats.model_usage["openai-api/local/fake-model"].input_tokens == 100 * len(
        script.requests
    )
    # telling data: levels solved with wasted steps, and a level given up
    assert {s for s, _, _ in want.values()} == {True, False}
    assert any(n is not None and n > 0 for _, _, n in want.values())
