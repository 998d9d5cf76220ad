"""``chain bench serve``: served and in-process episodes agree step for step; a smoke run (slow)."""

from __future__ import annotations

import argparse

import pytest

pytest.importorskip("openenv", reason="chain bench serve needs the serve extra (openenv-core)")

from chaingeo.benchmarks import serve as bench
from chaingeo.core.suite import shipped_level
from chaingeo.integrations.serve.environment import Catalog
from tests.support.serve import running


def test_served_episodes_take_the_steps_in_process_ones_take() -> None:
    """Both policies play the same seeded episodes on either side: the same step counts (the
    oracle's are the levels' o_i), so the ratio compares like with like."""
    catalog = Catalog({i: shipped_level(i) for i in bench.LEVELS})
    with running(catalog) as url:
        for policy in bench.POLICIES:
            here = bench.in_process(policy, 4)
            there = bench.served(url, policy, 4, 2)
            assert here.steps == there.steps == len(there.latencies) > 0
    oracle = sum(lv.optimal_steps for lv, _ in bench._tasks(4))
    assert bench.in_process("oracle", 4).steps == oracle


@pytest.mark.slow
def test_bench_serve_quick_runs(capsys: pytest.CaptureFixture[str]) -> None:
    assert bench.run(argparse.Namespace(quick=True, repeat=1)) == 0
    out = capsys.readouterr().out
    assert out.count("in-process") == 3 and out.count("x4") == 2
