"""``chain report``: the tables come out with the numbers the runs imply, plus CSV and the plot."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import pytest

from chaingeo.cli.main import main
from chaingeo.evaluation.agents.base import AgentSpec
from chaingeo.evaluation.episode import ProtocolConfig
from chaingeo.evaluation.report.tables import find_runs, load_run, sort_value, table1
from chaingeo.evaluation.runner import RunConfig, evaluate
from tests.support.harness import FAKE, fake_levels


@pytest.fixture(scope="module")
def runs(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("runs")
    levels = fake_levels(3, pieces=2)
    cfg = RunConfig(progress=False)
    names = {lv.id: [p.name for p in lv.pieces] for lv in levels}
    # "scripted": solves L00 in 3 steps (one wasted), fails L01 and L02 (gives up at once).
    plans = {"L00": ["take nobody", *(f"take {n}" for n in names["L00"])], "L01": [], "L02": []}
    (root / "plans.json").write_text(json.dumps(plans))
    spec = AgentSpec("replay", {"file": str(root / "plans.json"), "label": "scripted"})
    evaluate(levels, spec, root / "runs" / "scripted-interactive", FAKE, cfg)
    one = ProtocolConfig(name="oneshot", env=FAKE.env)
    evaluate(levels, spec, root / "runs" / "scripted-oneshot", one, cfg)
    evaluate(levels, AgentSpec("random"), root / "runs" / "random-interactive", FAKE, cfg)
    return root


def test_table1_numbers(runs: Path) -> None:
    loaded = [load_run(p) for p in find_runs([runs / "runs"])]
    table = table1(loaded)
    rows = {r[0]: [sort_value(v) for v in r] for r in table.rows}
    scripted = rows["scripted"]
    # Puzzle (none), Stacking, All, Succ.Task, Episodes, AvgSteps, Dist2Opt, NormDist
    assert scripted[1] is None
    assert scripted[2] == pytest.approx(1 / 3) and scripted[3] == pytest.approx(1 / 3)
    assert scripted[4:9] == [1, 3, 3.0, 1.0, 0.5]
    assert rows["random"][3] == 1.0 and rows["random"][7] == 0.0
    assert "scripted (one-shot)" in rows
    # One sample per level: Wilson intervals for the rates, and the caption says so.
    stacking = next(r for r in table.rows if r[0] == "scripted")[2]
    assert (stacking.low, stacking.high) == pytest.approx((0.0615, 0.7923), abs=1e-4)
    assert "Wilson" in table.caption and "standard error" in table.caption


def test_chain_report_writes_tables_csv_and_plot(
    runs: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["report", str(runs / "runs"), "--out", str(tmp_path / "rep")]) == 0
    out = capsys.readouterr().out
    assert "### Table 1" in out
    assert "| scripted | — | 33.3 [6.1, 79.2] | 33.3 [6.1, 79.2] | 1 |" in out
    # one solved episode: its steps have no standard error; random solves all three
    assert "| 3.00 ± — | 1.00 ± — | 0.500 ± — |" in out
    assert "Uncertainty: 95% Wilson score interval" in out
    assert "Interactive vs one-shot" in out and "Stacking Easy" in out
    table = list(csv.reader(io.StringIO((tmp_path / "rep" / "table1.csv").read_text())))
    assert table[0][:5] == ["Agent", "Puzzle", "Puzzle low", "Puzzle high", "Puzzle stderr"]
    assert "NormDist stderr" in table[0] and "Solved/USD low" in table[0]
    row = dict(zip(table[0], next(r for r in table if r[0] == "scripted"), strict=True))
    assert float(row["Stacking low"]) == pytest.approx(0.0615, abs=1e-4)
    assert row["Puzzle"] == row["Puzzle low"] == "" and row["AvgSteps stderr"] == ""
    assert len(table) == 4
    png = (tmp_path / "rep" / "cost_success.png").read_bytes()
    assert png.startswith(b"\x89PNG") and len(png) > 5000
    proto = (tmp_path / "rep" / "interactive_vs_oneshot.csv").read_text().splitlines()
    assert proto[1].startswith("scripted,")


def test_chain_report_rejects_a_folder_without_runs(tmp_path: Path) -> None:
    assert main(["report", str(tmp_path)]) == 2
