"""The paper's metrics, computed from episode outcomes.

Notation: a run plays N levels, level ``i`` with ``n_i`` samples (episodes) of which ``c_i``
succeed; ``o_i`` is the level's optimal plan length (``optimal_steps``, exact: found by the
solvers on the very state machine the agent plays) and ``s_e`` the steps episode ``e`` used
(every agent turn counts, including unparseable and illegal ones, as the environment counts
them). ``S`` is the set of successful episodes.

- **Pass@1** (the headline "success"): ``mean_i c_i / n_i``; with one sample per level this is
  the fraction of levels solved. **Puzzle** and **Stacking** success are Pass@1 restricted to
  each family; the **per-difficulty** success is Pass@1 restricted to (family, difficulty).
- **Succ.Task**: ``|S|``, the number of solved episodes (with one sample per level: the number
  of levels solved).
- **AvgSteps (solved)**: ``mean_{e in S} s_e``.
- **Dist2Opt**: ``mean_{e in S} (s_e - o_e)``, extra steps over the optimum.
- **NormDist**: ``mean_{e in S} (s_e - o_e) / max(1, o_e)``; the ``max`` keeps a zero-step
  level from dividing by zero.
- **Solved per 1M tokens**: ``|S| / (T / 10^6)`` with ``T`` all tokens (input + output, summed
  over every episode, solved or not); None when no tokens were used.
- **Solved per USD**: ``|S| / C`` with ``C`` the run's cost in USD; None when nothing was spent
  or some episode's cost is unknown (a model with no price).
- **Pass@k** (unbiased estimator of Chen et al., 2021): ``mean_i 1 - C(n_i - c_i, k) / C(n_i, k)``,
  the chance that at least one of k samples drawn without replacement from the n_i succeeds.
- **Avg@k**: ``mean_i (1/k) * sum_{j<k} success(i, j)``, the mean success of the first k samples.

The three step metrics are None when nothing was solved (there is nothing to average).
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from math import comb
from statistics import fmean

from chaingeo.evaluation.episode import Outcome
from chaingeo.evaluation.usage import Usage, total_usage

FAMILIES = ("puzzle", "stacking")
DIFFICULTIES = ("easy", "mid", "hard")


def pass_at_k_unbiased(n: int, c: int, k: int) -> float:
    """``1 - C(n-c, k) / C(n, k)``: P(at least one success among k of the n samples)."""
    if not 0 <= c <= n:
        raise ValueError(f"need 0 <= c <= n, got n={n}, c={c}")
    if not 1 <= k <= n:
        raise ValueError(f"need 1 <= k <= n, got n={n}, k={k}")
    if n - c < k:
        return 1.0
    return 1.0 - comb(n - c, k) / comb(n, k)


def _by_level(outcomes: Iterable[Outcome]) -> dict[str, list[Outcome]]:
    groups: dict[str, list[Outcome]] = defaultdict(list)
    for o in outcomes:
        groups[o.level_id].append(o)
    for group in groups.values():
        group.sort(key=lambda o: o.sample)
        samples = [o.sample for o in group]
        if len(set(samples)) != len(samples):
            raise ValueError(f"level {group[0].level_id}: sample {samples} listed twice")
    return dict(sorted(groups.items()))


def pass_at_1(outcomes: Iterable[Outcome]) -> float | None:
    """Mean over levels of the fraction of samples solved; None for no episodes."""
    groups = _by_level(outcomes)
    if not groups:
        return None
    return fmean(sum(o.success for o in g) / len(g) for g in groups.values())


def pass_at_k(outcomes: Iterable[Outcome], k: int) -> float | None:
    """Unbiased Pass@k averaged over levels; every level needs at least k samples."""
    groups = _by_level(outcomes)
    if not groups:
        return None
    return fmean(pass_at_k_unbiased(len(g), sum(o.success for o in g), k) for g in groups.values())


def avg_at_k(outcomes: Iterable[Outcome], k: int) -> float | None:
    """Mean success of the first k samples (by sample index) of each level."""
    groups = _by_level(outcomes)
    if not groups:
        return None
    for level_id, g in groups.items():
        if len(g) < k:
            raise ValueError(f"level {level_id}: Avg@{k} needs {k} samples, has {len(g)}")
    return fmean(sum(o.success for o in g[:k]) / k for g in groups.values())


def solved(outcomes: Iterable[Outcome]) -> list[Outcome]:
    return [o for o in outcomes if o.success]


def succ_task(outcomes: Iterable[Outcome]) -> int:
    return len(solved(outcomes))


def avg_steps_solved(outcomes: Iterable[Outcome]) -> float | None:
    s = solved(outcomes)
    return fmean(o.steps for o in s) if s else None


def dist_to_opt(outcomes: Iterable[Outcome]) -> float | None:
    s = solved(outcomes)
    return fmean(o.steps - o.optimal_steps for o in s) if s else None


def norm_dist(outcomes: Iterable[Outcome]) -> float | None:
    s = solved(outcomes)
    return fmean((o.steps - o.optimal_steps) / max(1, o.optimal_steps) for o in s) if s else None


def run_cost(outcomes: Iterable[Outcome]) -> float | None:
    """Total USD, or None when any episode's cost is unknown."""
    total = 0.0
    for o in outcomes:
        if o.cost_usd is None:
            return None
        total += o.cost_usd
    return total


