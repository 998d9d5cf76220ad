"""The runner: determinism, parallel jobs, kill-and-resume, one-shot, selection, command agents."""

from __future__ import annotations

import dataclasses
import io
import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from chaingeo.evaluation.agents.base import Agent, AgentSpec, Reply, Turn
from chaingeo.evaluation.agents.registry import AGENTS
from chaingeo.evaluation.episode import ProtocolConfig
from chaingeo.evaluation.logs import RunError
from chaingeo.evaluation.runner import RunConfig, evaluate
from tests.support.harness import FAKE, fake_levels
from tests.support.paths import ROOT


def _records(run: Path) -> dict[str, dict[str, Any]]:
    out = {}
    for line in (run / "episodes.jsonl").read_text().splitlines():
        rec = json.loads(line)
        rec.pop("wall_seconds")
        assert rec["key"] not in out, f"{rec['key']} recorded twice"
        out[rec["key"]] = rec
    return out


def test_what_evaluate_returns_is_the_run_read_back(tmp_path: Path) -> None:
    """``chain eval`` reports from the returned outcomes and header, never rereading the run:
    they must say what the run directory says (row name, outcomes, errors, tool notes)."""
    from chaingeo.evaluation.report.tables import load_run, run_of

    spec = AgentSpec("random", {"label": "rand"})
    proto = dataclasses.replace(FAKE, candidates=2, judge="vote")
    got = evaluate(fake_levels(2), spec, tmp_path / "r", proto, RunConfig(progress=False))
    back = load_run(tmp_path / "r")
    ours = run_of(tmp_path / "r", got.header, got)
    assert (ours.name, ours.outcomes, ours.errors) == (back.name, back.outcomes, back.errors)
    assert ours.name == "rand (best of 2, vote)"
    assert got.tools_refused == []


def test_seeded_runs_repeat_and_parallel_jobs_agree(tmp_path: Path) -> None:
    levels = fake_levels(3)
    cfg = RunConfig(samples=2, seed=5, progress=False)
    evaluate(levels, AgentSpec("random"), tmp_path / "a", FAKE, cfg)
    evaluate(levels, AgentSpec("random"), tmp_path / "b", FAKE, cfg)
    evaluate(
        levels,
        AgentSpec("random"),
        tmp_path / "c",
        FAKE,
        RunConfig(samples=2, seed=5, jobs=2, progress=False),
    )
    a, b, c = (_records(tmp_path / x) for x in "abc")
    assert a == b == c
    assert len(a) == 6
    # different samples draw different orders
    orders = {tuple(s["action"] for s in r["steps"]) for r in a.values()}
    assert len(orders) > 1
    evaluate(levels, AgentSpec("random"), tmp_path / "d", FAKE, RunConfig(seed=6, progress=False))
    assert {k: r["seed"] for k, r in _records(tmp_path / "d").items()} != {
        k: r["seed"] for k, r in a.items() if k.endswith("#0")
    }


KILL_SCRIPT = """
import sys
from pathlib import Path
sys.path.insert(0, {root!r})
from chaingeo.evaluation.agents.base import AgentSpec
from chaingeo.evaluation.runner import RunConfig, evaluate
from tests.support.harness import FAKE, fake_levels
evaluate(fake_levels(8), AgentSpec("random"), Path({run!r}), FAKE,
         RunConfig(samples=2, seed=1, progress=False, resume={resume}))
"""


def test_a_killed_run_resumes_with_no_episode_lost_or_run_twice(tmp_path: Path) -> None:
    run = tmp_path / "run"
    script = tmp_path / "go.py"
    script.write_text(KILL_SCRIPT.format(root=str(ROOT), run=str(run), resume=False))
    env = dict(os.environ, FAKE_ENV_DELAY="0.03")
    proc = subprocess.Popen([sys.executable, str(script)], env=env, start_new_session=True)
    deadline = time.monotonic() + 60
    episodes = run / "episodes.jsonl"
    while time.monotonic() < deadline:
        if episodes.exists() and episodes.read_text().count("\n") >= 3:
            break
        time.sleep(0.02)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    done_before = len(_records(run))
    assert 3 <= done_before < 16, "the run must be killed part way"
    evaluate(
        fake_levels(8),
        AgentSpec("random"),
        run,
        FAKE,
        RunConfig(samples=2, seed=1, progress=False, resume=True),
    )
    resumed = _records(run)
    assert len(resumed) == 16
    evaluate(
        fake_levels(8),
        AgentSpec("random"),
        tmp_path / "whole",
        FAKE,
        RunConfig(samples=2, seed=1, progress=False),
    )
    assert resumed == _records(tmp_path / "whole")


