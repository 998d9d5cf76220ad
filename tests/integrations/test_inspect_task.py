"""The inspect_ai task ``chaingeo/chain``: the oracle through every dialect and protocol, the
reducers over epochs, the parameters, and the command line through inspect_ai's entry point."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("inspect_ai")

from inspect_ai import eval as inspect_eval
from inspect_ai.log import EvalLog, read_eval_log
from inspect_ai.model import ContentImage, ContentText, ModelOutput, ModelUsage, get_model

from chaingeo.core.suite import load_level, shipped_levels
from chaingeo.evaluation.agents.baselines import oracle_plan
from chaingeo.evaluation.agents.tools import tool_specs, translate
from chaingeo.integrations.inspect.oracle import call_of
from chaingeo.integrations.inspect.solver import content_of
from chaingeo.integrations.inspect.task import (
    TaskParameterError,
    chain,
    parse_images,
    select_levels,
)

#: One small level of each kind: stacking, a puzzle that only slides, a puzzle that turns.
FEW = ["stacking-2x2x2-easy-s101-000000", "puzzle-easy-01-luban-3-piece"]


def _run(task: Any, tmp: Path, model: Any = "mockllm/model", **kwargs: Any) -> EvalLog:
    [log] = inspect_eval(task, model=model, log_dir=str(tmp), display="none", **kwargs)
    assert log.status == "success", log.error
    return log


def _metrics(log: EvalLog, reducer: str = "mean") -> dict[str, float]:
    assert log.results is not None
    [score] = [s for s in log.results.scores if s.reducer == reducer]
    return {k: v.value for k, v in score.metrics.items()}


@pytest.mark.parametrize("dialect", ["text", "tools"])
def test_the_oracle_scores_one_through_every_protocol(dialect: str, tmp_path: Path) -> None:
    log = _run(
        chain(levels=FEW, agent="oracle", dialect=dialect, protocol="both", images="off"), tmp_path
    )
    assert log.samples is not None and len(log.samples) == 2 * len(FEW)
    m = _metrics(log)
    assert (m["accuracy"], m["stderr"], m["normdist"], m["dist2opt"]) == (1.0, 0.0, 0.0, 0.0)
    for sample in log.samples:
        assert sample.scores is not None
        meta = sample.scores["success"].metadata or {}
        assert meta["steps"] == meta["o_i"] == load_level(meta["level_id"]).optimal_steps


def test_every_shipped_plan_reads_back_from_its_tool_calls() -> None:
    """The oracle's calls translate to its actions' own text on every shipped level (a turn's
    centre is the engine's to find: the rotate tool takes none)."""
    for level_id in shipped_levels():
        level = load_level(level_id)
        offered = tool_specs(level)
        for text in oracle_plan(level):
            name, args = call_of(text, level.family)
            back = translate(name, args, offered)
            assert back.problem is None and back.action == text.split(" about ")[0], text


@pytest.mark.slow
@pytest.mark.parametrize("dialect", ["text", "tools"])
def test_the_oracle_solves_the_whole_shipped_suite(dialect: str, tmp_path: Path) -> None:
    log = _run(chain(agent="oracle", dialect=dialect, protocol="both"), tmp_path)
    assert log.samples is not None and len(log.samples) == 2 * len(shipped_levels())
    m = _metrics(log)
    assert (m["accuracy"], m["normdist"]) == (1.0, 0.0)


def _scripted(replies: list[str]) -> Any:
    usage = ModelUsage(input_tokens=10, output_tokens=5, total_tokens=15)
    outs = [
        ModelOutput.from_content("mockllm", r).model_copy(update={"usage": usage}) for r in replies
    ]
    return get_model("mockllm/model", custom_outputs=outs, memoize=False)


def test_epochs_give_pass_at_k_and_pass_hat_k(tmp_path: Path) -> None:
    """Epoch 1 solves the level, epoch 2 gives up: mean 0.5, Pass@2 1, Pass^2 0."""
    level = load_level(FEW[0])
    plan = [f"<action>{a}</action>" for a in oracle_plan(level)]
    model = _scripted([*plan, "<action>finish</action>"])
    log = _run(chain(levels=FEW[0], images="off"), tmp_path, model, epochs=2, max_samples=1)
    assert log.eval.config.epochs == 2
    assert _metrics(log, "mean")["accuracy"] == 0.5
    assert _metrics(log, "pass_at_k")["accuracy"] == 1.0
    assert _metrics(log, "pass_hat_k")["accuracy"] == 0.0
    # NormDist over the solved episode only, after any reducer
    assert _metrics(log, "pass_hat_k")["normdist"] == 0.0
    assert log.stats.model_usage["mockllm/model"].input_tokens == 10 * (len(plan) + 1)


def test_the_first_observation_is_the_input_with_its_pictures(tmp_path: Path) -> None:
    task = chain(levels=FEW[0], images="front,top")
    [sample] = list(task.dataset)
    assert not isinstance(sample.input, str)
    system, user = sample.input
    assert "<action>" in str(system.content)
    assert isinstance(user.content, list)
    images = [p for p in user.content if isinstance(p, ContentImage)]
    labels = [
        p.text for p in user.content if isinstance(p, ContentText) and p.text.startswith("View")
    ]
    assert labels == ["View: front", "View: top"] and len(images) == 2
    assert all(p.image.startswith("data:image/png;base64,iVBOR") for p in images)
    [off] = list(chain(levels=FEW[0], images="off").dataset)
    assert not any(isinstance(p, ContentImage) for p in off.input[1].content)  # type: ignore[union-attr]


def test_content_of_keeps_only_the_named_views() -> None:
    parts: list[dict[str, Any]] = [
        {"type": "text", "text": "obs"},
        {"type": "text", "text": "View: front"},
        {"type": "image_url", "image_url": {"url": "data:image/png;base64,AA"}},
        {"type": "text", "text": "View: iso"},
        {"type": "image_url", "image_url": {"url": "data:image/png;base64,BB"}},
    ]
    kept = content_of(parts, ["iso"])
    assert [type(p).__name__ for p in kept] == ["ContentText", "ContentText", "ContentImage"]
    assert len(content_of(parts, None)) == 5


def test_parameters_and_their_errors(tmp_path: Path) -> None:
    assert [lv.family for lv in select_levels("stacking", None, 3)] == ["stacking"] * 3
    assert {lv.difficulty for lv in select_levels("puzzle", "hard", None)} == {"hard"}
    assert [lv.id for lv in select_levels("all", None, ",".join(FEW))] == sorted(FEW)
    assert parse_images("off") == (False, None) and parse_images(True) == (True, None)
    for bad in (
        {"family": "boxes"},
        {"tier": "extreme"},
        {"levels": 0},
        {"agent": "human"},
        {"dialect": "json"},
        {"protocol": "closed"},
    ):
        with pytest.raises(TaskParameterError):
            chain(**bad)
    task = chain(levels=FEW[0], config="chain-paper", images="off")
    assert {s.metadata["protocol"] for s in task.dataset if s.metadata} == {
        "interactive",
        "oneshot",
    }


def test_the_paper_config_reaches_the_model(tmp_path: Path) -> None:
    seen: list[Any] = []

    def answer(messages: Any, tools: Any, choice: Any, config: Any) -> ModelOutput:
        seen.append(config)
        out = ModelOutput.from_content("mockllm", "<action>finish</action>")
        return out.model_copy(update={"usage": ModelUsage(input_tokens=1, output_tokens=1)})

    model = get_model("mockllm/model", custom_outputs=answer, memoize=False)
    _run(chain(levels=FEW[0], config="chain-paper", images="off"), tmp_path, model)
    assert seen and {(c.temperature, c.top_p) for c in seen} == {(0.6, 0.95)}


def test_inspect_eval_finds_the_task_by_its_entry_point(tmp_path: Path) -> None:
    """``inspect eval chaingeo/chain``: the installed entry point, the command line, the log."""
    cmd = [
        *(sys.executable, "-m", "inspect_ai", "eval", "chaingeo/chain"),
        *("-T", "family=stacking", "-T", "levels=3", "-T", "agent=oracle", "-T", "images=off"),
        *("--model", "mockllm/model", "--epochs", "2", "--log-dir", str(tmp_path)),
        *("--display", "none"),
    ]
    env = {**os.environ, "INSPECT_LOG_FORMAT": "eval"}
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=300, env=env, cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-2000:]
    [path] = list(tmp_path.glob("*.eval"))
    log = read_eval_log(str(path))
    assert log.samples is not None and len(log.samples) == 6  # 3 levels x 2 epochs
    assert {s.reducer for s in log.results.scores} == {"mean", "pass_at_k", "pass_hat_k"}  # type: ignore[union-attr]
    assert all({"accuracy", "stderr"} <= set(s.metrics) for s in log.results.scores)  # type: ignore[union-attr]


