"""The reports' intervals against independent definitions: the Wilson interval as the inverted
score test (bisection, no shared formula), its exact coverage, scipy where it is installed, and
the bootstrap against the normal approximation it converges to."""

from __future__ import annotations

import math
from statistics import NormalDist, fmean, pstdev

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.evaluation import stats

Z = NormalDist().inv_cdf(0.975)


def _score_rejects(c: int, n: int, p: float) -> bool:
    """The score test of H0: rate = p rejects at 5% (the definition Wilson inverts)."""
    if p <= 0.0 or p >= 1.0:
        return c != (0 if p <= 0.0 else n)
    return abs(c - n * p) > Z * math.sqrt(n * p * (1 - p))


def _bisect_edge(c: int, n: int, inside: float, outside: float) -> float:
    """Where the score test starts rejecting between an accepted and a rejected p."""
    for _ in range(100):
        mid = (inside + outside) / 2
        if _score_rejects(c, n, mid):
            outside = mid
        else:
            inside = mid
    return (inside + outside) / 2


counts = st.integers(1, 400).flatmap(lambda n: st.tuples(st.integers(0, n), st.just(n)))


@given(counts)
def test_wilson_is_the_inverted_score_test(cn: tuple[int, int]) -> None:
    c, n = cn
    low, high = stats.wilson(c, n)
    p = c / n
    want_low = 0.0 if c == 0 else _bisect_edge(c, n, p, 0.0)
    want_high = 1.0 if c == n else _bisect_edge(c, n, p, 1.0)
    assert low == pytest.approx(want_low, abs=1e-9)
    assert high == pytest.approx(want_high, abs=1e-9)


@given(counts)
def test_wilson_bounds_and_edges(cn: tuple[int, int]) -> None:
    c, n = cn
    low, high = stats.wilson(c, n)
    assert 0.0 <= low <= c / n <= high <= 1.0
    assert (low == 0.0) == (c == 0) and (high == 1.0) == (c == n)
    flip_low, flip_high = stats.wilson(n - c, n)  # symmetric under success <-> failure
    assert (flip_low, flip_high) == pytest.approx((1 - high, 1 - low), abs=1e-12)


@given(counts)
def test_wilson_is_monotone_in_successes_and_narrows_with_levels(cn: tuple[int, int]) -> None:
    c, n = cn
    low, high = stats.wilson(c, n)
    if c < n:
        up_low, up_high = stats.wilson(c + 1, n)
        assert up_low > low and up_high > high
    # four times the levels at the same rate: a narrower interval
    big_low, big_high = stats.wilson(4 * c, 4 * n)
    assert big_high - big_low < high - low


@pytest.mark.parametrize("n", [10, 32, 77])
def test_wilson_coverage_is_near_nominal(n: int) -> None:
    """Exact coverage averaged over true rates in [0.05, 0.95]: 95% within two points (the
    normal interval falls far short near the edges at these sizes)."""
    bounds = [stats.wilson(c, n) for c in range(n + 1)]
    covered = []
    for p in np.linspace(0.05, 0.95, 181):
        pmf = [math.comb(n, c) * p**c * (1 - p) ** (n - c) for c in range(n + 1)]
        covered.append(sum(w for w, (lo, hi) in zip(pmf, bounds, strict=True) if lo <= p <= hi))
    assert 0.93 <= fmean(covered) <= 0.97
    assert min(covered) >= 0.83  # Wilson's known worst case at small n, never a collapse


def test_wilson_matches_scipy_when_installed() -> None:
    scipy_stats = pytest.importorskip("scipy.stats")
    for c, n in [(0, 5), (1, 3), (7, 32), (32, 32), (40, 77)]:
        ci = scipy_stats.binomtest(c, n).proportion_ci(method="wilson")
        assert stats.wilson(c, n) == pytest.approx((ci.low, ci.high), abs=1e-12)


def test_wilson_rejects_impossible_counts() -> None:
    for c, n in [(0, 0), (-1, 3), (4, 3)]:
        with pytest.raises(ValueError):
            stats.wilson(c, n)
    assert stats.rate(0, 0) == stats.Estimate(None)


@settings(max_examples=30, deadline=None)
@given(st.lists(st.floats(0, 1), min_size=1, max_size=40), st.integers(0, 2**32))
def test_bootstrap_is_seeded_and_brackets_the_mean(values: list[float], seed: int) -> None:
    e = stats.level_rate(values, seed)
    assert e == stats.level_rate(values, seed)  # the same seed, the same interval
    assert e.low is not None and e.high is not None and e.value is not None
    assert min(values) - 1e-12 <= e.low <= e.value <= e.high <= max(values) + 1e-12


def test_bootstrap_approaches_the_normal_interval() -> None:
    """Many levels: the percentile interval is the mean ± z * sd / sqrt(L) (plug-in sd)."""
    rng = np.random.default_rng(7)
    values = list(rng.integers(0, 5, size=400) / 4)  # four samples per level
    low, high = stats.bootstrap(values, seed=3)
    half = Z * pstdev(values) / math.sqrt(len(values))
    assert low == pytest.approx(fmean(values) - half, abs=0.2 * half)
    assert high == pytest.approx(fmean(values) + half, abs=0.2 * half)


def test_mean_standard_error_and_edges() -> None:
    e = stats.mean([2.0, 4.0, 9.0])
    assert e.value == pytest.approx(5.0)
    assert e.stderr == pytest.approx(math.sqrt(((3**2 + 1**2 + 4**2) / 2) / 3))
    assert stats.mean([3.0]).stderr is None and stats.mean([]).value is None


def test_difference_is_newcombes_hybrid() -> None:
    a, b = stats.rate(20, 32), stats.rate(10, 32)
    d = stats.difference(a, b)
    assert d.value == pytest.approx(10 / 32)
    assert None not in (a.value, a.low, a.high, b.value, b.low, b.high, d.low, d.high)
    assert d.low == pytest.approx(
        float(d) - math.hypot(float(a) - float(a.low or 0), float(b.high or 0) - float(b))
    )
    assert float(d.low or 0) < float(d) < float(d.high or 0)
    assert stats.difference(a, stats.Estimate(None)).value is None


def test_ratio_bootstrap() -> None:
    e = stats.bootstrap_ratio([1, 0, 2, 1], [0.5, 0.5, 1.0, 0.5])
    assert e.value == pytest.approx(4 / 2.5) and e.low is not None and e.high is not None
    assert e.low <= float(e) <= e.high
    assert stats.bootstrap_ratio([1], [0.0]).value is None
