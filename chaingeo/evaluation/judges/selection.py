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
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from chaingeo.evaluation.agents.base import ObservationLike, Reply, StateLike, StepResultLike
from chaingeo.evaluation.usage import Usage


@dataclass(frozen=True)
class CheckedReply:
    index: int
    reply: Reply
    result: StepResultLike | None  # the verifier's verdict in a clone (None: nothing to try)
    after: StateLike | None  # the clone after the action (None when illegal or unreadable)

    @property
    def legal(self) -> bool:
        return self.result is not None and self.result.legal


#: Orders legal candidates: the key of each (smaller first).
Preference = Callable[[CheckedReply], tuple[int, ...]]
#: What a judge ranks: the turn's candidates, and what the agent saw (when known).
Candidates = Sequence[CheckedReply]
Seen = ObservationLike | None


class Judge:
    name = "judge"
    model: str | None = None  # for pricing what it spends
    usage: Usage = Usage()  # tokens spent so far (judges that call a model add to it)

    def start(self, seed: int) -> None:
        """A new episode begins."""

    def rank(
        self,
        state: StateLike,
        candidates: Sequence[CheckedReply],
        observation: ObservationLike | None = None,
    ) -> list[int]:
        """Candidate indices, best first (every index exactly once): verified-legal ones
        first, then by :meth:`preference`, then in sampling order."""
        prefer = self.preference(state, candidates, observation)
        return [
            c.index for c in sorted(candidates, key=lambda c: (not c.legal, prefer(c), c.index))
        ]

    def preference(self, state: StateLike, candidates: Candidates, obs: Seen = None) -> Preference:
        """How this judge orders legal candidates (smaller first); none by default."""
        return lambda c: ()


class FirstLegal(Judge):
    name = "first"


class Vote(Judge):
    name = "vote"

    def preference(self, state: StateLike, candidates: Candidates, obs: Seen = None) -> Preference:
        votes = Counter(c.result.action.to_text() for c in candidates if c.legal and c.result)
        return lambda c: (-votes[c.result.action.to_text()] if c.legal and c.result else 0,)


class ProgressJudge(Judge):
    name = "progress"

    def preference(self, state: StateLike, candidates: Candidates, obs: Seen = None) -> Preference:
        def key(c: CheckedReply) -> tuple[int, ...]:
            if c.after is None:
                return ()
            return (int(not c.after.is_success()), -len(c.after.legal_actions()))

        return key


def verify(state: StateLike, replies: Sequence[Reply]) -> list[CheckedReply]:
    """Try each reply's action in its own clone of ``state``."""
    out = []
    for i, reply in enumerate(replies):
        if reply.action is None:
            out.append(CheckedReply(i, reply, None, None))
            continue
        probe = state.clone()
        result = probe.step_text(reply.action)
        out.append(CheckedReply(i, reply, result, probe if result.legal else None))
    return out
