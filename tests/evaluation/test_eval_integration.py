"""The harness on the real environments: baselines, the model agent, ``chain eval`` end to end."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from tests.support.paths import ROOT

pytest.importorskip("chaingeo.envs.machines.state")
pytest.importorskip("chaingeo.envs.observation")

from chaingeo.cli.main import main
from chaingeo.core.colors import assign_colors
from chaingeo.core.geometry import Shape, puzzle_signature
from chaingeo.core.kinematics import Move
from chaingeo.core.level import (
    Level,
    Piece,
    Provenance,
    PuzzleSolution,
    load_levels,
    revalidate,
    save_level,
    stacking_level,
)
from chaingeo.core.rules import PuzzleRules
from chaingeo.evaluation.agents.base import AgentSpec
from chaingeo.evaluation.agents.baselines import oracle_plan
from chaingeo.evaluation.episode import ProtocolConfig
from chaingeo.evaluation.play import EpisodeTask, run_episode
from chaingeo.evaluation.runner import RunConfig, evaluate
from tests.support.fake_openai import Script, fake_openai, reply


def _bars(level_id: str, n: int) -> Level:
    """n bars of two cells stacked along y: taking them apart needs n - 1 removals."""
    colors = assign_colors(n)
    shapes = [Shape([(0, i, 0), (1, i, 0)]) for i in range(n)]
    names = [c.name for c in colors]
    moves = tuple(Move((names[i],), "+y", None) for i in range(n - 1, 0, -1))
    level = Level(
        id=level_id,
        family="puzzle",
        difficulty="easy",
        goal="disassemble",
        box=None,
        pieces=tuple(Piece(c.name, c.hex, s) for c, s in zip(colors, shapes, strict=True)),
        solution=PuzzleSolution(moves),
        optimal_steps=n - 1,
        max_steps=30,
        rules=PuzzleRules(),
        provenance=Provenance("test", "1", None, None, puzzle_signature(shapes)),
    )
    return revalidate(level)


def _suite() -> list[Level]:
    dominoes = [
        Shape([(0, 0, 0), (1, 0, 0)]),
        Shape([(0, 1, 0), (1, 1, 0)]),
        Shape([(0, 0, 1), (0, 1, 1)]),
        Shape([(1, 0, 1), (1, 1, 1)]),
    ]
    ell = [Shape([(0, 0, 0), (1, 0, 0), (0, 1, 0)]), Shape([(1, 1, 0), (2, 1, 0), (2, 0, 0)])]
    return [
        stacking_level("s-dominoes", "easy", (2, 2, 2), dominoes),
        stacking_level("s-ells", "mid", (3, 2, 1), ell),
        _bars("p-bars2", 2),
        _bars("p-bars3", 3),
    ]


def _shipped() -> list[Level]:
    folder = ROOT / "levels"
    return load_levels(folder) if any(folder.rglob("*.json")) else []


def _oracle_cases() -> list[object]:
    """Both protocols over the test levels and every eighth shipped level; every shipped level
    under ``slow`` (each one's plan is replayed as agent text by default in
    tests/conformance/test_conformance.py; the harness runs the same code for all)."""
    shipped = _shipped()
    some = _suite() + shipped[::8]
    rest = [lv for i, lv in enumerate(shipped) if i % 8]
    return [
        case
        for protocol in ("interactive", "oneshot")
        for case in (
            pytest.param(protocol, some, id=f"{protocol}-some"),
            pytest.param(protocol, rest, id=f"{protocol}-rest", marks=pytest.mark.slow),
        )
    ]


@pytest.mark.parametrize(("protocol", "levels"), _oracle_cases())
def test_oracle_solves_every_level_in_exactly_optimal_steps(
    protocol: str, levels: list[Level]
) -> None:
    for level in levels:
        task = EpisodeTask(level, 0, 0, AgentSpec("oracle"), ProtocolConfig(name=protocol))  # type: ignore[arg-type]
        rec = run_episode(task).record
        assert rec["success"], level.id
        assert rec["steps_used"] == level.optimal_steps, level.id


def test_baselines_on_real_levels_are_seeded(tmp_path: Path) -> None:
    levels = _suite()
    for agent in ("random", "greedy"):
        runs = []
        for name in ("a", "b"):
            evaluate(
                levels,
                AgentSpec(agent),
                tmp_path / f"{agent}-{name}",
                config=RunConfig(seed=2, progress=False),
            )
            lines = (tmp_path / f"{agent}-{name}" / "episodes.jsonl").read_text().splitlines()
            runs.append(
                sorted(
                    (json.loads(x)["key"], [s["sent"] for s in json.loads(x)["steps"]])
                    for x in lines
                )
            )
        assert runs[0] == runs[1]
    greedy = [
        json.loads(x) for x in (tmp_path / "greedy-a" / "episodes.jsonl").read_text().splitlines()
    ]
    assert all(r["success"] for r in greedy)  # these small levels are easy for one-step lookahead


def test_model_agent_on_a_real_level_sees_real_views(tmp_path: Path) -> None:
    level = _suite()[0]
    script = Script([reply(f"<action>{a}</action>") for a in oracle_plan(level)])
    with fake_openai(script) as url:
        spec = AgentSpec("openai", {"model": "m", "base_url": url, "backoff_base": 0.01})
        out = evaluate([level], spec, tmp_path / "run", config=RunConfig(progress=False))
    assert script.problems == []
    assert [o.steps for o in out] == [level.optimal_steps] and out[0].success
    parts = script.requests[0]["body"]["messages"][1]["content"]
    assert sum(p["type"] == "image_url" for p in parts) >= 4
    rec = json.loads((tmp_path / "run" / "episodes.jsonl").read_text())
    for name in rec["steps"][0]["images"].values():
        assert (tmp_path / "run" / "images" / name).read_bytes().startswith(b"\x89PNG")


def test_chain_eval_end_to_end(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    suite = tmp_path / "levels"
    for level in _suite():
        save_level(level, suite / f"{level.id}.json")
    out = tmp_path / "runs"
    assert main(["eval", "--levels", str(suite), "--out", str(out), "--no-progress"]) == 0
    text = capsys.readouterr().out
    full = r"100\.0 \[\d+\.\d, 100\.0\]"  # all solved, with its 95% interval
    assert re.search(rf"\| oracle \| {full} \| {full} \| {full} \| 4 \| 4 \| ", text)
    # (and each run's lock file, .NAME.lock, beside it)
    assert sorted(p.name for p in out.iterdir() if not p.name.endswith(".lock")) == [
        "greedy-interactive",
        "oracle-interactive",
        "random-interactive",
    ]
    # Running again into the same folder needs --resume, which then has nothing left to do.
    assert main(["eval", "--levels", str(suite), "--out", str(out), "--no-progress"]) == 2
    assert (
        main(["eval", "--levels", str(suite), "--out", str(out), "--no-progress", "--resume"]) == 0
    )
    lines = (out / "oracle-interactive" / "episodes.jsonl").read_text().splitlines()
    assert len(lines) == 4

    level = _suite()[2]
    script = Script([reply(f"<action>{a}</action>") for a in oracle_plan(level)] * 2)
    with fake_openai(script) as url:
        args = ["eval", "--levels", str(suite / f"{level.id}.json"), "--agent", "openai"]
        args += [
            "--model",
            "fake",
            "--base-url",
            url,
            "--out",
            str(tmp_path / "m"),
            "--no-progress",
        ]
        args += ["--protocol", "both"]
        assert main(args) == 0
    assert script.problems == []
    assert "| fake | 100.0 [20.7, 100.0] | — | 100.0 [20.7, 100.0] | 1 |" in capsys.readouterr().out
