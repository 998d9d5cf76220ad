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
- **Pass^k** (all k succeed; unbiased, as tau-bench): ``mean_i C(c_i, k) / C(n_i, k)``, the chance
  that k samples drawn without replacement from the n_i all succeed: reliability, not luck.
- **Avg@k**: ``mean_i (1/k) * sum_{j<k} success(i, j)``, the mean success of the first k samples.

The three step metrics are None when nothing was solved (there is nothing to average).

Each metric a report shows is registered once (:func:`register_metric`: name, column title,
which direction is better, kind, formatter) in :data:`METRICS`; the tables, the CSV and the site
read the registry. A registered metric returns an :class:`~chaingeo.evaluation.stats.Estimate`:
rates with a 95% interval (Wilson with one sample per level, else a bootstrap over levels), means
with their standard error (:mod:`chaingeo.evaluation.stats`).
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from math import comb
from statistics import fmean
from typing import Any, Literal

from chaingeo.evaluation import stats
from chaingeo.evaluation.episode import Outcome
from chaingeo.evaluation.stats import Estimate
from chaingeo.evaluation.usage import total_usage

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


def pass_hat_k_unbiased(n: int, c: int, k: int) -> float:
    """``C(c, k) / C(n, k)``: P(all k of k samples drawn from the n succeed)."""
    if not 0 <= c <= n:
        raise ValueError(f"need 0 <= c <= n, got n={n}, c={c}")
    if not 1 <= k <= n:
        raise ValueError(f"need 1 <= k <= n, got n={n}, k={k}")
    return comb(c, k) / comb(n, k)


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


def pass_hat_k(outcomes: Iterable[Outcome], k: int) -> float | None:
    """Unbiased Pass^k (all k succeed) averaged over levels; every level needs k samples."""
    groups = _by_level(outcomes)
    if not groups:
        return None
    return fmean(pass_hat_k_unbiased(len(g), sum(o.success for o in g), k) for g in groups.values())


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


# ---------------------------------------------------------------------------------------------
# The registry: every figure a report shows, defined once, with its uncertainty.
# ---------------------------------------------------------------------------------------------

Kind = Literal["rate", "mean", "count", "tokens", "usd", "ratio"]


@dataclass(frozen=True)
class Metric:
    """One registered figure: ``compute(outcomes, k)`` gives its :class:`Estimate`."""

    name: str
    title: str
    better: Literal["higher", "lower"] | None
    kind: Kind
    compute: Callable[[Sequence[Outcome], int], Estimate]
    doc: str
    digits: int = 2

    def format(self, e: Any) -> str:
        """The cell text: percent with ``[low, high]`` for rates, ``± stderr`` for means."""
        if not isinstance(e, Estimate):
            return "—" if e is None else str(e)
        if e.value is None:
            return "—"
        return _FORMATS[self.kind](e.value, e, self.digits)


def _uncertainty(e: Estimate, show: Callable[[float], str]) -> str:
    """`` [low, high]`` or `` ± stderr`` (as the estimate has), in the value's own units."""
    if e.low is not None and e.high is not None:
        return f" [{show(e.low)}, {show(e.high)}]"
    if e.stderr is not None:
        return f" ± {show(e.stderr)}"
    return " ± —" if e.method == stats.STDERR else ""


def _fmt_rate(v: float, e: Estimate, digits: int) -> str:
    def pct(x: float) -> str:
        return f"{100 * x:.1f}"

    return pct(v) + _uncertainty(e, pct)


def _fmt_number(v: float, e: Estimate, digits: int) -> str:
    def num(x: float) -> str:
        return f"{x:.{digits}f}"

    return num(v) + _uncertainty(e, num)


def _fmt_tokens(v: float, e: Estimate, digits: int) -> str:
    n = int(v)
    return f"{n / 1e6:.2f}M" if n >= 1e6 else f"{n / 1e3:.1f}k" if n >= 1e3 else str(n)


_FORMATS: dict[Kind, Callable[[float, Estimate, int], str]] = {
    "rate": _fmt_rate,
    "mean": _fmt_number,
    "ratio": _fmt_number,
    "count": lambda v, e, d: str(int(v)),
    "tokens": _fmt_tokens,
    "usd": lambda v, e, d: f"{v:.{d}f}",
}

