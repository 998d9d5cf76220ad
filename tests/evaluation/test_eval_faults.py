"""Hostile input to the harness: agents and environments that raise, workers that die, servers
that refuse the key or keep failing, and a run killed while its workers play."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from chaingeo.evaluation.agents.base import Agent, AgentSpec, AuthenticationError, Reply, Turn
from chaingeo.evaluation.agents.registry import AGENTS
from chaingeo.evaluation.episode import ProtocolConfig
from chaingeo.evaluation.runner import RunConfig, evaluate
from tests.support.fake_openai import Script, fake_openai
from tests.support.harness import (
    FAKE,
    chain_eval,
    fake_levels,
    openai_args,
    suite_folder,
)
from tests.support.paths import ROOT

FAULTY = ProtocolConfig(env="tests.support.faulty_env")
SECRET = "sk-test-do-not-log-0123456789"


def _records(run: Path) -> dict[str, dict[str, Any]]:
    out: dict[str, dict[str, Any]] = {}
    for line in (run / "episodes.jsonl").read_text().splitlines():
        rec = json.loads(line)
        assert rec["key"] not in out, f"{rec['key']} recorded twice"
        out[rec["key"]] = rec
    return out


class _Raising(Agent):
    """Plays ``take`` actions, but raises on the level named in its options."""

    name = "raising"
    model = "raising"

    def __init__(self, options: dict[str, Any]) -> None:
        self.options = options

    def act(self, turn: Turn) -> Reply:
        if turn.level.id == self.options.get("level", "L01"):
            kind = self.options.get("kind", "overflow")
            if kind == "overflow":
                raise OverflowError(f"int too large to convert {SECRET}")
            if kind == "recursion":
                return self.act(turn)
        piece = turn.level.pieces[turn.index % len(turn.level.pieces)].name
        return Reply(f"take {piece}", f"take {piece}")


@pytest.fixture
def raising_agent() -> Iterator[None]:
    with AGENTS.registered("raising", lambda spec: _Raising(dict(spec.options))):
        yield


@pytest.mark.parametrize("kind", ["overflow", "recursion"])
def test_an_agent_that_raises_is_one_errored_episode(
    tmp_path: Path, raising_agent: None, kind: str
) -> None:
    spec = AgentSpec("raising", {"kind": kind}, {"api_key": SECRET})
    cfg = RunConfig(samples=2, progress=False)
    outcomes = evaluate(fake_levels(3), spec, tmp_path / "r", FAKE, cfg)
    recs = _records(tmp_path / "r")
    assert len(outcomes) == len(recs) == 6
    expected = "OverflowError" if kind == "overflow" else "RecursionError"
    for key, rec in recs.items():
        if key.startswith("L01"):
            assert rec["status"] == "error" and rec["error_type"] == expected
            assert rec["error"].startswith(expected + ": ")
            assert "Traceback" not in rec["error"] and len(rec["error"]) <= 500
        else:
            assert rec["status"] == "done" and rec["success"], rec
    text = (tmp_path / "r" / "episodes.jsonl").read_text()
    assert SECRET not in text and "Traceback" not in text
    # --resume continues past the errors; --retry-errors plays them again (and they fail again)
    resume = RunConfig(samples=2, progress=False, resume=True)
    evaluate(fake_levels(3), spec, tmp_path / "r", FAKE, resume)
    assert len((tmp_path / "r" / "episodes.jsonl").read_text().splitlines()) == 6
    evaluate(
        fake_levels(3),
        spec,
        tmp_path / "r",
        FAKE,
        RunConfig(samples=2, progress=False, resume=True, retry_errors=True),
    )
    lines = (tmp_path / "r" / "episodes.jsonl").read_text().splitlines()
    assert len(lines) == 8 and all(json.loads(x)["key"].startswith("L01") for x in lines[6:])


def test_an_environment_that_raises_in_a_worker_is_an_errored_episode(tmp_path: Path) -> None:
    cfg = RunConfig(samples=1, jobs=2, progress=False)
    evaluate(fake_levels(4), AgentSpec("random"), tmp_path / "r", FAULTY, cfg)
    recs = _records(tmp_path / "r")
    assert sorted(recs) == ["L00#0", "L01#0", "L02#0", "L03#0"]
    assert recs["L01#0"]["error_type"] == "ZeroDivisionError"
    assert recs["L01#0"]["error"] == "ZeroDivisionError: the environment divided by zero"
    assert recs["L02#0"]["error_type"] == "RecursionError"
    assert recs["L00#0"]["status"] == recs["L03#0"]["status"] == "done"
    evaluate(fake_levels(4), AgentSpec("random"), tmp_path / "r", FAULTY, RunConfig(resume=True))
    assert len(_records(tmp_path / "r")) == 4


def test_a_worker_that_dies_under_its_episode_does_not_stop_the_run(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("FAULTY_ENV_DIE", "1")
    cfg = RunConfig(samples=1, jobs=2, progress=False)
    evaluate(fake_levels(4), AgentSpec("random"), tmp_path / "r", FAULTY, cfg)
    recs = _records(tmp_path / "r")
    assert sorted(recs) == ["L00#0", "L01#0", "L02#0", "L03#0"]
    assert recs["L03#0"]["status"] == "error"
    assert recs["L03#0"]["error_type"] == "BrokenProcessPool"


# ------------------------------------------------------------------------------ chain eval


def test_chain_eval_exits_1_on_errored_episodes_unless_allowed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    suite = suite_folder(tmp_path)
    env = ["--env", "tests.support.faulty_env", "--agent", "random"]
    assert chain_eval(suite, tmp_path / "a", *env) == 1
    out = capsys.readouterr().out
    assert out.startswith("WARNING: 2 episode(s) errored (random-interactive: 2)")
    assert chain_eval(suite, tmp_path / "b", *env, "--allow-errors") == 0
    assert "accepted (--allow-errors)" in capsys.readouterr().out
    assert chain_eval(suite, tmp_path / "c", "--env", "tests.support.fake_env") == 0
    assert "WARNING" not in capsys.readouterr().out


def test_a_refused_key_stops_the_run_at_the_first_call(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("OPENAI_API_KEY", SECRET)
    script = Script([{"fault": "echo-key-401"}] * 10)
    with fake_openai(script) as url:
        assert chain_eval(suite_folder(tmp_path), tmp_path / "r", *openai_args(url)) == 2
    assert len(script.requests) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "authentication failed" in err[0] and "HTTP 401" in err[0]
    assert SECRET not in err[0]
    assert _records(tmp_path / "r" / "fake-interactive") == {}  # nothing recorded


def test_no_key_for_a_remote_server_stops_the_run(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.delenv("OPENAI_API_KEY", raising=False)
    remote = openai_args("https://models.example.invalid/v1")
    assert chain_eval(suite_folder(tmp_path), tmp_path / "r", *remote) == 2
    err = capsys.readouterr().err
    assert "no API key for a remote server" in err


def test_server_errors_after_every_retry_are_errored_episodes(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    suite = suite_folder(tmp_path, 2)
    fast = ["--agent-option", "max_retries=1", "--agent-option", "backoff_base=0.001"]
    script = Script([{"fault": "500"}] * 100)
    with fake_openai(script) as url:
        assert chain_eval(suite, tmp_path / "a", *openai_args(url), *fast) == 1
        assert len(script.requests) == 4  # 2 episodes x (1 try + 1 retry)
        assert "WARNING: 2 episode(s) errored" in capsys.readouterr().out
        assert chain_eval(suite, tmp_path / "b", *openai_args(url), *fast, "--allow-errors") == 0
    recs = _records(tmp_path / "a" / "fake-interactive")
    assert all(r["status"] == "error" and "HTTP 500" in r["error"] for r in recs.values())


def test_auth_error_is_an_agent_error() -> None:
    assert issubclass(AuthenticationError, RuntimeError)


# ------------------------------------------------------------------------------ a killed run


def _session(sid: int) -> list[int]:
    """Live (not zombie) processes of session ``sid``: the run and everything it started, even
    once reparented."""
    out = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            stat = (Path("/proc") / entry / "stat").read_text()
        except OSError:
            continue
        fields = stat[stat.rindex(")") + 2 :].split()
        if int(fields[3]) == sid and fields[0] != "Z":
            out.append(int(entry))
    return out


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs /proc")
def test_a_killed_parallel_run_leaves_no_process_behind(tmp_path: Path) -> None:
    suite = suite_folder(tmp_path, 8)
    cmd = [sys.executable, "-m", "chaingeo.cli.main", "eval", "--levels", str(suite)]
    cmd += ["--out", str(tmp_path / "r"), "--env", FAKE.env, "--agent", "random"]
    cmd += ["--samples", "4", "--jobs", "2", "--no-progress"]
    env = dict(os.environ, FAKE_ENV_DELAY="0.05", PYTHONPATH=str(ROOT))
    proc = subprocess.Popen(cmd, cwd=ROOT, env=env, start_new_session=True, stdout=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 60
        while len(_session(proc.pid)) < 4:  # the run, two workers, the resource tracker
            assert time.monotonic() < deadline and proc.poll() is None, "no workers started"
            time.sleep(0.05)
        os.kill(proc.pid, signal.SIGKILL)  # the parent only: its workers must follow
        proc.wait()
        killed = time.monotonic()
        while _session(proc.pid) and time.monotonic() - killed < 10:
            time.sleep(0.05)
        assert _session(proc.pid) == [], "processes outlived the killed run"
        assert proc.stdout is not None
        assert proc.stdout.read() is not None  # EOF: nobody holds the run's stdout any more
    finally:
        for pid in _session(proc.pid):
            os.kill(pid, signal.SIGKILL)
