"""Run directories: header contents, appended records, images by hash, resumption, redaction."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import pytest

from chaingeo.evaluation.logs import (
    EPISODES,
    REDACTED,
    RunError,
    RunLog,
    episode_key,
    make_header,
)


def _header(**over: object) -> dict[str, object]:
    h = make_header(
        agent={"name": "random", "seed": 3},
        protocol={"name": "interactive", "history_window": 5},
        level_set_hash="ab" * 32,
        levels=["b", "a"],
        seed=7,
        samples=1,
    )
    h.update(over)
    return h


def _rec(key: str, **over: object) -> dict[str, object]:
    """A complete episode record (readers check every field they use) for ``key``."""
    level_id, sample = key.split("#")
    rec: dict[str, object] = {
        "key": key,
        "level_id": level_id,
        "sample": int(sample),
        "family": "stacking",
        "difficulty": "easy",
        "optimal_steps": 2,
        "steps_used": 2,
        "success": True,
        "status": "done",
    }
    rec.update(over)
    return rec


def test_header_names_commit_versions_and_level_set(tmp_path: Path) -> None:
    log = RunLog.create(tmp_path / "run", _header())
    head = log.header()
    assert head["format"] == "chain-run/1"
    assert head["level_set_hash"] == "ab" * 32 and head["levels"] == ["a", "b"]
    assert set(head["git"]) == {"commit", "dirty"}
    assert head["git"]["commit"] is None or len(head["git"]["commit"]) == 40
    assert head["packages"]["numpy"] and head["packages"]["python"]
    assert head["agent"] == {"name": "random", "seed": 3}


def test_records_append_images_by_hash_and_partial_tail(tmp_path: Path) -> None:
    log = RunLog.create(tmp_path / "run", _header())
    png = b"\x89PNG fake bytes"
    name = log.put_image(png)
    assert name == hashlib.sha256(png).hexdigest() + ".png"
    assert (log.path / "images" / name).read_bytes() == png
    assert log.put_image(png) == name
    log.append(_rec(episode_key("a", 0), images=[name]))
    log.append(_rec(episode_key("b", 0), status="error"))
    # A killed writer leaves half a line behind.
    with open(log.path / EPISODES, "ab") as fh:
        fh.write(b'{"key": "c#0", "sta')
    assert [r["key"] for r in log.records()] == ["a#0", "b#0"]
    assert log.finished_keys() == {"a#0", "b#0"}
    assert log.finished_keys(retry_errors=True) == {"a#0"}
    log.close()  # one writer at a time: the folder's lock
    again = RunLog.create(log.path, _header(), resume=True)
    again.append(_rec("c#0"))
    lines = (log.path / EPISODES).read_text().splitlines()
    assert [json.loads(x)["key"] for x in lines] == ["a#0", "b#0", "c#0"]
    # A retried episode: the later record wins.
    again.append(_rec("b#0"))
    assert again.latest()["b#0"]["status"] == "done"


def test_resume_refuses_a_different_run_and_new_refuses_existing(tmp_path: Path) -> None:
    RunLog.create(tmp_path / "run", _header()).close()
    with pytest.raises(RunError, match="--resume"):
        RunLog.create(tmp_path / "run", _header())
    with pytest.raises(RunError, match="level_set_hash differs"):
        RunLog.create(tmp_path / "run", _header(level_set_hash="cd" * 32), resume=True)
    with pytest.raises(RunError, match="agent differs"):
        RunLog.create(tmp_path / "run", _header(agent={"name": "greedy"}), resume=True)
    (tmp_path / "other").mkdir()
    (tmp_path / "other" / "x").write_text("x")
    with pytest.raises(RunError, match="not a run directory"):
        RunLog.create(tmp_path / "other", _header())


def test_secrets_never_reach_the_files(tmp_path: Path) -> None:
    key = "sk-test-0123456789abcdef"
    log = RunLog.create(tmp_path / "run", _header(note=f"key={key}"), secrets=[key])
    log.append({"key": "a#0", "reply": f"the server echoed {key} back"})
    for f in log.path.rglob("*"):
        if f.is_file():
            assert key not in f.read_text(errors="replace")
    assert REDACTED in (log.path / EPISODES).read_text()


def test_a_corrupt_middle_line_is_an_error(tmp_path: Path) -> None:
    log = RunLog.create(tmp_path / "run", _header())
    good = [json.dumps(_rec(k)) for k in ("a#0", "b#0")]
    (log.path / EPISODES).write_text(f"{good[0]}\nnot json\n{good[1]}\n")
    with pytest.raises(RunError, match="line 2"):
        log.records()
