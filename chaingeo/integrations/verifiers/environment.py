"""The verifiers environment: our state machine plays the user's side of each episode.

Like verifiers' TextArena taskset, :meth:`ChainGeoEnv.run` holds the agent's rollout open turn by
turn: it sends the level's first observation, reads each reply with
:class:`~chaingeo.integrations.game.Game` and answers with the next observation (feedback text,
and the views as image parts when ``images``), and ends the exchange when the level is solved,
the agent says ``finish`` or the step budget is spent (``oneshot``: after the one plan). The
outcome goes on the trace before it closes, where the task's rewards read it.
"""

from __future__ import annotations

import asyncio
from collections.abc import Mapping
from typing import Any, Literal

import verifiers.v1 as vf

from chaingeo.integrations.game import DEFAULT_WEIGHTS, Call
from chaingeo.integrations.verifiers.harness import ChainGeoHarnessConfig
from chaingeo.integrations.verifiers.taskset import INFO_KEY, TASKSET_ID, ChainGeoConfig


class ChainGeoEnvConfig(vf.EnvConfig):  # type: ignore[misc]
    """One seat, ``agent`` (``--env.agent.*``), as in verifiers' single-agent env, in a local
    subprocess box by default: our harness runs no code there, so no sandbox is needed."""

    agent: vf.AgentConfig = vf.AgentConfig(runtime=vf.SubprocessConfig())


class ChainGeoEnv(vf.Env[ChainGeoEnvConfig]):  # type: ignore[misc]
    """An episode is one level played against the agent, our state machine answering."""

    async def run(self, task: Any, agents: Any) -> None:
        # Stepping and drawing run in a worker thread: the interception server of every
        # rollout shares this event loop. The task carries no prompt: the first observation is
        # rendered here, so the environment opens the exchange.
        game = await asyncio.to_thread(task.game)
        async with agents.agent.interaction(task) as interaction:
            messages: list[dict[str, Any]] | None = [await asyncio.to_thread(game.opening)]
            while messages is not None:
                segment = await interaction.turn(messages)
                if segment.terminated:  # a limit or a stop ended the run first
                    break
                calls = calls_of(segment.messages)
                messages = await asyncio.to_thread(game.answer, segment.last_reply, calls)
            interaction.trace.info[INFO_KEY] = game.outcome().to_json()


def calls_of(messages: Any) -> list[Call]:
    """The tool calls of a segment's last assistant message (id, name, argument text)."""
    replies = [m for m in messages if getattr(m, "role", None) == "assistant"]
    made = (replies[-1].tool_calls or []) if replies else []
    return [(str(c.id), str(c.name), str(c.arguments)) for c in made]


def load_environment(
    family: Literal["puzzle", "stacking"] | None = None,
    difficulty: Literal["easy", "mid", "hard"] | None = None,
    split: Literal["test"] = "test",
    images: bool = True,
    protocol: Literal["interactive", "oneshot"] = "interactive",
    reward: Mapping[str, float] | None = None,
    level_dir: str | None = None,
    history_window: int = 5,
    tools: bool = False,
    context: Literal["recent", "full"] = "recent",
    harness: str | None = None,
) -> ChainGeoEnv:
    """A :class:`ChainGeoEnv` over the chosen levels (the shipped suite's ``split``, or the
    files in ``level_dir``). ``reward`` overrides the weights of ``success``, ``efficiency``
    and ``format`` (default :data:`~chaingeo.integrations.game.DEFAULT_WEIGHTS`); ``tools``
    offers the actions as native tool calls too; ``context`` is what our harness shows the
    model (:class:`~chaingeo.integrations.verifiers.harness.ChainGeoHarnessConfig`);
    ``harness`` names another verifiers harness than ours (e.g. ``null``, text only)."""
    weights = dict(reward or {})
    unknown = sorted(set(weights) - set(DEFAULT_WEIGHTS))
    if unknown:
        raise ValueError(f"unknown reward {unknown[0]!r}; use {', '.join(DEFAULT_WEIGHTS)}")
    task = vf.TaskConfig(rewards={k: {"weight": float(w)} for k, w in weights.items()})
    taskset = ChainGeoConfig(
        id=TASKSET_ID,
        family=family,
        difficulty=difficulty,
        split=split,
        images=images,
        protocol=protocol,
        level_dir=level_dir,
        history_window=history_window,
        tools=tools,
        task=task,
    )
    seat = vf.AgentConfig(runtime=vf.SubprocessConfig(), harness=_harness(harness, context))
    return ChainGeoEnv(ChainGeoEnvConfig(taskset=taskset, agent=seat))


def _harness(name: str | None, context: str) -> Any:
    if name in (None, TASKSET_ID):
        return ChainGeoHarnessConfig(id=TASKSET_ID, context=context)
    from verifiers.v1.utils.loaders import harness_config_type

    return harness_config_type(name)(id=name)