def test_resuming_with_another_level_set_is_refused(tmp_path: Path) -> None:
    evaluate(fake_levels(2), AgentSpec("random"), tmp_path / "r", FAKE, RunConfig(progress=False))
    with pytest.raises(RunError, match="level_set_hash differs"):
        evaluate(
            fake_levels(3),
            AgentSpec("random"),
            tmp_path / "r",
            FAKE,
            RunConfig(progress=False, resume=True),
        )


def test_oneshot_runs_the_plan_open_loop(tmp_path: Path) -> None:
    (level,) = fake_levels(1, pieces=3)
    names = [p.name for p in level.pieces]
    plans = tmp_path / "plans.json"
    plans.write_text(
        json.dumps(
            {
                level.id: [
                    f"take {names[0]}",
                    "take nobody",
                    f"take {names[0]}",
                    f"take {names[1]}",
                    f"take {names[2]}",
                    f"take {names[0]}",
                ]
            }
        )
    )
    proto = ProtocolConfig(name="oneshot", env=FAKE.env)
    evaluate(
        [level],
        AgentSpec("replay", {"file": str(plans)}),
        tmp_path / "o",
        proto,
        RunConfig(progress=False),
    )
    (rec,) = _records(tmp_path / "o").values()
    # two failed actions cost their steps; the plan stops once the level is solved
    assert rec["success"] and rec["steps_used"] == 5 and rec["invalid"] == 2
    assert rec["protocol"] == "oneshot" and len(rec["plan"]["actions"]) == 6


class _Picky(Agent):
    """Candidate 0 proposes an illegal action, candidate 1 a legal one."""

    name = "picky"
    needs_state = True
    uses_images = False

    def act(self, turn: Turn) -> Reply:
        assert turn.state is not None
        if turn.candidate == 0:
            return Reply("<action>take nobody</action>", "take nobody")
        text = turn.state.legal_actions()[0].to_text()
        return Reply(text, text)


@pytest.fixture
def picky() -> Iterator[None]:
    with AGENTS.registered("picky", lambda spec: _Picky()):
        yield


def test_verifier_selection_commits_a_checked_candidate(tmp_path: Path, picky: None) -> None:
    (level,) = fake_levels(1, pieces=3)
    for judge in ("first", "vote", "progress"):
        proto = ProtocolConfig(candidates=3, judge=judge, env=FAKE.env)
        evaluate([level], AgentSpec("picky"), tmp_path / judge, proto, RunConfig(progress=False))
        (rec,) = _records(tmp_path / judge).values()
        assert rec["success"] and rec["steps_used"] == 3 and rec["invalid"] == 0
        cands = rec["steps"][0]["candidates"]
        assert [c["legal"] for c in cands] == [False, True, True]
        assert [c["chosen"] for c in cands] == [False, True, False]
    # without selection the illegal first candidate costs steps
    evaluate([level], AgentSpec("picky"), tmp_path / "plain", FAKE, RunConfig(progress=False))
    (rec,) = _records(tmp_path / "plain").values()
    assert not rec["success"] and rec["steps_used"] == level.max_steps


AGENT_PROGRAM = textwrap.dedent(
    """
    import json, sys
    names = []
    for line in sys.stdin:
        msg = json.loads(line)
        if msg["type"] == "start":
            names = list(msg["level"]["pieces"])
        elif msg["type"] == "turn":
            assert all(open(p, "rb").read(4) == b"\\x89PNG" for p in msg["images"].values())
            if msg["mode"] == "plan":
                print(json.dumps({"actions": ["take " + n for n in names]}), flush=True)
            elif msg["turn"] == 0:
                print("not json", flush=True)
            else:
                print(json.dumps({"action": "take " + names[msg["turn"] - 1],
                                  "usage": {"input_tokens": 7, "output_tokens": 3}}), flush=True)
        else:
            break
    """
)


