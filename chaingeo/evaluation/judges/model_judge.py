"""A vision-language model as the judge of verified candidate actions (the paper's "VLM judge").

Shown the same observation as the agent (text and views) and the candidates that passed the
verifier, numbered, it answers ``<choice>N</choice>``. Only legal candidates are offered and the
model is asked only when there are two or more different ones; a reply without a readable
choice falls back to the verifier's order (a judge's slip never costs a step). Options as for
the ``openai`` agent (``model``, ``base_url``, ``api_key_env``, ``timeout``, ``max_retries``,
``backoff_base``), with ``temperature`` 0.1 by default.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from typing import Any, Final

from chaingeo.evaluation.agents.base import ObservationLike, StateLike
from chaingeo.evaluation.agents.http import ChatClient, ServerSettings
from chaingeo.evaluation.agents.prompt import user_content
from chaingeo.evaluation.judges.selection import (
    Candidates,
    CheckedReply,
    Judge,
    Preference,
    Seen,
)
from chaingeo.evaluation.usage import Usage

JUDGE_PROMPT: Final = (
    "You judge candidate actions in a 3D physical reasoning game made of voxel pieces. Each "
    "candidate has already been checked to be legal. Pick the one most likely to lead to "
    "solving the task. Answer with <choice>N</choice>, N the candidate's number."
)
#: At most 9 digits: a longer number names no candidate (and ``int`` never sees 5,000 digits).
_CHOICE_RE: Final = re.compile(r"<choice>\s*(\d{1,9})\s*</choice>", re.IGNORECASE)


class ModelJudge(Judge):
    name = "model"

    def __init__(self, options: Mapping[str, Any]) -> None:
        if not options.get("model"):
            raise ValueError("the model judge needs a model name (judge option model=...)")
        self.options = dict(options)
        self.model = str(options["model"])
        self.server = ServerSettings.from_options(options)
        self._client: ChatClient | None = None
        self.usage = Usage()
        self.replies: list[str] = []

    def start(self, seed: int) -> None:
        self._client = self.server.client(seed + 1)

    def preference(self, state: StateLike, candidates: Candidates, obs: Seen = None) -> Preference:
        """The candidate the model picks first (when it picks one of two or more distinct
        legal actions); the rest in sampling order."""
        offered: list[CheckedReply] = []
        seen: set[str] = set()
        for c in sorted(candidates, key=lambda c: (not c.legal, c.index)):
            if c.legal and c.reply.action is not None and c.reply.action not in seen:
                seen.add(c.reply.action)
                offered.append(c)
        if len(offered) < 2 or obs is None:
            return lambda c: ()
        best = self._ask(offered, obs)
        return lambda c: (int(c.index != best),)

    def _ask(self, offered: Sequence[CheckedReply], observation: ObservationLike) -> int | None:
        """The index of the candidate the model chooses, None when its answer names none."""
        if self._client is None:
            self.start(0)
        assert self._client is not None
        content = user_content(observation)
        listing = "\n".join(f"{i}. {c.reply.action}" for i, c in enumerate(offered, 1))
        content.append({"type": "text", "text": f"Candidates:\n{listing}"})
        body = {
            "model": self.model,
            "messages": [
                {"role": "system", "content": JUDGE_PROMPT},
                {"role": "user", "content": content},
            ],
            "temperature": float(self.options.get("temperature", 0.1)),
            "top_p": float(self.options.get("top_p", 0.95)),
        }
        answer = self._client.complete(body)
        self.usage = self.usage + Usage.from_openai(answer.get("usage"))
        message = answer["choices"][0].get("message") or {}
        raw = message.get("content")
        text = raw if isinstance(raw, str) else ""
        self.replies.append(text)
        found = _CHOICE_RE.findall(text)
        if not found or not 1 <= int(found[-1]) <= len(offered):
            return None
        return offered[int(found[-1]) - 1].index