def _offline(cache: Path) -> dict[str, str]:
    """An environment where tiktoken's cache is empty and its download fails at once."""
    env = {k: v for k, v in os.environ.items() if k not in ("DATA_GYM_CACHE_DIR",)}
    closed = "http://127.0.0.1:9"  # the discard port: nothing listens there
    return {**env, "TIKTOKEN_CACHE_DIR": str(cache), "HTTPS_PROXY": closed, "https_proxy": closed}


def test_the_readme_command_runs_offline_with_an_empty_tiktoken_cache(tmp_path: Path) -> None:
    """The issue's command, model replies without usage (so inspect_ai counts tokens with
    tiktoken's o200k_base), on a machine that cannot download it: every sample is scored."""
    cache = tmp_path / "tiktoken"
    cmd = [
        *(sys.executable, "-m", "inspect_ai", "eval", "chaingeo/chain"),
        *("-T", "family=stacking", "-T", "levels=3", "-T", "max_steps=3"),
        *("--model", "mockllm/model", "--log-dir", str(tmp_path / "logs"), "--display", "none"),
    ]
    env = {**_offline(cache), "INSPECT_LOG_FORMAT": "eval"}
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=300, env=env, cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-2000:]
    [path] = list((tmp_path / "logs").glob("*.eval"))
    log = read_eval_log(str(path))
    assert log.status == "success", log.error
    assert log.samples is not None and len(log.samples) == 3
    assert all(s.scores and s.scores["success"].value == 0 for s in log.samples)
    assert all(s.model_usage for s in log.samples), "inspect_ai counted the tokens"
    assert all({"accuracy", "stderr"} <= set(s.metrics) for s in log.results.scores)  # type: ignore[union-attr]
