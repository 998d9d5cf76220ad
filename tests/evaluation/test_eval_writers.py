"""Writers that cannot collide or leave partial state (issue #37, items 9-11): an advisory lock
per output folder refuses a second writer with one clear line; every file is written to a
temporary name and renamed; a full disk (ENOSPC, simulated by making the write fail, and for
real on a small tmpfs where one can be mounted) is one line naming the path, with the finished
episodes kept and the run resumable."""

from __future__ import annotations

import errno
import json
import os
import subprocess
import sys
from collections import Counter
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from chaingeo.cli.main import main
from chaingeo.core.files import lock_folder, unlock_folder
from tests.support.harness import FAKE, chain_eval, suite_folder
from tests.support.paths import ROOT

RANDOM = ["--agent", "random", "--env", FAKE.env]


def _keys(run: Path) -> list[str]:
    lines = (run / "episodes.jsonl").read_text().splitlines()
    return [json.loads(x)["key"] for x in lines if x.strip()]


def _one_line(capsys: pytest.CaptureFixture[str]) -> str:
    err = [x for x in capsys.readouterr().err.splitlines() if x.startswith("chain ")]
    assert len(err) == 1, err
    return err[0]


# -- item 9: two writers ----------------------------------------------------------------------


def test_two_concurrent_resumes_record_every_episode_once(tmp_path: Path) -> None:
    suite = suite_folder(tmp_path, 6)
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "chaingeo.cli.main", "eval", "--levels", str(suite)]
    cmd += ["--out", str(out), "--resume", "--no-progress", "--samples", "8", *RANDOM]
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    first = subprocess.Popen(cmd, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    second = subprocess.Popen(
        cmd, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE
    )
    codes = [p.wait(timeout=300) for p in (first, second)]
    assert 0 in codes and set(codes) <= {0, 2}, [p.communicate() for p in (first, second)]
    keys = _keys(out / "random-interactive")
    assert len(keys) == 6 * 8 and max(Counter(keys).values()) == 1


def test_a_second_eval_on_a_locked_folder_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    suite, out = suite_folder(tmp_path), tmp_path / "out"
    fd = lock_folder(out / "random-interactive")
    try:
        assert chain_eval(suite, out, *RANDOM) == 2
    finally:
        unlock_folder(fd)
    assert "another chain process" in _one_line(capsys)
    assert chain_eval(suite, out, *RANDOM, "--resume") == 0


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("run")
    assert chain_eval(suite_folder(root), root / "out", *RANDOM) == 0
    return root / "out" / "random-interactive"


@pytest.mark.parametrize("what", ["html", "tables"])
def test_a_second_report_writer_is_refused(
    run: Path, tmp_path: Path, what: str, capsys: pytest.CaptureFixture[str]
) -> None:
    site, rep = tmp_path / "site", tmp_path / "rep"
    fd = lock_folder(site if what == "html" else rep)
    try:
        assert main(["report", str(run), "--out", str(rep), "--html", str(site)]) == 2
    finally:
        unlock_folder(fd)
    assert "another chain process" in _one_line(capsys)
    assert main(["report", str(run), "--out", str(rep), "--html", str(site)]) == 0


# -- item 10: a full disk ---------------------------------------------------------------------


def _enospc(*args: Any, **kwargs: Any) -> Any:
    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), "simulated")


