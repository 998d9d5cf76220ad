"""Verifier-based selection among candidate actions, and the hook for judges / reward models.

With ``candidates = K > 1`` the agent is asked K times per turn. Each candidate's action is
tried in a *clone* of the state (the verifier: the environment's own rules), which changes
nothing and costs no step. A :class:`Judge` then orders the candidates, best first; the harness
commits the first one. Built-in judges:

- ``first``: verified-legal candidates first, otherwise in sampling order (plain verifier);
- ``vote``: verified-legal first, then the action proposed most often (self-consistency);
- ``progress``: a reward model without a network: prefers a candidate that solves the level,
  then one after which the most legal actions remain (keeps options open), then sampling order;
- ``model``: a vision-language judge on any OpenAI-compatible server
  (:mod:`chaingeo.evaluation.judges.model_judge`; options ``judge_options``: model, base_url, ...).

Judges are made by name from :mod:`chaingeo.evaluation.judges.registry`, where another (a trained
reward model, ...) is registered. A judge that calls a model adds what it spent to ``usage``.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass

from chaingeo.evaluation.agents.base import ObservationLike, Reply, StateLike, StepResultLike
from chaingeo.evaluation.usage import Usage


@dataclass(frozen=True)
class Candidate:
    index: int
    reply: Reply
    result: StepResultLike | None  # the verifier's verdict in a clone (None: nothing to try)
    after: StateLike | None  # the clone after the action (None when illegal or unreadable)

    @property
    def legal(self) -> bool:
        return self.result is not None and self.result.legal


class Judge:
    name = "judge"
    model: str | None = None  # for pricing what it spends
    usage: Usage = Usage()  # tokens spent so far (judges that call a model add to it)

    def start(self, seed: int) -> None:
        """A new episode begins."""

    def rank(
        self,
        state: StateLike,
        candidates: Sequence[Candidate],
        observation: ObservationLike | None = None,
    ) -> list[int]:
        """Candidate indices, best first (every index exactly once)."""
        raise NotImplementedError


class FirstLegal(Judge):
    name = "first"

    def rank(
        self,
        state: StateLike,
        candidates: Sequence[Candidate],
        observation: ObservationLike | None = None,
    ) -> list[int]:
        return [c.index for c in sorted(candidates, key=lambda c: (not c.legal, c.index))]


class Vote(Judge):
    name = "vote"

    def rank(
        self,
        state: StateLike,
        candidates: Sequence[Candidate],
        observation: ObservationLike | None = None,
    ) -> list[int]:
        votes = Counter(c.result.action.to_text() for c in candidates if c.legal and c.result)

        def key(c: Candidate) -> tuple[bool, int, int]:
            n = votes[c.result.action.to_text()] if c.legal and c.result else 0
            return (not c.legal, -n, c.index)

        return [c.index for c in sorted(candidates, key=key)]


class Progress(Judge):
    name = "progress"

    def rank(
        self,
        state: StateLike,
        candidates: Sequence[Candidate],
        observation: ObservationLike | None = None,
    ) -> list[int]:
        def key(c: Candidate) -> tuple[bool, bool, int, int]:
            if c.after is None:
                return (True, True, 0, c.index)
            return (False, not c.after.is_success(), -len(c.after.legal_actions()), c.index)

        return [c.index for c in sorted(candidates, key=key)]


def verify(state: StateLike, replies: Sequence[Reply]) -> list[Candidate]:
    """Try each reply's action in its own clone of ``state``."""
    out = []
    for i, reply in enumerate(replies):
        if reply.action is None:
            out.append(Candidate(i, reply, None, None))
            continue
        probe = state.clone()
        result = probe.step_text(reply.action)
        out.append(Candidate(i, reply, result, probe if result.legal else None))
    return out
