"""Turning an observation into a chat message, and reading actions back out of a reply.

The reply format is the original benchmark's: the action goes between ``<action>`` and
``</action>`` (the last such pair wins, so a model may think aloud first); a one-shot plan goes
between ``<plan>`` and ``</plan>``, one action per line (or as several ``<action>`` tags).
Nothing a model writes is ever evaluated: the text found is handed to the environment's parser.
"""

from __future__ import annotations

import base64
import re
from collections.abc import Sequence
from typing import Any, Final

from chaingeo.evaluation.agents.base import ObservationLike

SYSTEM_PROMPT: Final = (
    "You are playing a 3D physical reasoning game made of voxel pieces. Each turn you see the "
    "task, the pieces by colour, recent history and rendered views with labelled axes; "
    "coordinates are 1-based. Think as much as you like, then give exactly one action as "
    "<action>ACTION</action> at the end of your reply."
)
ONESHOT_PROMPT: Final = (
    "You are solving a 3D physical reasoning game made of voxel pieces from a single view; "
    "coordinates are 1-based. You will not see the result of any action: write your complete "
    "plan, one action per line, between <plan> and </plan> at the end of your reply."
)

TOOLS_PROMPT: Final = (
    "You are playing a 3D physical reasoning game made of voxel pieces. Each turn you see the "
    "task, the pieces by colour, recent history and rendered views with labelled axes; "
    "coordinates are 1-based. Act by calling the tools: each call is one action and costs one "
    "step. You may make several calls in one reply: they run in order and stop at the first one "
    "that is rejected, and each call's result comes back to you. (Without tools, give exactly "
    "one action as <action>ACTION</action> at the end of your reply.)"
)
ONESHOT_TOOLS_PROMPT: Final = (
    "You are solving a 3D physical reasoning game made of voxel pieces from a single view; "
    "coordinates are 1-based. You will not see the result of any action: give your complete "
    "plan in this one reply by calling the tools once per action, in order. (Without tools, "
    "write the plan, one action per line, between <plan> and </plan>.)"
)

_ACTION_RE: Final = re.compile(r"<action>(.*?)</action>", re.IGNORECASE | re.DOTALL)
_OPEN_RE: Final = re.compile(r"<action>", re.IGNORECASE)
_PLAN_RE: Final = re.compile(r"<plan>(.*?)</plan>", re.IGNORECASE | re.DOTALL)
_BULLET_RE: Final = re.compile(r"^\s*(?:[-*•]|\d+[.):]|step\s+\d+\s*[:.)-])\s*", re.IGNORECASE)


def _clean(action: str) -> str:
    text = action.strip().strip("`").strip()
    return " ".join(text.split())


def extract_action(text: str) -> tuple[str | None, str | None]:
    """(action, None) for the last ``<action>`` pair, else (None, why not)."""
    found = _ACTION_RE.findall(text)
    if found:
        action = _clean(found[-1])
        if action:
            return action, None
        return None, "the <action></action> tags were empty"
    if _OPEN_RE.search(text):
        return None, "your reply was cut off before </action>"
    return None, "no <action>...</action> found in your reply"


def extract_plan(text: str) -> tuple[tuple[str, ...], str | None]:
    """The plan's actions in order: ``<plan>`` lines, else every ``<action>`` tag."""
    blocks = _PLAN_RE.findall(text)
    if blocks:
        lines = [_clean(_BULLET_RE.sub("", line)) for line in blocks[-1].splitlines()]
        actions = tuple(line for line in lines if line)
        return actions, None if actions else "the <plan></plan> block was empty"
    actions = tuple(a for a in (_clean(x) for x in _ACTION_RE.findall(text)) if a)
    if actions:
        return actions, None
    if re.search(r"<plan>", text, re.IGNORECASE):
        return (), "your reply was cut off before </plan>"
    return (), "no <plan>...</plan> found in your reply"


def observation_text(obs: ObservationLike, feedback: str | None = None) -> str:
    """The text part of a turn (the observation's own text), plus why the last reply could not
    be read when that is the case (the environment never saw it, so its history cannot say)."""
    text = obs.to_text()
    if feedback:
        text += f"\n\nFeedback on your last reply: {feedback}"
    return text


def user_content(
    obs: ObservationLike,
    feedback: str | None = None,
    views: Sequence[str] | None = None,
    image_detail: str | None = None,
) -> list[dict[str, Any]]:
    """OpenAI content parts: the text, then each view as a base64 PNG data URL."""
    content: list[dict[str, Any]] = [{"type": "text", "text": observation_text(obs, feedback)}]
    for name, png in obs.images.items():
        if views is not None and name not in views:
            continue
        url: dict[str, Any] = {"url": "data:image/png;base64," + base64.b64encode(png).decode()}
        if image_detail:
            url["detail"] = image_detail
        content.append({"type": "text", "text": f"View: {name}"})
        content.append({"type": "image_url", "image_url": url})
    return content