#: name -> metric, in registration order (the order a table lists them by default).
METRICS: dict[str, Metric] = {}


def register_metric(
    name: str, title: str, kind: Kind, better: Literal["higher", "lower"] | None, digits: int = 2
) -> Callable[[Callable[[Sequence[Outcome], int], Estimate]], Metric]:
    """Register ``compute(outcomes, k) -> Estimate`` under ``name`` (once: a name is unique)."""

    def add(fn: Callable[[Sequence[Outcome], int], Estimate]) -> Metric:
        if name in METRICS:
            raise ValueError(f"metric {name!r} registered twice")
        metric = Metric(name, title, better, kind, fn, (fn.__doc__ or "").strip(), digits)
        METRICS[name] = metric
        return metric

    return add


def _level_values(outcomes: Sequence[Outcome], per_level: Callable[[int, int], float]) -> Estimate:
    """The per-level values ``per_level(n_i, c_i)``, their mean and its standard error."""
    groups = _by_level(outcomes)
    return stats.mean([per_level(len(g), sum(o.success for o in g)) for g in groups.values()])


@register_metric("pass@1", "Pass@1", "rate", "higher")
def _m_pass_at_1(outcomes: Sequence[Outcome], k: int = 1) -> Estimate:
    """Mean over levels of the share of samples solved: Wilson with one sample per level,
    else a bootstrap over levels."""
    groups = _by_level(outcomes)
    if not groups:
        return Estimate(None)
    if all(len(g) == 1 for g in groups.values()):
        return stats.rate(sum(g[0].success for g in groups.values()), len(groups))
    return stats.level_rate([sum(o.success for o in g) / len(g) for g in groups.values()])


@register_metric("succ_task", "Succ.Task", "count", "higher")
def _m_succ_task(outcomes: Sequence[Outcome], k: int = 1) -> Estimate:
    """Solved episodes."""
    return Estimate(float(succ_task(outcomes)))


@register_metric("episodes", "Episodes", "count", None)
def _m_episodes(outcomes: Sequence[Outcome], k: int = 1) -> Estimate:
    """Episodes played."""
    return Estimate(float(len(outcomes)))


@register_metric("avg_steps", "AvgSteps", "mean", "lower")
def _m_avg_steps(outcomes: Sequence[Outcome], k: int = 1) -> Estimate:
    """Steps of the solved episodes."""
    return stats.mean([o.steps for o in solved(outcomes)])


@register_metric("dist2opt", "Dist2Opt", "mean", "lower")
def _m_dist2opt(outcomes: Sequence[Outcome], k: int = 1) -> Estimate:
    """Extra steps over the optimum, solved episodes."""
    return stats.mean([o.steps - o.optimal_steps for o in solved(outcomes)])


@register_metric("normdist", "NormDist", "mean", "lower", digits=3)
def _m_normdist(outcomes: Sequence[Outcome], k: int = 1) -> Estimate:
    """Extra steps relative to the optimum, solved episodes."""
    return stats.mean(
        [(o.steps - o.optimal_steps) / max(1, o.optimal_steps) for o in solved(outcomes)]
    )


@register_metric("tokens_per_episode", "Tok/episode", "mean", "lower", digits=0)
def _m_tokens_per_episode(outcomes: Sequence[Outcome], k: int = 1) -> Estimate:
    """Tokens (input + output) of an episode."""
    return stats.mean([o.usage.total_tokens for o in outcomes])


@register_metric("tokens", "Tokens", "tokens", "lower")
def _m_tokens(outcomes: Sequence[Outcome], k: int = 1) -> Estimate:
    """All tokens of the run."""
    return Estimate(float(total_usage(o.usage for o in outcomes).total_tokens))


@register_metric("cost_usd", "USD", "usd", "lower", digits=4)
def _m_cost(outcomes: Sequence[Outcome], k: int = 1) -> Estimate:
    """The run's cost; unknown (—) when some episode's model has no price."""
    return Estimate(run_cost(outcomes))


