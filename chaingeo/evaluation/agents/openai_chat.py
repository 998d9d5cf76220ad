"""The model agent: any OpenAI-compatible chat-completions server.

Options (all logged; the key is not an option): ``model``, ``base_url`` (default: env
``OPENAI_BASE_URL``, else ``https://api.openai.com/v1``), ``api_key_env`` (the variable holding
the key, default ``OPENAI_API_KEY``; a local server may need none), ``temperature`` 0.6 and
``top_p`` 0.95 (the paper's), ``max_tokens``, ``timeout``, ``max_retries``, ``backoff_base``,
``tools`` (offer an ``act``/``submit_plan`` tool instead of relying on tags), ``send_seed`` (pass
a per-call seed to servers that accept one), ``image_detail``, ``views`` (subset of views sent).

Each turn is one stateless request (system prompt + the observation, whose history already
holds the last N turns), so the context stays bounded and a run can resume anywhere.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from typing import Any

from chaingeo.core.level import Level
from chaingeo.evaluation.agents.base import Agent, AgentError, Reply, Turn
from chaingeo.evaluation.agents.http import ChatClient, ServerSettings
from chaingeo.evaluation.agents.prompt import (
    ONESHOT_PROMPT,
    SYSTEM_PROMPT,
    extract_action,
    extract_plan,
    user_content,
)
from chaingeo.evaluation.usage import Usage

ACT_TOOL: dict[str, Any] = {
    "type": "function",
    "function": {
        "name": "act",
        "description": "Take one action in the game.",
        "parameters": {
            "type": "object",
            "properties": {"action": {"type": "string", "description": "e.g. pickup red"}},
            "required": ["action"],
        },
    },
}
PLAN_TOOL: dict[str, Any] = {
    "type": "function",
    "function": {
        "name": "submit_plan",
        "description": "Submit the whole plan, actions in order.",
        "parameters": {
            "type": "object",
            "properties": {"actions": {"type": "array", "items": {"type": "string"}}},
            "required": ["actions"],
        },
    },
}


class OpenAIAgent(Agent):
    name = "openai"

    def __init__(self, options: Mapping[str, Any], secrets: Mapping[str, str]) -> None:
        if not options.get("model"):
            raise ValueError("the openai agent needs a model name (--model)")
        self.options = dict(options)
        self.model = str(options["model"])
        self.server = ServerSettings.from_options(options, secrets)
        self.uses_images = bool(options.get("images", True))
        self._client: ChatClient | None = None
        self._seed = 0

    def start(self, level: Level, seed: int) -> None:
        self._seed = seed
        self._client = self.server.client(seed)

    def _body(self, system: str, turn: Turn, tool: dict[str, Any]) -> dict[str, Any]:
        assert turn.observation is not None
        views = self.options.get("views")
        body: dict[str, Any] = {
            "model": self.model,
            "messages": [
                {"role": "system", "content": system},
                {
                    "role": "user",
                    "content": user_content(
                        turn.observation,
                        turn.last_feedback,
                        views=list(views) if views else None,
                        image_detail=self.options.get("image_detail"),
                    ),
                },
            ],
            "temperature": float(self.options.get("temperature", 0.6)),
            "top_p": float(self.options.get("top_p", 0.95)),
        }
        if self.options.get("max_tokens"):
            body["max_tokens"] = int(self.options["max_tokens"])
        if self.options.get("send_seed"):
            body["seed"] = (self._seed * 1_000_003 + turn.index * 101 + turn.candidate) % 2**31
        if self.options.get("tools"):
            body["tools"] = [tool]
        return body

    def _call(self, body: dict[str, Any]) -> tuple[str, str | None, Any, Usage]:
        if self._client is None:
            raise AgentError("start() was not called")
        answer = self._client.complete(body)
        choice = answer["choices"][0] if isinstance(answer["choices"][0], dict) else {}
        message = choice.get("message") or {}
        text = _content_text(message.get("content"))
        reasoning = message.get("reasoning_content") or message.get("reasoning")
        tool_args = _tool_arguments(message.get("tool_calls"))
        usage = Usage.from_openai(answer.get("usage"))
        return text, reasoning if isinstance(reasoning, str) else None, tool_args, usage

    def act(self, turn: Turn) -> Reply:
        text, reasoning, tool_args, usage = self._call(self._body(SYSTEM_PROMPT, turn, ACT_TOOL))
        if isinstance(tool_args, dict) and isinstance(tool_args.get("action"), str):
            action: str | None = " ".join(tool_args["action"].split()) or None
            note = None if action else "the act tool was called with an empty action"
            shown = text or json.dumps({"tool": "act", **tool_args})
            return Reply(shown, action, usage, note=note, reasoning=reasoning)
        action, note = extract_action(text)
        return Reply(text, action, usage, note=note, reasoning=reasoning)

    def plan(self, turn: Turn) -> Reply:
        text, reasoning, tool_args, usage = self._call(self._body(ONESHOT_PROMPT, turn, PLAN_TOOL))
        if isinstance(tool_args, dict) and isinstance(tool_args.get("actions"), list):
            actions = tuple(
                " ".join(str(a).split()) for a in tool_args["actions"] if str(a).strip()
            )
            shown = text or json.dumps({"tool": "submit_plan", **tool_args})
            return Reply(shown, None, usage, actions=actions, reasoning=reasoning)
        actions, note = extract_plan(text)
        return Reply(text, None, usage, actions=actions, note=note, reasoning=reasoning)


def _content_text(content: Any) -> str:
    if isinstance(content, str):
        return content
    if isinstance(content, list):  # content parts
        return "".join(
            str(p.get("text", ""))
            for p in content
            if isinstance(p, dict) and p.get("type") == "text"
        )
    return ""


def _tool_arguments(calls: Any) -> Any:
    if not isinstance(calls, list) or not calls:
        return None
    fn = calls[0].get("function") if isinstance(calls[0], dict) else None
    if not isinstance(fn, dict):
        return None
    args = fn.get("arguments")
    if isinstance(args, dict):
        return args
    if isinstance(args, str):
        try:
            return json.loads(args)
        except json.JSONDecodeError:
            return None
    return None