def test_command_agent_speaks_json_lines(tmp_path: Path) -> None:
    prog = tmp_path / "agent.py"
    prog.write_text(AGENT_PROGRAM)
    spec = AgentSpec("command", {"command": f"{sys.executable} {prog}", "timeout": 20})
    levels = fake_levels(1, pieces=2)
    evaluate(levels, spec, tmp_path / "i", FAKE, RunConfig(progress=False))
    (rec,) = _records(tmp_path / "i").values()
    assert rec["success"] and rec["steps_used"] == 3 and rec["invalid"] == 1
    assert rec["usage"]["input_tokens"] == 14
    proto = ProtocolConfig(name="oneshot", env=FAKE.env)
    evaluate(levels, spec, tmp_path / "o", proto, RunConfig(progress=False))
    (rec,) = _records(tmp_path / "o").values()
    assert rec["success"] and rec["steps_used"] == 2


def test_a_program_that_dies_is_an_episode_error(tmp_path: Path) -> None:
    spec = AgentSpec("command", {"command": f"{sys.executable} -c pass", "timeout": 20})
    evaluate(fake_levels(1), spec, tmp_path / "x", FAKE, RunConfig(progress=False))
    (rec,) = _records(tmp_path / "x").values()
    assert rec["status"] == "error" and "exited" in rec["error"]


def test_dask_runs_the_same_episodes(tmp_path: Path) -> None:
    distributed = pytest.importorskip("distributed")
    levels = fake_levels(2)
    cfg = RunConfig(samples=2, seed=3, progress=False)
    evaluate(levels, AgentSpec("random"), tmp_path / "local", FAKE, cfg)
    with distributed.LocalCluster(
        n_workers=1, processes=False, threads_per_worker=2, dashboard_address=None
    ) as cluster:
        dcfg = RunConfig(samples=2, seed=3, progress=False, dask=cluster.scheduler_address)
        evaluate(levels, AgentSpec("random"), tmp_path / "dask", FAKE, dcfg)
    assert _records(tmp_path / "dask") == _records(tmp_path / "local")


def test_replaying_a_run_reproduces_it(tmp_path: Path) -> None:
    levels = fake_levels(3)
    cfg = RunConfig(samples=2, seed=4, progress=False)
    evaluate(levels, AgentSpec("random"), tmp_path / "orig", FAKE, cfg)
    spec = AgentSpec("replay", {"file": str(tmp_path / "orig")})
    evaluate(levels, spec, tmp_path / "again", FAKE, cfg)
    orig, again = _records(tmp_path / "orig"), _records(tmp_path / "again")
    assert {k: [s["sent"] for s in r["steps"]] for k, r in orig.items()} == {
        k: [s["sent"] for s in r["steps"]] for k, r in again.items()
    }
    assert {k: r["success"] for k, r in orig.items()} == {k: r["success"] for k, r in again.items()}


def test_bad_agent_options_fail_before_anything_is_written(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="needs a model"):
        evaluate(
            fake_levels(1), AgentSpec("openai"), tmp_path / "r", FAKE, RunConfig(progress=False)
        )
    with pytest.raises(ValueError, match="unknown agent"):
        evaluate(
            fake_levels(1), AgentSpec("nobody"), tmp_path / "r", FAKE, RunConfig(progress=False)
        )
    assert not (tmp_path / "r").exists()


def test_progress_off_a_terminal_is_one_line_per_episode_then_the_totals(tmp_path: Path) -> None:
    stream = io.StringIO()  # not a terminal: a log file, CI
    evaluate(
        fake_levels(3), AgentSpec("random"), tmp_path / "p", FAKE, RunConfig(seed=2), stream=stream
    )
    lines = stream.getvalue().splitlines()
    assert len(lines) == 4
    for i, line in enumerate(lines[:3]):
        assert line.startswith(f"[random] {i + 1}/3 | solved ")
        assert line.endswith(("solved", "unsolved", "error"))
    assert lines[3].startswith("[random] 3/3 | solved ")
