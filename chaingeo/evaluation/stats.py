"""Uncertainty of the reported figures: intervals for rates, standard errors for means.

With 32 puzzle levels one level is 3.1 points of Pass@1, so a table without error bars invites
reading noise as a ranking. Every figure a report prints is an :class:`Estimate`: the value and,
where it has one, a 95% interval (rates) or a standard error (means), and the method's name, which
the table's caption repeats.

- **Wilson score interval** for a rate measured once per level (``c`` of ``n`` levels solved): the
  ``p`` whose score test ``|c - n p| <= z sqrt(n p (1 - p))`` does not reject, which stays inside
  [0, 1] and is sensible at 0/n and n/n (the normal interval collapses to a point there).
- **Bootstrap over levels** when levels have several samples (epochs): the levels are the unit
  that was sampled, so they are resampled with replacement (seeded, percentile interval); a
  level's own samples stay together.
- **Standard error of the mean**: ``s / sqrt(m)`` with ``s`` the sample standard deviation
  (``ddof = 1``); undefined (None) for fewer than two values.
- **Newcombe's hybrid score interval** for a difference of two rates, from their own intervals.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from statistics import NormalDist, fmean, stdev
from typing import Final

import numpy as np

#: Two-sided 95%: the normal quantile 0.975.
Z95: Final = NormalDist().inv_cdf(0.975)
#: Resamples of the bootstrap (the percentile bounds move by < 0.5 points between seeds at 2000).
RESAMPLES: Final = 2000
WILSON: Final = "wilson"
BOOTSTRAP: Final = "bootstrap"
STDERR: Final = "stderr"
NEWCOMBE: Final = "newcombe"
#: How each method is named in a table caption.
METHOD_TEXT: Final = {
    WILSON: "95% Wilson score interval (one sample per level)",
    BOOTSTRAP: f"95% percentile bootstrap over levels ({RESAMPLES} resamples, seeded)",
    STDERR: "± standard error of the mean",
    NEWCOMBE: "95% Newcombe hybrid score interval for a difference of rates",
}


@dataclass(frozen=True)
class Estimate:
    """A reported figure and its uncertainty: an interval ``[low, high]`` or a ``stderr``."""

    value: float | None
    low: float | None = None
    high: float | None = None
    stderr: float | None = None
    method: str | None = None

    def __float__(self) -> float:
        return math.nan if self.value is None else float(self.value)


def wilson(successes: int, n: int, z: float = Z95) -> tuple[float, float]:
    """The Wilson score interval of ``successes / n``; exactly 0 (n/n: 1) at the edge."""
    if n < 1 or not 0 <= successes <= n:
        raise ValueError(f"need n >= 1 and 0 <= successes <= n, got {successes}/{n}")
    p = successes / n
    z2 = z * z
    denom = 1.0 + z2 / n
    centre = (p + z2 / (2 * n)) / denom
    half = z * math.sqrt(p * (1 - p) / n + z2 / (4 * n * n)) / denom
    low = 0.0 if successes == 0 else max(0.0, centre - half)
    high = 1.0 if successes == n else min(1.0, centre + half)
    return low, high


def rate(successes: int, n: int) -> Estimate:
    """A rate measured once on each of ``n`` levels, with its Wilson interval."""
    if n == 0:
        return Estimate(None)
    low, high = wilson(successes, n)
    return Estimate(successes / n, low, high, method=WILSON)


def mean(values: Sequence[float]) -> Estimate:
    """The mean and its standard error (None below two values); None for no values."""
    if not values:
        return Estimate(None)
    se = stdev(values) / math.sqrt(len(values)) if len(values) > 1 else None
    return Estimate(fmean(values), stderr=se, method=STDERR)


def bootstrap(
    per_level: Sequence[float], seed: int = 0, resamples: int = RESAMPLES
) -> tuple[float, float]:
    """95% percentile interval of the mean of per-level values, levels resampled with
    replacement (``numpy`` Generator from ``SeedSequence([seed])``: the same bytes anywhere)."""
    values = np.asarray(per_level, dtype=np.float64)
    if values.size == 0:
        raise ValueError("bootstrap needs at least one level")
    rng = np.random.default_rng(np.random.SeedSequence([seed]))
    picks = rng.integers(0, values.size, size=(resamples, values.size))
    means = values[picks].mean(axis=1)
    low, high = np.quantile(means, [0.025, 0.975], method="linear")
    return float(low), float(high)


def level_rate(per_level: Sequence[float], seed: int = 0) -> Estimate:
    """The mean over levels of a per-level rate that averages several samples, with a
    bootstrap interval over levels (clipped to the values' range, as the mean is)."""
    if not per_level:
        return Estimate(None)
    low, high = bootstrap(per_level, seed)
    value = fmean(per_level)
    return Estimate(value, min(low, value), max(high, value), method=BOOTSTRAP)


def bootstrap_ratio(
    numerators: Sequence[float], denominators: Sequence[float], seed: int = 0
) -> Estimate:
    """``sum(numerators) / sum(denominators)`` over levels (solved per 1M tokens, per USD),
    with a percentile bootstrap interval over levels; None when the denominator is 0."""
    num = np.asarray(numerators, dtype=np.float64)
    den = np.asarray(denominators, dtype=np.float64)
    if num.size == 0 or den.sum() <= 0:
        return Estimate(None)
    value = float(num.sum() / den.sum())
    rng = np.random.default_rng(np.random.SeedSequence([seed]))
    picks = rng.integers(0, num.size, size=(RESAMPLES, num.size))
    sums = den[picks].sum(axis=1)
    ok = sums > 0
    if not ok.any():
        return Estimate(value)
    ratios = num[picks].sum(axis=1)[ok] / sums[ok]
    low, high = np.quantile(ratios, [0.025, 0.975], method="linear")
    return Estimate(value, min(float(low), value), max(float(high), value), method=BOOTSTRAP)


def difference(a: Estimate, b: Estimate) -> Estimate:
    """``a - b`` with Newcombe's hybrid interval built from the two rates' own intervals."""
    if a.value is None or b.value is None:
        return Estimate(None)
    d = a.value - b.value
    if a.low is None or a.high is None or b.low is None or b.high is None:
        return Estimate(d)
    low = d - math.hypot(a.value - a.low, b.high - b.value)
    high = d + math.hypot(a.high - a.value, b.value - b.low)
    return Estimate(d, low, high, method=NEWCOMBE)
