"""Agents and their registry: ``make_agent(AgentSpec("random", {...}))``.

Built in: ``oracle`` (plays the level's optimal plan), ``random`` (seeded, uniform over legal
actions), ``greedy`` (one-step lookahead), ``replay`` (actions from a file or a recorded run),
``command`` (an external program speaking JSON lines) and ``openai`` (any OpenAI-compatible
chat-completions server). Add one with :func:`register_agent`.
"""

from __future__ import annotations

from collections.abc import Callable

from chaingeo.core.registry import Registry
from chaingeo.evaluation.agents.base import Agent, AgentSpec
from chaingeo.evaluation.agents.baselines import GreedyAgent, OracleAgent, RandomAgent
from chaingeo.evaluation.agents.command import CommandAgent
from chaingeo.evaluation.agents.openai_chat import OpenAIAgent
from chaingeo.evaluation.agents.replay import ReplayAgent


def _oracle(spec: AgentSpec) -> Agent:
    return OracleAgent()


def _random(spec: AgentSpec) -> Agent:
    return RandomAgent(spec.options)


def _greedy(spec: AgentSpec) -> Agent:
    return GreedyAgent(spec.options)


def _replay(spec: AgentSpec) -> Agent:
    return ReplayAgent(spec.options)


def _command(spec: AgentSpec) -> Agent:
    return CommandAgent(spec.options)


def _openai(spec: AgentSpec) -> Agent:
    return OpenAIAgent(spec.options, spec.secrets)


#: Agent factories by name; a second one under a taken name is refused.
AGENTS: Registry[Callable[[AgentSpec], Agent]] = Registry("agent")
AGENTS.register("command", _command)
AGENTS.register("greedy", _greedy)
AGENTS.register("openai", _openai)
AGENTS.register("oracle", _oracle)
AGENTS.register("random", _random)
AGENTS.register("replay", _replay)

#: The agents ``chain eval`` runs when given none: no network, no files needed.
BASELINES: tuple[str, ...] = ("oracle", "greedy", "random")


def register_agent(name: str, factory: Callable[[AgentSpec], Agent]) -> None:
    """Add an agent; a name already taken raises :class:`DuplicateNameError`."""
    AGENTS.register(name, factory)


def make_agent(spec: AgentSpec) -> Agent:
    return AGENTS.get(spec.name)(spec)
