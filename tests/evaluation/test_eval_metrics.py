"""The paper's metrics on hand-made trajectories whose answers are worked out by hand."""

from __future__ import annotations

import itertools
import json
import statistics
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from chaingeo.evaluation import metrics as m
from chaingeo.evaluation.episode import Outcome
from chaingeo.evaluation.stats import Estimate
from chaingeo.evaluation.usage import Price, PriceError, PriceTable, Usage, UsageError, total_usage

U = Usage(input_tokens=1000, output_tokens=500, calls=1)


def _o(level: str, fam: str, diff: str, opt: int, ok: bool, steps: int, sample: int) -> Outcome:
    return Outcome(level, fam, diff, opt, ok, steps, sample, U, 0.01)


# Level A (stacking easy, o=4): solved in 6, then failed at the 30-step budget.
# Level B (puzzle mid, o=5): failed twice.
# Level C (stacking hard, o=8): solved in 8 and in 10.
RUN = [
    _o("A", "stacking", "easy", 4, True, 6, 0),
    _o("A", "stacking", "easy", 4, False, 30, 1),
    _o("B", "puzzle", "mid", 5, False, 30, 0),
    _o("B", "puzzle", "mid", 5, False, 30, 1),
    _o("C", "stacking", "hard", 8, True, 8, 0),
    _o("C", "stacking", "hard", 8, True, 10, 1),
]


def test_success_metrics_by_hand() -> None:
    assert m.pass_at_1(RUN) == pytest.approx((1 / 2 + 0 + 1) / 3)
    assert m.pass_at_k(RUN, 2) == pytest.approx(2 / 3)  # A: 1, B: 0, C: 1
    assert m.avg_at_k(RUN, 1) == pytest.approx(2 / 3)  # first samples: A yes, B no, C yes
    assert m.avg_at_k(RUN, 2) == pytest.approx(0.5)
    assert m.pass_at_1(m.by_family(RUN, "puzzle")) == 0.0
    assert m.pass_at_1(m.by_family(RUN, "stacking")) == pytest.approx(0.75)
    assert m.succ_task(RUN) == 3


def test_step_metrics_by_hand() -> None:
    assert m.avg_steps_solved(RUN) == pytest.approx((6 + 8 + 10) / 3)
    assert m.dist_to_opt(RUN) == pytest.approx((2 + 0 + 2) / 3)
    assert m.norm_dist(RUN) == pytest.approx((2 / 4 + 0 / 8 + 2 / 8) / 3)


def test_norm_dist_uses_max_one_for_a_zero_step_optimum() -> None:
    run = [_o("Z", "puzzle", "easy", 0, True, 3, 0), _o("Y", "puzzle", "easy", 2, True, 3, 0)]
    assert m.norm_dist(run) == pytest.approx((3 / 1 + 1 / 2) / 2)
    assert m.dist_to_opt(run) == pytest.approx((3 + 1) / 2)


def test_efficiency_metrics_by_hand() -> None:
    # 6 episodes x 1500 tokens = 9000 tokens; 6 x $0.01 = $0.06; 3 solved.
    assert m.solved_per_million_tokens(RUN) == pytest.approx(3 / 0.009)
    assert m.solved_per_usd(RUN) == pytest.approx(3 / 0.06)
    free = [Outcome("A", "stacking", "easy", 4, True, 4)]
    assert m.solved_per_million_tokens(free) is None
    assert m.solved_per_usd(free) is None
    unknown = [*RUN[:1], Outcome("B", "puzzle", "mid", 5, False, 30, 0, U, None)]
    assert m.run_cost(unknown) is None and m.solved_per_usd(unknown) is None


def test_nothing_solved_gives_none_not_zero() -> None:
    run = [RUN[2], RUN[3]]
    assert m.avg_steps_solved(run) is None
    assert m.dist_to_opt(run) is None
    assert m.norm_dist(run) is None
    assert m.pass_at_1([]) is None


def test_summary_row() -> None:
    s = m.summarize(RUN)
    assert (s.episodes, s.levels, s.samples, s.value("succ_task")) == (6, 3, 2, 3)
    assert s.value("pass@1", "stacking", "easy") == pytest.approx(0.5)
    assert s.value("pass@1", "stacking", "hard") == 1.0
    assert s.value("pass@1", "puzzle", "mid") == 0.0
    assert s.value("pass@1", "puzzle", "hard") is None
    assert s.ks == [1, 2] and s.value("pass@k", k=2) == pytest.approx(2 / 3)
    assert s.value("pass^k", k=2) == pytest.approx(1 / 3)  # only C solves both samples
    assert s.usage == Usage(6000, 3000, 0, 0, 6)
    assert s.value("cost_usd") == pytest.approx(0.06)
    # Two samples per level: Pass@1's interval is a bootstrap over the three levels, so it
    # lies within the smallest and largest level's rate; the step means carry a stderr.
    p1 = s.estimate("pass@1")
    assert p1.method == "bootstrap" and 0.0 <= p1.low <= p1.value <= p1.high <= 1.0  # type: ignore[operator]
    steps = s.estimate("avg_steps")
    assert steps.stderr == pytest.approx(statistics.stdev([6, 8, 10]) / 3**0.5)


