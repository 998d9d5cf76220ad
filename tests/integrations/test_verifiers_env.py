"""The verifiers environment end to end, through verifiers' own evaluation (its ``vf-eval``
runner, in this process) against the local fake OpenAI server: the optimal plan scores 1,
nonsense scores 0, under both protocols."""

from __future__ import annotations

import asyncio
import importlib.metadata
import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pytest

from chaingeo.core.level import load_level
from chaingeo.evaluation.agents.baselines import oracle_plan
from tests.support.fake_openai import Script, calls, fake_openai, reply
from tests.support.plans import place_calls

if importlib.util.find_spec("verifiers") is None:
    pytest.skip(
        "verifiers is not installed (pip install 'chaingeo[train]')", allow_module_level=True
    )

if TYPE_CHECKING:
    from chaingeo.integrations.verifiers import TASKSET_ID, load_environment
else:
    # verifiers is imported when a test first needs it, not at collection, where every xdist
    # worker paid ~3 s for it; the id is checked against ours in test_the_taskset_id_...
    TASKSET_ID = "chaingeo-env"

    def load_environment(*args, **kwargs):
        from chaingeo.integrations.verifiers import load_environment as load

        return load(*args, **kwargs)


KEY_VAR = "CHAINGEO_TEST_KEY"
EASY: dict[str, Any] = {"family": "stacking", "difficulty": "easy"}


def needs_plugin() -> None:
    """Skip unless verifiers' plugin distribution is installed: a process that starts without
    chaingeo (verifiers' command line) finds the taskset id ``chaingeo-env`` only through it
    (the README's install line installs it)."""
    try:
        importlib.metadata.distribution("chaingeo-env")
    except importlib.metadata.PackageNotFoundError:
        pytest.skip(
            "the plugin chaingeo-env is not installed "
            "(python -m chaingeo.integrations.verifiers install)"
        )


def plans(limit: int, **taskset: Any) -> list[list[str]]:
    """The optimal plans of the first ``limit`` tasks, in the order the eval runs them."""
    env = load_environment(**taskset)
    return [oracle_plan(load_level(t.data.level_path)) for t in env.taskset.take(limit)]


def evaluate(
    script: Script,
    tmp_path: Path,
    limit: int,
    monkeypatch: pytest.MonkeyPatch,
    agent: dict[str, Any] | None = None,
    **taskset: Any,
) -> list[Any]:
    """verifiers' eval runner over the first ``limit`` tasks, one episode at a time (the
    script is one sequence of answers), ``agent`` configuring the seat; the traces, in task
    order."""
    from verifiers.v1.cli.eval.runner import run_eval
    from verifiers.v1.configs.cli.eval import EvalConfig

    import chaingeo.integrations.verifiers  # noqa: F401  (the id resolves in this process)

    monkeypatch.setenv(KEY_VAR, "sk-test")
    env: dict[str, Any] = {"taskset": {"id": TASKSET_ID, **taskset}}
    if agent is not None:
        env["agent"] = agent
    with fake_openai(script) as url:
        config = EvalConfig.model_validate(
            {
                "env": env,
                "model": "fake-model",
                "client": {"base_url": url, "api_key_var": KEY_VAR},
                "select": {"limit": limit},
                "max_concurrent": 1,
                "push": False,
                "rich": None,
                "output_dir": str(tmp_path),
            }
        )
        episodes = asyncio.run(run_eval(config))
    assert script.problems == []
    traces = [t for e in sorted(episodes, key=lambda e: e.task.data.idx) for t in e.traces]
    assert all(t.ok for t in traces), [t.errors for t in traces]
    return traces


