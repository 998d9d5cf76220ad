"""What an agent is to the harness: it reads a turn and replies with text (and usage).

The harness (``chaingeo.evaluation.runner``) owns the game state; an agent only ever sees a
:class:`Turn` (the observation, and, for built-in baselines that declare ``needs_state``, a
clone of the state they may explore freely). An agent returns a :class:`Reply`: the raw text it
produced, the action text it means (``None`` when none could be read: the harness then counts an
unparseable step, it never crashes), and the tokens it used. In the one-shot protocol it returns
its whole plan as ``actions``. An interactive reply may carry several actions too (a model's
native tool calls, in ``calls``): the harness executes them in order, each a step, stopping at the
first one rejected, and hands the next turn that reply (``previous``) with the result of every
call it executed (``results``), so the agent can answer each call.

Agents are built from an :class:`AgentSpec` (name + options) by the registry in
:mod:`chaingeo.evaluation.agents.registry`, so a worker process or a Dask worker can build its
own copy; secrets (API keys) travel in ``AgentSpec.secrets``, which is never serialised into a log.
"""

from __future__ import annotations

from collections.abc import Hashable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any, Protocol

from chaingeo.core.errors import ChainGeoError
from chaingeo.core.level import Level
from chaingeo.evaluation.usage import Usage

# ---------------------------------------------------------------------------------------------
# The environment as the harness sees it (the contract with chaingeo.envs.machines.state /
# observation).
# ---------------------------------------------------------------------------------------------


class StepResultLike(Protocol):
    @property
    def action(self) -> Any: ...
    @property
    def legal(self) -> bool: ...
    @property
    def error(self) -> str | None: ...
    @property
    def feedback(self) -> str: ...
    @property
    def success(self) -> bool: ...
    @property
    def truncated(self) -> bool: ...


class StateLike(Protocol):
    @property
    def level(self) -> Level: ...
    @property
    def steps_used(self) -> int: ...
    @property
    def max_steps(self) -> int: ...
    @property
    def finished(self) -> bool: ...  # ended by ``finish``
    def legal_actions(self) -> Sequence[Any]: ...  # sorted, ``finish`` last while unfinished
    def apply(self, action: Any) -> None: ...
    def clone(self) -> StateLike: ...
    def key(self) -> Hashable: ...
    def is_success(self) -> bool: ...
    def is_truncated(self) -> bool: ...
    def step_text(self, text: str) -> StepResultLike: ...


class ObservationLike(Protocol):
    @property
    def instruction(self) -> str: ...
    @property
    def steps_left(self) -> int: ...
    @property
    def images(self) -> Mapping[str, bytes]: ...
    def to_text(self) -> str: ...


# ---------------------------------------------------------------------------------------------
# Turns, replies, agents
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Turn:
    """One request to an agent."""

    level: Level
    observation: ObservationLike | None
    state: StateLike | None  # a clone, only for agents with ``needs_state``
    index: int  # 0-based turn number within the episode
    sample: int  # which of the K samples of this level
    candidate: int = 0  # which candidate of this turn (verifier-based selection)
    last_feedback: str | None = None
    previous: Reply | None = None  # the reply the last turn committed
    results: tuple[StepResultLike, ...] = ()  # what each of its executed actions did, in order


@dataclass(frozen=True)
class ToolCall:
    """One native tool (function) call of a model, as its server sent it, and the action text
    it was translated to."""

    id: str
    name: str
    arguments: str  # the JSON text of the arguments, as sent
    action: str

    def to_json(self) -> dict[str, str]:
        return {
            "id": self.id,
            "name": self.name,
            "arguments": self.arguments,
            "action": self.action,
        }


@dataclass(frozen=True)
class Reply:
    text: str  # the raw reply, logged as is (no images, no secrets)
    action: str | None  # the action text read from it (the first, with several); None: nothing
    usage: Usage = field(default_factory=Usage)
    #: one-shot: the whole plan, in order; interactive: several actions to take in order (the
    #: first is ``action``), each a step, stopping at the first one rejected
    actions: tuple[str, ...] = ()
    note: str | None = None  # why no action could be read, shown to the agent as feedback
    reasoning: str | None = None  # a model's separate reasoning text, logged when present
    calls: tuple[ToolCall, ...] = ()  # native tool calls, one per action, in order


class AgentError(ChainGeoError, RuntimeError):
    """The agent could not produce a reply at all (server down after every retry, program
    died): the episode is recorded with status ``error`` and can be retried with ``--resume``."""


class AuthenticationError(AgentError):
    """The server refused the credentials (HTTP 401/403) or a remote server was given no key:
    no episode can succeed, so the run stops at the first call instead of recording errors."""


#: Options that say how to reach an agent, not how it behaves.
TRANSPORT = frozenset(
    {
        "base_url",
        "timeout",
        "max_retries",
        "backoff_base",
        "backoff_max",
        "retry_budget",
        "api_key_env",
    }
)


@dataclass(frozen=True)
class AgentSpec:
    """How to build an agent: registry name, options (logged), secrets (never logged)."""

    name: str
    options: Mapping[str, Any] = field(default_factory=dict)
    secrets: Mapping[str, str] = field(default_factory=dict, repr=False)

    def to_json(self) -> dict[str, Any]:
        """What defines the agent's behaviour (a resumed run must match it)."""
        return {
            "name": self.name,
            "options": {k: v for k, v in sorted(self.options.items()) if k not in TRANSPORT},
        }

    def transport(self) -> dict[str, Any]:
        """How it is reached (may change between a run and its resumption)."""
        return {k: v for k, v in sorted(self.options.items()) if k in TRANSPORT}

    @property
    def label(self) -> str:
        """The name a report shows: the model for model agents, else the agent's name."""
        label = self.options.get("label") or self.options.get("model") or self.name
        return str(label)


class Agent:
    """Base class: subclasses override :meth:`act` (interactive) and usually :meth:`plan`."""

    name = "agent"
    needs_state = False  # gets a clone of the state each turn (built-in baselines)
    uses_images = True  # the harness renders views only for agents that look at them
    model: str | None = None  # for pricing

    def start(self, level: Level, seed: int) -> None:
        """A new episode begins (``seed`` is this episode's own)."""

    def act(self, turn: Turn) -> Reply:
        raise NotImplementedError

    def plan(self, turn: Turn) -> Reply:
        """One-shot: the whole plan at once. Default: not supported."""
        raise AgentError(f"agent {self.name!r} cannot plan one-shot")

    def close(self) -> None:
        """Release processes or connections."""

    def notes(self) -> dict[str, Any]:
        """Facts about how this episode was played that belong in its record (e.g. whether a
        model server took native tool calls); empty by default."""
        return {}