def test_registry_gives_every_metric_once_with_a_direction() -> None:
    assert {"pass@1", "avg_steps", "dist2opt", "normdist", "pass@k", "pass^k", "avg@k"} <= set(
        m.METRICS
    )
    assert m.METRICS["normdist"].better == "lower" and m.METRICS["pass@1"].better == "higher"
    with pytest.raises(ValueError, match="twice"):
        m.register_metric("pass@1", "again", "rate", "higher")(lambda o, k: Estimate(None))


@given(st.integers(1, 8).flatmap(lambda n: st.tuples(st.just(n), st.integers(0, n))), st.data())
def test_unbiased_pass_hat_k_equals_exhaustive_subsets(
    nc: tuple[int, int], data: st.DataObject
) -> None:
    n, c = nc
    k = data.draw(st.integers(1, n))
    outcomes = [True] * c + [False] * (n - c)
    subsets = list(itertools.combinations(range(n), k))
    exact = sum(all(outcomes[i] for i in s) for s in subsets) / len(subsets)
    assert m.pass_hat_k_unbiased(n, c, k) == pytest.approx(exact)


def test_duplicate_samples_and_short_levels_are_errors() -> None:
    with pytest.raises(ValueError, match="twice"):
        m.pass_at_1([RUN[0], RUN[0]])
    with pytest.raises(ValueError, match="needs 2 samples"):
        m.avg_at_k([RUN[0]], 2)
    with pytest.raises(ValueError):
        m.pass_at_k_unbiased(3, 1, 4)


@given(st.integers(1, 8).flatmap(lambda n: st.tuples(st.just(n), st.integers(0, n))), st.data())
def test_unbiased_pass_at_k_equals_exhaustive_subsets(
    nc: tuple[int, int], data: st.DataObject
) -> None:
    n, c = nc
    k = data.draw(st.integers(1, n))
    outcomes = [True] * c + [False] * (n - c)
    subsets = list(itertools.combinations(range(n), k))
    exact = sum(any(outcomes[i] for i in s) for s in subsets) / len(subsets)
    assert m.pass_at_k_unbiased(n, c, k) == pytest.approx(exact)


def test_usage_is_additive_and_reads_openai_blocks() -> None:
    block = {
        "prompt_tokens": 120,
        "completion_tokens": 80,
        "completion_tokens_details": {"reasoning_tokens": 50},
        "prompt_tokens_details": {"cached_tokens": 100},
    }
    u = Usage.from_openai(block)
    assert u == Usage(120, 80, 50, 100, 1)
    assert total_usage([u, u, Usage()]) == Usage(240, 160, 100, 200, 2)
    assert Usage.from_json(json.loads(json.dumps(u.to_json()))) == u
    assert Usage.from_openai(None) == Usage(calls=1)
    assert Usage.from_openai({"prompt_tokens": 12.0}) == Usage(12, calls=1)  # whole, as a float
    for bad in ({"prompt_tokens": "x"}, {"completion_tokens": -3}, {"prompt_tokens": 2.5}, [1]):
        with pytest.raises(UsageError):  # a server fault, never a silent zero
            Usage.from_openai(bad)  # type: ignore[arg-type]


def test_prices_come_from_the_data_file_and_user_files_win(tmp_path: Path) -> None:
    table = PriceTable.load()
    assert table.get("gpt-4o") is not None and table.get("openai/gpt-4o") == table.get("gpt-4o")
    assert table.cost("no-such-model", U) is None
    assert table.cost("no-such-model", Usage()) == 0.0
    mine = tmp_path / "p.json"
    mine.write_text(
        json.dumps(
            {"models": {"gpt-4o": {"input": 1, "output": 2}, "m": {"input": 0, "output": 4}}}
        )
    )
    table = PriceTable.load(mine)
    assert table.get("gpt-4o") == Price(1.0, 2.0, None)
    # 1000 fresh input at $0/M + 500 output at $4/M
    assert table.cost("m", U) == pytest.approx(0.002)
    # cached input billed at the cached rate; reasoning is inside output
    p = Price(input=2.0, output=10.0, cached_input=0.5)
    assert p.cost(Usage(1_000_000, 1_000_000, 400_000, 400_000, 1)) == pytest.approx(
        0.6 * 2.0 + 0.4 * 0.5 + 10.0
    )
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"models": {"x": {"input": -1, "output": 1}}}))
    with pytest.raises(PriceError, match=r"models\.x\.input"):
        PriceTable.load(bad)