@pytest.mark.parametrize("protocol", ["interactive", "oneshot"])
def test_the_optimal_plan_scores_one(
    protocol: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    todo = plans(2, **EASY)
    if protocol == "interactive":
        entries = [reply(f"Next: <action>{a}</action>") for plan in todo for a in plan]
    else:
        entries = [reply("<plan>\n" + "\n".join(plan) + "\n</plan>") for plan in todo]
    script = Script(entries=list(entries), chat_history=True)
    traces = evaluate(script, tmp_path, 2, monkeypatch, protocol=protocol, **EASY)
    assert [t.reward for t in traces] == [pytest.approx(1.0)] * 2
    assert [t.metrics["steps"] for t in traces] == [len(p) for p in todo]
    assert len(script.requests) == len(entries)  # one model call per action (per plan)
    first = script.requests[0]["body"]["messages"]
    assert ("<action>" if protocol == "interactive" else "<plan>") in first[0]["content"]
    images = [p for p in first[-1]["content"] if p["type"] == "image_url"]
    assert len(images) == (5 if protocol == "interactive" else 2)  # 4 views + tray; iso + tray


@pytest.mark.parametrize("protocol", ["interactive", "oneshot"])
def test_nonsense_scores_zero(
    protocol: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    [task] = load_environment("stacking", "easy").taskset.take(1)
    budget = task.data.max_steps
    entries = [reply("The answer is 42, obviously.")] * budget
    script = Script(entries=list(entries), chat_history=True)
    [trace] = evaluate(script, tmp_path, 1, monkeypatch, protocol=protocol, images=False, **EASY)
    assert trace.reward == 0.0
    outcome = trace.info["chaingeo"]
    assert outcome["success"] is False and outcome["readable"] == 0
    assert len(script.requests) == (budget if protocol == "interactive" else 1)
    # the model sees the latest observation only (its text keeps the last turns), no pictures
    assert all(len(r["body"]["messages"]) == 2 for r in script.requests)
    last = script.requests[-1]["body"]["messages"][-1]["content"]
    assert [p["type"] for p in last] == ["text"]
    if protocol == "interactive":
        assert "Recent turns:" in last[0]["text"] and "Steps left: 1" in last[0]["text"]


def test_the_taskset_id_names_our_classes() -> None:
    """verifiers' own loaders, given the id, find exactly our taskset, environment and harness
    (through the plugin module, which is nothing but a re-export, or its in-process alias)."""
    from verifiers.v1.utils import loaders

    import chaingeo.integrations.verifiers as ours

    assert ours.TASKSET_ID == TASKSET_ID
    assert loaders.taskset_class(TASKSET_ID) is ours.ChainGeoTaskset
    assert loaders.environment_class(TASKSET_ID) is ours.ChainGeoEnv
    assert loaders.harness_class(TASKSET_ID) is ours.ChainGeoHarness


def test_the_whole_conversation_on_request(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """``context full``: each request resends every turn, pictures included."""
    script = Script(entries=[reply("Hmm.")] * 3 + [reply("<action>finish</action>")])
    script.chat_history = True
    agent = {"harness": {"id": TASKSET_ID, "context": "full"}}
    evaluate(script, tmp_path, 1, monkeypatch, agent=agent, **EASY)
    sizes = [len(r["body"]["messages"]) for r in script.requests]
    assert sizes == [2, 4, 6, 8]
    pictures = [
        sum(isinstance(m["content"], list) and "image_url" in str(m["content"]) for m in body)
        for body in (r["body"]["messages"] for r in script.requests)
    ]
    assert pictures == [1, 2, 3, 4]


def test_wasted_turns_and_reward_weights(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Two ``state`` turns cost efficiency (1 - 2/o) but not success; weights are the config's."""
    [plan] = plans(1, **EASY)
    entries = [reply("<action>state</action>")] * 2 + [reply(f"<action>{a}</action>") for a in plan]
    weights = {"success": 1.0, "efficiency": 2.0, "format": 0.0}
    rewards = {k: {"weight": w} for k, w in weights.items()}
    script = Script(entries=entries, chat_history=True)
    [trace] = evaluate(
        script, tmp_path, 1, monkeypatch, images=False, task={"rewards": rewards}, **EASY
    )
    efficiency = max(0.0, 1 - 2 / len(plan))
    assert trace.rewards["efficiency"].score == pytest.approx(efficiency)
    assert trace.reward == pytest.approx(1.0 + 2.0 * efficiency)


@pytest.mark.parametrize("protocol", ["interactive", "oneshot"])
def test_the_optimal_plan_as_tool_calls(
    protocol: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """With ``tools`` the harness offers our action functions; interactive: a ``state`` call
    first (a wasted step, its result sent back), then the plan's calls in one reply."""
    [task] = load_environment("stacking", "easy", tools=True).taskset.take(1)
    made = place_calls(load_level(task.data.level_path))
    if protocol == "interactive":
        entries = [calls(("state", {})), calls(*made, text="The rest at once.")]
    else:
        entries = [calls(*made)]
    script = Script(entries=list(entries), chat_history=True)
    [trace] = evaluate(
        script, tmp_path, 1, monkeypatch, protocol=protocol, tools=True, images=False, **EASY
    )
    offered = [t["function"]["name"] for t in script.requests[0]["body"]["tools"]]
    assert offered == (["place", "pickup", "state", "finish"] if protocol == "interactive" else
                       ["place", "pickup", "finish"])  # fmt: skip
    wasted = 1 if protocol == "interactive" else 0
    assert trace.metrics["steps"] == len(made) + wasted
    assert trace.reward == pytest.approx(0.5 + 0.4 * (1 - wasted / len(made)) + 0.1)
    assert len(script.requests) == len(entries)
    if protocol == "interactive":  # the call's result came back before the next observation
        roles = [m["role"] for m in script.requests[1]["body"]["messages"]]
        assert roles == ["system", "user", "assistant", "tool", "user"]


def test_load_environment_checks_its_arguments() -> None:
    env = load_environment(family="stacking", difficulty="mid", protocol="oneshot", images=False)
    tasks = list(env.taskset)
    assert tasks and all(t.data.difficulty == "mid" and t.data.protocol == "oneshot" for t in tasks)
    assert [t.data.id for t in tasks] == sorted(t.data.id for t in tasks)
    weighted = load_environment(reward={"format": 0.0})
    assert weighted.taskset.config.task.rewards["format"].weight == 0.0
    with pytest.raises(ValueError, match="unknown reward 'speed'"):
        load_environment(reward={"speed": 1.0})
    with pytest.raises(ValueError):
        load_environment(protocol="telepathy")  # type: ignore[arg-type]
    with pytest.raises(ValueError):
        load_environment(history_window=-1)


def test_a_folder_of_levels_and_an_empty_selection(tmp_path: Path) -> None:
    from chaingeo.core.level import LevelError, save_level

    [task] = load_environment("stacking", "hard").taskset.take(1)
    save_level(load_level(task.data.level_path), tmp_path / "mine" / "one.json")
    [mine] = load_environment(level_dir=str(tmp_path / "mine")).taskset
    assert (mine.data.id, mine.data.difficulty) == (task.data.id, "hard")
    with pytest.raises(LevelError, match="no level matches family any, difficulty easy"):
        list(load_environment(level_dir=str(tmp_path / "mine"), difficulty="easy").taskset)


@pytest.mark.slow
def test_the_vf_eval_command(tmp_path: Path) -> None:
    """``vf-eval chaingeo-env ...``: verifiers' command line finds the taskset by its id."""
    needs_plugin()
    script = Script(entries=[reply("<action>finish</action>")], chat_history=True)
    vf_eval = Path(sys.executable).with_name("vf-eval")
    with fake_openai(script) as url:
        done = subprocess.run(
            [str(vf_eval), TASKSET_ID, "--env.taskset.family", "stacking", "-n", "1",
             "--env.taskset.images", "false", "--no-push", "--no-rich", "-m", "fake-model",
             "--client.base-url", url, "--client.api-key-var", KEY_VAR,
             "-o", str(tmp_path), "--run.name", "run"],
            capture_output=True, text=True, timeout=300, env={**os.environ, KEY_VAR: "k"},
        )  # fmt: skip
    assert done.returncode == 0, done.stderr[-2000:]
    [episode] = [json.loads(line) for line in (tmp_path / "run" / "traces.jsonl").open()]
    [trace] = episode["traces"]
    assert trace["rewards"]["format"]["score"] == 1.0  # 'finish' is a readable action
    assert trace["info"]["chaingeo"]["finished"] is True
    assert sum(r["score"] * r["weight"] for r in trace["rewards"].values()) == pytest.approx(0.1)


def test_without_the_plugin_the_id_resolves_in_process(monkeypatch: pytest.MonkeyPatch) -> None:
    """No plugin distribution: the alias module stands in (a proper module, spec and all), and
    verifiers' own loaders find our classes through it."""
    from verifiers.v1.utils import loaders

    import chaingeo.integrations.verifiers as ours
    from chaingeo.integrations.verifiers import plugin_module

    real = importlib.util.find_spec

    def no_plugin(name: str, *args: Any) -> Any:
        return None if name == plugin_module.PLUGIN_MODULE else real(name, *args)

    monkeypatch.delitem(sys.modules, plugin_module.PLUGIN_MODULE, raising=False)
    monkeypatch.setattr(importlib.util, "find_spec", no_plugin)
    plugin_module.install_alias()
    monkeypatch.setattr(importlib.util, "find_spec", real)
    alias = sys.modules[plugin_module.PLUGIN_MODULE]
    assert alias.__spec__ is not None and real(plugin_module.PLUGIN_MODULE) is not None
    assert loaders.taskset_class(TASKSET_ID) is ours.ChainGeoTaskset
    assert loaders.harness_class(TASKSET_ID) is ours.ChainGeoHarness
