"""The solver: one level's episode played in chat turns through an inspect_ai model.

Each turn the model is shown what ``chain eval`` shows it (:mod:`chaingeo.evaluation.agents.
openai_chat`): the system prompt of the dialect and protocol, then the current observation (text
with the history window, the views as images); after a reply with tool calls, that reply, one
tool result per call and the observation it answered (text only) come before it. The reply is
read by the dialect (:func:`~chaingeo.evaluation.agents.dialects.read_reply`) and played by the
episode; the conversation (every picture, reply, tool result and observation) goes into
``state.messages`` for ``inspect view``, with one info event per turn naming the parsed actions,
whether each was legal and the environment's feedback. Tokens are inspect_ai's to count.

``oracle`` replies are the level's stored plan, written as a model would write it (``<action>``
tags, a ``<plan>`` block, or tool calls) and read by the same dialect.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any, Literal

from inspect_ai.log import transcript
from inspect_ai.model import (
    ChatMessage,
    ChatMessageAssistant,
    ChatMessageSystem,
    ChatMessageTool,
    ChatMessageUser,
    Content,
    ContentImage,
    ContentText,
    GenerateConfig,
    get_model,
)
from inspect_ai.solver import Generate, Solver, TaskState, solver
from inspect_ai.tool import ToolInfo, ToolParams

from chaingeo.core.level import Level
from chaingeo.evaluation.agents.base import Reply
from chaingeo.evaluation.agents.dialects import DIALECTS, read_reply, tool_call
from chaingeo.evaluation.agents.prompt import user_content
from chaingeo.evaluation.agents.tools import skipped_result, tool_specs
from chaingeo.evaluation.episode import Episode, ProtocolConfig
from chaingeo.integrations.inspect.oracle import oracle_output
from chaingeo.integrations.inspect.scoring import OUTCOME_KEY

Agent = Literal["model", "oracle"]


def content_of(parts: Sequence[Mapping[str, Any]], views: Sequence[str] | None) -> list[Content]:
    """OpenAI content parts as inspect_ai content (images as :class:`ContentImage`), keeping
    only the named ``views`` when given."""
    out: list[Content] = []
    skip = False
    for part in parts:
        if part.get("type") == "image_url":
            if not skip:
                out.append(ContentImage(image=str(part["image_url"]["url"])))
            skip = False
            continue
        text = str(part.get("text", ""))
        if views is not None and text.startswith("View: ") and text[6:] not in views:
            skip = True  # this view's label and its picture
            continue
        out.append(ContentText(text=text))
    return out


def tool_infos(level: Level, protocol: str) -> list[ToolInfo]:
    """Our action functions (:func:`~chaingeo.evaluation.agents.tools.tool_specs`) as inspect_ai
    tool descriptions; inspect_ai never runs them: the episode does."""
    out = []
    for spec in tool_specs(level, state=protocol == "interactive"):
        fn = spec["function"]
        out.append(
            ToolInfo(
                name=fn["name"],
                description=fn["description"],
                parameters=ToolParams.model_validate(fn["parameters"]),
            )
        )
    return out


def first_messages(
    episode: Episode, dialect: str, views: Sequence[str] | None
) -> list[ChatMessage]:
    """The sample's input: the system prompt and the first observation."""
    system = DIALECTS.get(dialect).system_prompt(episode.oneshot)
    return [ChatMessageSystem(content=system), _observation(episode, views)]


def _observation(episode: Episode, views: Sequence[str] | None) -> ChatMessageUser:
    parts = user_content(episode.observation(), episode.note)
    return ChatMessageUser(content=content_of(parts, views))


def _text_only(message: ChatMessageUser) -> ChatMessageUser:
    """The observation without its pictures (as the previous turn is re-sent)."""
    content = message.content
    if isinstance(content, str):
        return message
    texts = [p for p in content if isinstance(p, ContentText) and not p.text.startswith("View: ")]
    return ChatMessageUser(content=list(texts))


@solver
def play_level(
    levels: Mapping[str, Level],
    protocols: Mapping[str, ProtocolConfig],
    dialect: str = "text",
    images: bool = True,
    views: Sequence[str] | None = None,
    agent: Agent = "model",
    seed: int = 0,
    sampling: Mapping[str, Any] | None = None,
) -> Solver:
    """Play the sample's level under its protocol (``metadata["protocol"]``, one of
    ``protocols``) to the end of its episode; the outcome goes to the store."""
    config = GenerateConfig(**dict(sampling or {}))

    async def solve(state: TaskState, generate: Generate) -> TaskState:
        level = levels[str(state.metadata.get("level_id", state.sample_id))]
        protocol = protocols[str(state.metadata.get("protocol", "interactive"))]
        episode = Episode(
            level,
            protocol,
            images=images,
            sample=state.epoch - 1,
            seed=seed,
            agent=agent,
            keep_images=False,
        )
        offered = tool_infos(level, protocol.name) if DIALECTS.get(dialect).uses_tools else []
        wire = tool_specs(level, state=protocol.name == "interactive") if offered else []
        model = get_model() if agent == "model" else None
        system = ChatMessageSystem(content=DIALECTS.get(dialect).system_prompt(episode.oneshot))
        shown = _observation(episode, views)
        before: list[ChatMessage] = []  # the previous turn, re-sent after tool calls
        turn = 0
        while not episode.done:
            if model is not None:
                output = await model.generate(
                    [system, *before, shown], tools=offered, config=config
                )
            else:
                output = oracle_output(level, episode, dialect, turn)
            message = output.message
            state.output = output
            if turn:  # the first observation is the sample's input already
                state.messages.append(shown)
            state.messages.append(message)
            calls = tuple(
                tool_call(c.id, c.function, c.arguments, wire) for c in message.tool_calls or ()
            )
            reply = read_reply(dialect, message.text, calls, oneshot=episode.oneshot)
            results = episode.play(reply)
            interactive = calls and offered and not episode.oneshot  # one-shot: no feedback
            answers = _tool_answers(message, calls, results) if interactive else []
            state.messages.extend(answers)
            _note(turn, reply, results)
            before = [_text_only(shown), message, *answers] if answers else []
            turn += 1
            if not episode.done:
                shown = _observation(episode, views)
        state.store.set(OUTCOME_KEY, episode.outcome().to_json())
        state.completed = True
        return state

    return solve


def _tool_answers(
    message: ChatMessageAssistant, calls: Sequence[Any], results: Sequence[Any]
) -> list[ChatMessage]:
    """One tool message per call, played or not (the chat protocol wants every call answered)."""
    rejected = next((i for i, r in enumerate(results) if not r.legal), None)
    skipped = "Not executed. Nothing changed." if rejected is None else skipped_result(rejected)
    out: list[ChatMessage] = []
    for i, (made, call) in enumerate(zip(message.tool_calls or (), calls, strict=True)):
        text = str(results[i].feedback) if i < len(results) else skipped
        out.append(ChatMessageTool(content=text, tool_call_id=made.id, function=call.name))
    return out


def _note(turn: int, reply: Reply, results: Sequence[Any]) -> None:
    """The turn's parsed actions, legality and feedback, as an info event in the transcript."""
    sent = reply.actions or ((reply.action,) if reply.action is not None else ())
    transcript().info(
        {
            "turn": turn,
            "actions": list(sent),
            "note": reply.note,
            "steps": [
                {
                    "action": r.action.to_text() if r.action is not None else None,
                    "legal": bool(r.legal),
                    "error": r.error,
                    "feedback": r.feedback,
                }
                for r in results
            ],
        },
        source="chaingeo",
    )
