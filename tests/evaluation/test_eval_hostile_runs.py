"""Hand-edited run folders into ``chain report`` and ``--html`` (issue #37, item 6): every JSON
of a run goes through the one bounded reader (regular files, size, depth first) and every record
field a reader relies on is checked as it is read, so each damage is one error line naming the
file (exit 2), never a traceback, a hang, a wrong count or a file from outside the run."""

from __future__ import annotations

import hashlib
import json
import os
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from chaingeo.cli.main import main
from chaingeo.evaluation.agents.base import AgentSpec
from chaingeo.evaluation.runner import RunConfig, evaluate
from tests.support.harness import FAKE, fake_levels


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("runs")
    evaluate(
        fake_levels(2, pieces=2), AgentSpec("random"), root / "r", FAKE, RunConfig(progress=False)
    )
    return root / "r"


def _lines(path: Path) -> list[dict[str, Any]]:
    return [json.loads(x) for x in path.read_text().splitlines() if x.strip()]


def _edit_record(change: Callable[[dict[str, Any]], Any]) -> Callable[[Path], None]:
    def edit(run: Path) -> None:
        recs = _lines(run / "episodes.jsonl")
        change(recs[0])
        (run / "episodes.jsonl").write_text("".join(json.dumps(r) + "\n" for r in recs))

    return edit


def _raw_line(text: str) -> Callable[[Path], None]:
    def edit(run: Path) -> None:
        with open(run / "episodes.jsonl", "a") as fh:
            fh.write(text + "\n")

    return edit


def _special(name: str, kind: str) -> Callable[[Path], None]:
    def edit(run: Path) -> None:
        (run / name).unlink()
        if kind == "fifo":
            os.mkfifo(run / name)
        else:
            (run / name).symlink_to(kind)

    return edit


DAMAGES: dict[str, Callable[[Path], object]] = {
    "nested line": _raw_line("[" * 100_000 + "]" * 100_000),
    "sample 1e300": _edit_record(lambda r: r.update(sample=1e300)),
    "sample -1": _edit_record(lambda r: r.update(sample=-1)),
    "usage lots": _edit_record(lambda r: r.update(usage="lots")),
    "usage negative": _edit_record(lambda r: r["usage"].update(calls=-5)),
    "success yes": _edit_record(lambda r: r.update(success="yes")),
    "level id newline": _edit_record(lambda r: r.update(level_id="L00\n")),
    "key differs": _edit_record(lambda r: r.update(key="other#0")),
    "steps string": _edit_record(lambda r: r.update(steps="many")),
    "turn text": _edit_record(lambda r: r["steps"].append({"turn": "x"})),
    "cost text": _edit_record(lambda r: r.update(cost_usd="free")),
    "episodes /dev/zero": _special("episodes.jsonl", "/dev/zero"),
    "episodes fifo": _special("episodes.jsonl", "fifo"),
    "header /dev/zero": _special("header.json", "/dev/zero"),
    "header fifo": _special("header.json", "fifo"),
    "header nested": lambda run: (run / "header.json").write_text("[" * 100_000),
    "header agent": lambda run: (run / "header.json").write_text(
        json.dumps({**json.loads((run / "header.json").read_text()), "agent": "x"})
    ),
    "candidates text": lambda run: (run / "header.json").write_text(
        json.dumps(
            {
                **json.loads((run / "header.json").read_text()),
                "protocol": {"candidates": "x"},
            }
        )
    ),
}


@pytest.mark.parametrize("html", [False, True], ids=["tables", "html"])
@pytest.mark.parametrize("damage", sorted(DAMAGES))
def test_a_damaged_run_is_one_error_line(
    run: Path, tmp_path: Path, damage: str, html: bool, capsys: pytest.CaptureFixture[str]
) -> None:
    copy = tmp_path / "run"
    shutil.copytree(run, copy)
    DAMAGES[damage](copy)
    extra = ["--html", str(tmp_path / "site")] if html else []
    assert main(["report", str(copy), "--out", str(tmp_path / "rep"), *extra]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(copy) in err[0], err
    assert not (tmp_path / "site").exists()


def test_an_image_linked_from_outside_the_run_is_not_copied(
    run: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    copy = tmp_path / "run"
    shutil.copytree(run, copy)
    secret = tmp_path / "secret.png"
    secret.write_bytes(b"\x89PNG not the run's own")
    name = hashlib.sha256(secret.read_bytes()).hexdigest() + ".png"
    (copy / "images" / name).symlink_to(secret)
    _edit_record(lambda r: r["steps"].append({"turn": 0, "images": {"front": name}}))(copy)
    site = tmp_path / "site"
    assert main(["report", str(copy), "--out", str(tmp_path / "rep"), "--html", str(site)]) == 0
    assert not (site / "images" / name).exists()
    pages = "".join(p.read_text() for p in site.rglob("*.html"))
    assert f"picture missing: {name}" in pages


@pytest.mark.parametrize("kind", ["/dev/zero", "fifo", "nested", "digits"])
def test_every_other_json_file_goes_through_the_bounded_reader(
    tmp_path: Path, kind: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """Price tables, replay plans and ``chain cover --pieces`` files: one typed error each."""
    from chaingeo.core.errors import ChainGeoError
    from chaingeo.evaluation.agents.replay import ReplayAgent
    from chaingeo.evaluation.usage import PriceTable

    path = tmp_path / "f.json"
    if kind == "/dev/zero":
        path.symlink_to("/dev/zero")
    elif kind == "fifo":
        os.mkfifo(path)
    else:
        path.write_text("[" * 100_000 if kind == "nested" else "[" + "9" * 5000 + "]")
    with pytest.raises(ChainGeoError):
        PriceTable.load(path)
    with pytest.raises(ValueError, match="cannot read replay file"):
        ReplayAgent({"file": str(path)})
    assert main(["cover", "--pieces", str(path), "--box", "2x2x2"]) == 2
    err = capsys.readouterr().err
    assert "--pieces" in err or "not a regular file" in err