def solved_per_million_tokens(outcomes: Sequence[Outcome]) -> float | None:
    tokens = total_usage(o.usage for o in outcomes).total_tokens
    return succ_task(outcomes) / (tokens / 1_000_000) if tokens else None


def solved_per_usd(outcomes: Sequence[Outcome]) -> float | None:
    cost = run_cost(outcomes)
    return succ_task(outcomes) / cost if cost else None


def by_family(outcomes: Iterable[Outcome], family: str) -> list[Outcome]:
    return [o for o in outcomes if o.family == family]


def by_difficulty(outcomes: Iterable[Outcome], family: str, difficulty: str) -> list[Outcome]:
    return [o for o in outcomes if o.family == family and o.difficulty == difficulty]


@dataclass(frozen=True)
class Summary:
    """One row of Table 1 (plus the K-sample figures when there are several samples)."""

    episodes: int
    levels: int
    samples: int  # the smallest number of samples any level has
    pass_at_1: float | None
    puzzle: float | None
    stacking: float | None
    succ_task: int
    avg_steps: float | None
    dist2opt: float | None
    normdist: float | None
    usage: Usage
    cost_usd: float | None
    solved_per_mtok: float | None
    solved_per_usd: float | None
    by_difficulty: dict[str, float | None]  # "stacking/easy" -> Pass@1
    pass_at: dict[int, float | None]  # k -> Pass@k for k = 1, 2, 4, ... <= samples
    avg_at: dict[int, float | None]


def summarize(outcomes: Sequence[Outcome]) -> Summary:
    groups = _by_level(outcomes)
    samples = min((len(g) for g in groups.values()), default=0)
    ks = [k for k in (1, 2, 4, 8, 16, 32, 64) if k <= samples]
    if samples and samples not in ks:
        ks.append(samples)
    return Summary(
        episodes=len(outcomes),
        levels=len(groups),
        samples=samples,
        pass_at_1=pass_at_1(outcomes),
        puzzle=pass_at_1(by_family(outcomes, "puzzle")),
        stacking=pass_at_1(by_family(outcomes, "stacking")),
        succ_task=succ_task(outcomes),
        avg_steps=avg_steps_solved(outcomes),
        dist2opt=dist_to_opt(outcomes),
        normdist=norm_dist(outcomes),
        usage=total_usage(o.usage for o in outcomes),
        cost_usd=run_cost(outcomes),
        solved_per_mtok=solved_per_million_tokens(outcomes),
        solved_per_usd=solved_per_usd(outcomes),
        by_difficulty={
            f"{f}/{d}": pass_at_1(by_difficulty(outcomes, f, d))
            for f in FAMILIES
            for d in DIFFICULTIES
        },
        pass_at={k: pass_at_k(outcomes, k) for k in ks},
        avg_at={k: avg_at_k(outcomes, k) for k in ks},
    )
