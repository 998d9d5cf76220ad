"""The score of one episode, the metrics over samples and the reducers over epochs.

A sample's score is its success (1 or 0) with, in its metadata, the episode's steps, ``o_i``
(the level's optimal steps), Dist2Opt and NormDist, and sums the metrics add up: ``solved``,
``episodes`` and the step figures summed over solved episodes. The reducers (``mean``,
``pass_at_k``: Pass@k, ``pass_hat_k``: Pass^k, with k the number of epochs, unbiased
as in :mod:`chaingeo.evaluation.metrics`) add those sums over a level's epochs, so the metrics
below give the same figures as ``chain report`` (NormDist averaged over solved episodes) after
any reducer. k follows ``--epochs`` (inspect_ai fixes a task's reducers before it knows the
epochs, so a fixed-k reducer could not).
"""

from __future__ import annotations

import math
from typing import Any

from inspect_ai.scorer import (
    Metric,
    SampleScore,
    Score,
    Scorer,
    ScoreReducer,
    Target,
    accuracy,
    metric,
    score_reducer,
    scorer,
    stderr,
)
from inspect_ai.solver import TaskState

from chaingeo.evaluation.episode import Outcome
from chaingeo.evaluation.metrics import pass_at_k_unbiased, pass_hat_k_unbiased

#: Where the solver leaves the episode's outcome (``state.store``).
OUTCOME_KEY = "chaingeo/outcome"
#: The metadata fields summed over epochs by every reducer.
SUMS = ("solved", "episodes", "steps_solved", "dist2opt_solved", "normdist_solved")


def episode_metadata(o: Outcome) -> dict[str, Any]:
    """One episode's figures, and the sums the metrics add up."""
    dist = o.steps - o.optimal_steps
    norm = dist / max(1, o.optimal_steps)
    return {
        "level_id": o.level_id,
        "family": o.family,
        "difficulty": o.difficulty,
        "steps": o.steps,
        "o_i": o.optimal_steps,
        "dist2opt": dist if o.success else None,
        "normdist": norm if o.success else None,
        "actions": o.actions,
        "readable": o.readable,
        "finished": o.finished,
        "truncated": o.truncated,
        "solved": int(o.success),
        "episodes": 1,
        "steps_solved": o.steps if o.success else 0,
        "dist2opt_solved": dist if o.success else 0,
        "normdist_solved": norm if o.success else 0.0,
    }


@scorer(metrics=[accuracy(), stderr()])
def success() -> Scorer:
    """1 when the episode solved its level, else 0; the episode's figures in the metadata."""

    async def score(state: TaskState, target: Target) -> Score:
        o = Outcome.from_json(state.store.get(OUTCOME_KEY))
        if o is None:
            return Score(value=0.0, explanation="the episode did not finish")
        how = f"{o.steps} steps, optimal {o.optimal_steps}"
        return Score(
            value=1.0 if o.success else 0.0,
            answer=f"{'solved' if o.success else 'not solved'} in {o.steps} steps",
            explanation=f"{'solved' if o.success else 'not solved'}: {how}",
            metadata=episode_metadata(o),
        )

    return score


def _sum(scores: list[SampleScore], key: str) -> float:
    return float(sum((s.score.metadata or {}).get(key) or 0 for s in scores))


def _per_solved(scores: list[SampleScore], key: str) -> float:
    solved = _sum(scores, "solved")
    return _sum(scores, key) / solved if solved else math.nan


@metric(name="normdist")
def normdist() -> Metric:
    """Mean NormDist over the solved episodes (NaN when none was solved)."""

    def compute(scores: list[SampleScore]) -> float:
        return _per_solved(scores, "normdist_solved")

    return compute


@metric(name="dist2opt")
def dist2opt() -> Metric:
    """Mean extra steps over the optimum, solved episodes."""

    def compute(scores: list[SampleScore]) -> float:
        return _per_solved(scores, "dist2opt_solved")

    return compute


@metric(name="avg_steps")
def avg_steps() -> Metric:
    """Mean steps of the solved episodes (the paper's AvgSteps)."""

    def compute(scores: list[SampleScore]) -> float:
        return _per_solved(scores, "steps_solved")

    return compute


def _reduced(value: float, scores: list[Score]) -> Score:
    """A level's score over its epochs: ``value``, the summed figures, and the first epoch's
    per-episode fields (as inspect_ai's own reducers keep them)."""
    meta = dict(scores[0].metadata or {}) if scores else {}
    for key in SUMS:
        meta[key] = sum((s.metadata or {}).get(key) or 0 for s in scores)
    return Score(value=value, metadata=meta)


def _successes(scores: list[Score]) -> tuple[int, int]:
    return len(scores), sum(1 for s in scores if float(s.as_float()) >= 1.0)


@score_reducer(name="mean")
def mean_epochs() -> ScoreReducer:
    """The share of a level's epochs solved."""

    def reduce(scores: list[Score]) -> Score:
        n, c = _successes(scores)
        return _reduced(c / n if n else math.nan, scores)

    return reduce


@score_reducer(name="pass_at_k")
def pass_at_epochs() -> ScoreReducer:
    """Pass@k with k the level's epochs (unbiased; at least one of k succeeds)."""

    def reduce(scores: list[Score]) -> Score:
        n, c = _successes(scores)
        return _reduced(pass_at_k_unbiased(n, c, n) if n else math.nan, scores)

    return reduce


@score_reducer(name="pass_hat_k")
def pass_all_epochs() -> ScoreReducer:
    """Pass^k with k the level's epochs (all k succeed)."""

    def reduce(scores: list[Score]) -> Score:
        n, c = _successes(scores)
        return _reduced(pass_hat_k_unbiased(n, c, n) if n else math.nan, scores)

    return reduce


#: The task's metrics: accuracy with its standard error, and the step figures.
METRICS: list[Metric | dict[str, list[Metric]]] = [
    accuracy(),
    stderr(),
    normdist(),
    dist2opt(),
    avg_steps(),
]
REDUCERS: list[ScoreReducer] = [mean_epochs(), pass_at_epochs(), pass_all_epochs()]
