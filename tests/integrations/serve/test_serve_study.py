"""A human-baseline study run by two scripted participants over OpenEnv's client: seeded level
orders, o_i hidden, every action timed, and ``chain report`` then shows a "human" row and the
human table of solve times by tier."""

from __future__ import annotations

import asyncio
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("openenv", reason="chain serve needs the serve extra (openenv-core)")

from openenv.core.generic_client import GenericEnvClient

from chaingeo.cli.main import main
from chaingeo.core.suite import shipped_level
from chaingeo.envs.demos import plan_texts
from chaingeo.evaluation.logs import RunLog
from chaingeo.integrations.serve.environment import Catalog
from chaingeo.integrations.serve.study import Study
from tests.support.serve import running

IDS = ("puzzle-easy-07-burr3", "stacking-2x2x2-easy-s101-000000", "stacking-2x2x3-mid-s104-000002")


async def _participant(url: str, who: str, plays: list[str]) -> list[dict[str, Any]]:
    """Each level in the order the study assigns: ``solve`` plays its optimal plan, ``give
    up`` says finish at once, ``leave`` makes one move and disconnects."""
    seen = []
    for how in plays:
        async with GenericEnvClient(base_url=url) as env:
            first = (await env.reset(participant=who)).observation
            seen.append(first)
            level = shipped_level(first["level_id"])
            if how == "solve":
                for text in plan_texts(level):
                    r = await env.step({"text": text})
                assert r.done and r.observation["success"]
            elif how == "give up":
                assert (await env.step({"text": "finish"})).done
            else:
                await env.step({"text": plan_texts(level)[0]})
    return seen


def test_two_participants_make_a_human_row(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    levels = [shipped_level(i) for i in IDS]
    study = Study.create("pilot", tmp_path, levels, seed=7)
    assert [lv.id for lv in study.order("alice")] == [lv.id for lv in study.order("alice")]
    orders = {who: [lv.id for lv in study.order(who)] for who in ("alice", "bob")}
    with running(Catalog({lv.id: lv for lv in levels}, study)) as url:

        async def both() -> tuple[list[dict[str, Any]], list[dict[str, Any]]]:
            return await asyncio.gather(
                _participant(url, "alice", ["solve"] * 3),
                _participant(url, "bob", ["solve", "give up", "leave"]),
            )

        alice, bob = asyncio.run(both())
    assert [o["level_id"] for o in alice] == orders["alice"]
    assert [o["level_id"] for o in bob] == orders["bob"]
    assert all(o["optimal_steps"] is None for o in alice + bob)

    records = RunLog(tmp_path / "pilot").records()
    assert len(records) == 6 and {r["participant"] for r in records} == {"alice", "bob"}
    assert sum(r["success"] for r in records) == 4
    assert all(r["agent"] == "human" and r["status"] == "done" for r in records)
    for r in records:
        times = [s["t"] for s in r["steps"]]
        assert times == sorted(times) and len(times) == r["steps_used"]
    study.close()  # the server stopped: its folder is free
    again = Study.create("pilot", tmp_path, levels, seed=7)  # a restarted server resumes
    with pytest.raises(Exception, match="every level"):
        again.next_level("alice")
    assert again.next_level("carol").id == again.order("carol")[0].id
    again.close()

    assert main(["report", str(tmp_path / "pilot"), "--out", str(tmp_path / "report")]) == 0
    out = capsys.readouterr().out
    row = next(line for line in out.splitlines() if line.startswith("| human |"))
    assert "| 66.7 [" in row  # Pass@1 over all six episodes, with its interval
    # two participants per level: the interval is a bootstrap over the three levels, the
    # run's own Pass@1 estimate (chaingeo.evaluation.metrics), named in the table's caption
    human = next(line for line in out.splitlines() if line.startswith("| human | all |"))
    assert "| 6 | 66.7 [50.0, 100.0] |" in human
    assert "Human baseline" in out and (tmp_path / "report" / "human.md").exists()
    head = (tmp_path / "report" / "human.csv").read_text().splitlines()[0].split(",")
    assert {"< 5 min % low", "< 5 min % high"} <= set(head)  # a share is a rate: its interval