def test_a_full_disk_mid_run_keeps_the_finished_episodes_and_resumes(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    suite, out = suite_folder(tmp_path, 4), tmp_path / "out"
    real_write, calls = os.write, [0]

    def write(fd: int, data: Any) -> int:
        calls[0] += 1
        if calls[0] == 3:  # the third record: half of it, then the disk is full
            real_write(fd, bytes(data)[: len(data) // 2])
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real_write(fd, data)

    monkeypatch.setattr(os, "write", write)
    assert chain_eval(suite, out, *RANDOM) == 2
    assert "No space left on device" in _one_line(capsys)
    run = out / "random-interactive"
    assert len(_keys_complete(run)) == 2
    monkeypatch.setattr(os, "write", real_write)
    assert chain_eval(suite, out, *RANDOM, "--resume") == 0
    keys = _keys(run)
    assert len(keys) == 4 and max(Counter(keys).values()) == 1


def _keys_complete(run: Path) -> list[str]:
    text = (run / "episodes.jsonl").read_text()
    return [json.loads(x)["key"] for x in text.split("\n")[:-1] if x.strip()]


def test_an_eval_started_with_a_full_disk_leaves_no_half_run(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import chaingeo.evaluation.logs as logs

    suite, out = suite_folder(tmp_path), tmp_path / "out"
    monkeypatch.setattr(logs, "atomic_write", _enospc)
    assert chain_eval(suite, out, *RANDOM) == 2
    assert "No space left on device" in _one_line(capsys)
    assert not (out / "random-interactive").exists()
    monkeypatch.undo()
    assert chain_eval(suite, out, *RANDOM, "--resume") == 0


def _no_temporaries(folder: Path) -> Iterator[Path]:
    return (p for p in folder.rglob(".*") if p.is_file() and not p.name.endswith(".lock"))


def test_a_full_disk_while_writing_the_report_leaves_no_partial_file(
    run: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import chaingeo.evaluation.report.tables as tables

    real, calls = getattr(tables, "atomic_write"), [0]  # noqa: B009 (not re-exported)

    def write(path: Path, data: bytes, **kw: Any) -> Path:
        calls[0] += 1
        if calls[0] == 3:
            Path(f"{path}.part").write_bytes(b"x")  # what a real write leaves
            Path(f"{path}.part").unlink()
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))
        return Path(real(path, data, **kw))

    monkeypatch.setattr(tables, "atomic_write", write)
    assert main(["report", str(run), "--out", str(tmp_path / "rep")]) == 2
    line = _one_line(capsys)
    assert "No space left on device" in line and str(tmp_path / "rep") in line
    assert not list(_no_temporaries(tmp_path))


@pytest.mark.parametrize("suffix", [".gif", ".mp4"])
def test_a_video_cut_short_is_an_error_not_a_success(
    tmp_path: Path,
    suffix: str,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """A writer that stops early without an error (ffmpeg on a full disk) leaves a file that
    is not whole: the command says so (exit 2) and leaves no file."""
    import chaingeo.worldmodel.video as video

    def short(v: Any, path: Path) -> Path:
        path.write_bytes((b"GIF89a" if suffix == ".gif" else b"\0\0\0\x20ftypisom") + b"\0" * 4000)
        return path

    monkeypatch.setattr(video, "write_gif" if suffix == ".gif" else "write_mp4", short)
    out = tmp_path / f"v{suffix}"
    assert main(["video", "puzzle-easy-01-luban-3-piece", "--out", str(out), "--size", "128"]) == 2
    assert "written whole" in _one_line(capsys)
    assert list(tmp_path.iterdir()) == []


def _tmpfs(path: Path, size: str) -> bool:
    if os.geteuid() != 0:
        return False
    path.mkdir()
    done = subprocess.run(["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(path)],
                          capture_output=True, check=False)  # fmt: skip
    return done.returncode == 0


@pytest.mark.parametrize("suffix", [".gif", ".mp4"])
def test_a_real_full_disk_for_chain_video(
    tmp_path: Path, suffix: str, capsys: pytest.CaptureFixture[str]
) -> None:
    disk = tmp_path / "disk"
    if not _tmpfs(disk, "64k"):
        pytest.skip("mounting a tmpfs needs root and the capability")
    try:
        (disk / "fill").write_bytes(b"\0" * 60_000)
        out = disk / f"v{suffix}"
        code = main(["video", "puzzle-easy-04-burr6", "--out", str(out), "--size", "128"])
        err = capsys.readouterr().err
        assert code == 2 and ("No space left" in err or "whole" in err), err
        assert sorted(p.name for p in disk.iterdir()) == ["fill"]
    finally:
        subprocess.run(["umount", str(disk)], check=False)


# -- item 11 ----------------------------------------------------------------------------------


def test_export_dataset_into_an_existing_file_is_one_error_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    pytest.importorskip("pyarrow")
    target = tmp_path / "file"
    target.write_text("x")
    assert main(["export-dataset", "stacking-2x2x2-easy-s101-000000", "--out", str(target)]) == 2
    assert "is a file" in _one_line(capsys) and target.read_text() == "x"
