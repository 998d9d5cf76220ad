"""The wire types of ``chain serve``: OpenEnv's Action, Observation and State, ours.

OpenEnv validates every action against :class:`ChainAction` before the environment sees it
(pydantic, ``extra="forbid"``), so a malformed request is refused with OpenEnv's own validation
error and reaches nothing. What an action *says* is the agent's business: an unreadable or
illegal action is played like any agent's, costing its step (the rules of the benchmark).
"""

from __future__ import annotations

import json
from typing import Any

from openenv.core.env_server.types import Action, Observation, State
from pydantic import Field, field_validator, model_validator
from pydantic_core import PydanticCustomError

from chaingeo.core import limits

#: Characters of a tool name.
MAX_TOOL_NAME_CHARS = 64


def _invalid(message: str) -> PydanticCustomError:
    """A validation error whose details are plain JSON (a ``ValueError`` would put the exception
    object in them, which OpenEnv cannot send back: it would end the session instead)."""
    return PydanticCustomError("chain_action", message)


class ChainAction(Action):  # type: ignore[misc]
    """One agent turn: ``text`` (read in the session's dialect) or one tool call."""

    text: str | None = Field(default=None, max_length=limits.MAX_REPLY_CHARS)
    tool: str | None = Field(default=None, max_length=MAX_TOOL_NAME_CHARS)
    arguments: dict[str, Any] | None = None

    @field_validator("arguments")
    @classmethod
    def _small_arguments(cls, value: dict[str, Any] | None) -> dict[str, Any] | None:
        if value is not None and len(json.dumps(value)) > limits.MAX_TOOL_ARGUMENT_CHARS:
            raise _invalid(f"arguments longer than {limits.MAX_TOOL_ARGUMENT_CHARS} characters")
        return value

    @model_validator(mode="after")
    def _one_kind(self) -> ChainAction:
        if (self.text is None) == (self.tool is None):
            raise _invalid('an action is {"text": ...} or {"tool": NAME, "arguments": {...}}')
        if self.text is not None and self.arguments is not None:
            raise _invalid("arguments belong to a tool call")
        return self


class ChainObservation(Observation):  # type: ignore[misc]
    """What the agent sees after a reset or a step (``done`` and ``reward`` are OpenEnv's)."""

    level_id: str = ""
    family: str = ""
    instruction: str = ""
    #: The whole observation as the harness's prompt text (instruction, pieces, recent turns,
    #: steps left, the views' names, and why the last reply could not be read, if it could not).
    text: str = ""
    #: What the last action did (the machine's feedback), None after a reset.
    feedback: str | None = None
    #: The last step: its action text, whether it was legal, and the error kind if not.
    last: dict[str, Any] | None = None
    success: bool = False
    steps: int = 0
    steps_left: int = 0
    max_steps: int = 0
    #: The level's fewest steps (hidden, None, in a human study).
    optimal_steps: int | None = None
    #: Every legal action's text (when the reset asked for ``legal``).
    legal: list[str] | None = None
    #: View name -> PNG as base64 (when the reset asked for ``images``).
    images: dict[str, str] = Field(default_factory=dict)
    #: The pieces' cells and colours for a 3D view (when the reset asked for ``scene``).
    scene: dict[str, Any] | None = None


class ChainState(State):  # type: ignore[misc]
    """``state``: the level, the steps used, and the position's canonical key."""

    level_id: str | None = None
    steps: int = 0
    key: str | None = None
    done: bool = False
    success: bool = False