def _per_level_sums(
    outcomes: Sequence[Outcome], amount: Callable[[Outcome], float]
) -> tuple[list[float], list[float]]:
    groups = _by_level(outcomes).values()
    return [float(sum(o.success for o in g)) for g in groups], [
        sum(amount(o) for o in g) for g in groups
    ]


@register_metric("solved_per_mtok", "Solved/1M tok", "ratio", "higher")
def _m_solved_per_mtok(outcomes: Sequence[Outcome], k: int = 1) -> Estimate:
    """Solved episodes per million tokens (bootstrap over levels)."""
    return stats.bootstrap_ratio(
        *_per_level_sums(outcomes, lambda o: o.usage.total_tokens / 1_000_000)
    )


@register_metric("solved_per_usd", "Solved/USD", "ratio", "higher")
def _m_solved_per_usd(outcomes: Sequence[Outcome], k: int = 1) -> Estimate:
    """Solved episodes per USD (bootstrap over levels); unknown with an unpriced episode."""
    if run_cost(outcomes) is None:
        return Estimate(None)
    return stats.bootstrap_ratio(*_per_level_sums(outcomes, lambda o: o.cost_usd or 0.0))


@register_metric("pass@k", "Pass@k", "rate", "higher")
def _m_pass_at_k(outcomes: Sequence[Outcome], k: int = 1) -> Estimate:
    """Unbiased Pass@k: mean over levels ± its standard error over levels."""
    return _level_values(outcomes, lambda n, c: pass_at_k_unbiased(n, c, k))


@register_metric("pass^k", "Pass^k", "rate", "higher")
def _m_pass_hat_k(outcomes: Sequence[Outcome], k: int = 1) -> Estimate:
    """Unbiased Pass^k (all k succeed): mean over levels ± its standard error over levels."""
    return _level_values(outcomes, lambda n, c: pass_hat_k_unbiased(n, c, k))


@register_metric("avg@k", "Avg@k", "rate", "higher")
def _m_avg_at_k(outcomes: Sequence[Outcome], k: int = 1) -> Estimate:
    """Mean success of each level's first k samples ± its standard error over levels."""
    groups = _by_level(outcomes)
    for level_id, g in groups.items():
        if len(g) < k:
            raise ValueError(f"level {level_id}: Avg@{k} needs {k} samples, has {len(g)}")
    return stats.mean([sum(o.success for o in g[:k]) / k for g in groups.values()])


# ---------------------------------------------------------------------------------------------
# A run's figures
# ---------------------------------------------------------------------------------------------


class Summary:
    """The registered figures of one run, on the whole run or a family / tier, computed once."""

    def __init__(self, outcomes: Sequence[Outcome]) -> None:
        self.outcomes = list(outcomes)
        groups = _by_level(self.outcomes)
        self.episodes = len(self.outcomes)
        self.levels = len(groups)
        #: The smallest number of samples any level has.
        self.samples = min((len(g) for g in groups.values()), default=0)
        self.usage = total_usage(o.usage for o in self.outcomes)
        ks = [k for k in (1, 2, 4, 8, 16, 32, 64) if k <= self.samples]
        if self.samples and self.samples not in ks:
            ks.append(self.samples)
        #: The k of the K-sample figures: powers of two up to the samples, and the samples.
        self.ks = ks
        self._cache: dict[tuple[str, str | None, str | None, int], Estimate] = {}

    def estimate(
        self, name: str, family: str | None = None, difficulty: str | None = None, k: int = 1
    ) -> Estimate:
        """Metric ``name`` (see :data:`METRICS`) on the episodes of ``family`` / ``difficulty``."""
        key = (name, family, difficulty, k)
        if key not in self._cache:
            chosen = [
                o
                for o in self.outcomes
                if (family is None or o.family == family)
                and (difficulty is None or o.difficulty == difficulty)
            ]
            self._cache[key] = METRICS[name].compute(chosen, k)
        return self._cache[key]

    def value(
        self, name: str, family: str | None = None, difficulty: str | None = None, k: int = 1
    ) -> float | None:
        return self.estimate(name, family, difficulty, k).value


def summarize(outcomes: Sequence[Outcome]) -> Summary:
    return Summary(outcomes)
