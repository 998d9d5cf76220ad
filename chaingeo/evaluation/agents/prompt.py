"""Turning an observation into a chat message, and reading actions back out of a reply.

The reply format is the original benchmark's: the action goes between ``<action>`` and
``</action>`` (the last such pair wins, so a model may think aloud first); a one-shot plan goes
between ``<plan>`` and ``</plan>``, one action per line (or as several ``<action>`` tags).
Nothing a model writes is ever evaluated: the text found is handed to the environment's parser.
Reading is one linear scan over at most :data:`~chaingeo.core.limits.MAX_REPLY_CHARS` characters.
"""

from __future__ import annotations

import base64
import re
from collections.abc import Sequence
from typing import Any, Final

from chaingeo.core import limits
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

_BULLET_RE: Final = re.compile(r"^\s*(?:[-*•]|\d+[.):]|step\s+\d+\s*[:.)-])\s*", re.IGNORECASE)
#: ASCII upper case to lower case only: keeps every index of the text (``str.lower`` may not).
_ASCII_LOWER: Final = str.maketrans("ABCDEFGHIJKLMNOPQRSTUVWXYZ", "abcdefghijklmnopqrstuvwxyz")


def _clean(action: str) -> str:
    text = action.strip().strip("`").strip()
    return " ".join(text.split())


def _tagged(text: str, tag: str) -> tuple[list[str], bool]:
    """Every ``<tag>...</tag>`` body left to right (each from an opening tag to the first
    closing tag after it, tags in any case) and whether an opening tag is left unclosed. One
    forward scan with ``str.find``: linear whatever the text (a regular expression with a lazy
    ``.*?`` rescans the rest of the text from every opening tag)."""
    folded = text.translate(_ASCII_LOWER)
    opening, closing = f"<{tag}>", f"</{tag}>"
    found: list[str] = []
    pos = 0
    while (start := folded.find(opening, pos)) >= 0:
        end = folded.find(closing, start + len(opening))
        if end < 0:
            return found, True
        found.append(text[start + len(opening) : end])
        pos = end + len(closing)
    return found, False


def _too_long(text: str) -> str | None:
    if len(text) <= limits.MAX_REPLY_CHARS:
        return None
    return f"your reply has {len(text)} characters; at most {limits.MAX_REPLY_CHARS} are read"


def extract_action(text: str) -> tuple[str | None, str | None]:
    """(action, None) for the last ``<action>`` pair, else (None, why not)."""
    too_long = _too_long(text)
    if too_long:
        return None, too_long
    found, unclosed = _tagged(text, "action")
    if found:
        action = _clean(found[-1])
        if action:
            return action, None
        return None, "the <action></action> tags were empty"
    if unclosed:
        return None, "your reply was cut off before </action>"
    return None, "no <action>...</action> found in your reply"


def extract_plan(text: str) -> tuple[tuple[str, ...], str | None]:
    """The plan's actions in order: ``<plan>`` lines, else every ``<action>`` tag."""
    too_long = _too_long(text)
    if too_long:
        return (), too_long
    blocks, unclosed = _tagged(text, "plan")
    if blocks:
        lines = [_clean(_BULLET_RE.sub("", line)) for line in blocks[-1].splitlines()]
        actions = tuple(line for line in lines if line)
        return actions, None if actions else "the <plan></plan> block was empty"
    actions = tuple(a for a in (_clean(x) for x in _tagged(text, "action")[0]) if a)
    if actions:
        return actions, None
    if unclosed:
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
