"""The precompiled-kernel store is verified before anything in it is loaded (issue #37, item 2):
the manifest records the module's size and SHA-256 and the module is hashed before import; the
folder and its files must be the user's and writable by no one else; the manifest is read with
the bounded JSON reader and its sources, read bounded too, must cover every kernel. A store that
fails says why (``chain precompile --status``) and numba is used, with one warning line."""

from __future__ import annotations

import hashlib
import importlib.util
import json
import os
import subprocess
import sys
import threading
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from chaingeo.cli.main import main
from chaingeo.kernels import aot

MODULE_BYTES = b"\x7fELF" + bytes(range(256)) * 64


def _store(root: Path, module: bytes = MODULE_BYTES, **over: Any) -> Path:
    """A store under ``root`` (as ``$CHAINGEO_KERNEL_DIR``) whose manifest records
    :data:`MODULE_BYTES`; ``module`` is what the module file holds, ``over`` edits the
    manifest's fields."""
    folder = _folder(root)
    folder.mkdir(parents=True)
    source = root / "pkg" / "kernels.py"
    source.parent.mkdir(exist_ok=True)
    source.write_text("X = 1\n")
    st = source.stat()
    body: dict[str, Any] = {
        "format": aot.FORMAT,
        "exports": {"chaingeo.pkg.kernels:k": {"<i8": "k0"}},
        "numpy": np.__version__,
        "numba": "0",
        "sources": {str(source): [st.st_size, st.st_mtime_ns, aot.file_digest(source)]},
        "module": {"size": len(MODULE_BYTES), "sha256": hashlib.sha256(MODULE_BYTES).hexdigest()},
    }
    body.update(over)
    (folder / aot.MANIFEST).write_text(json.dumps(body))
    aot.module_path(folder).write_bytes(module)
    return folder


def _folder(root: Path) -> Path:
    old = os.environ.get(aot.DIR_ENV)
    os.environ[aot.DIR_ENV] = str(root)
    try:
        return aot.store_dir()
    finally:
        if old is None:
            del os.environ[aot.DIR_ENV]
        else:
            os.environ[aot.DIR_ENV] = old


def _bounded(call: Callable[[], Any], seconds: float = 20.0) -> Any:
    """``call()`` in a thread that must finish in ``seconds`` (a FIFO read would hang)."""
    out: list[Any] = []
    worker = threading.Thread(target=lambda: out.append(call()), daemon=True)
    worker.start()
    worker.join(seconds)
    assert not worker.is_alive(), "hung"
    return out[0]


def test_a_whole_store_passes_its_checks(tmp_path: Path) -> None:
    found = aot.status(_store(tmp_path))
    assert found.usable, found.sentence


def _fifo_source(folder: Path) -> None:
    fifo = folder.parent / "fifo.py"
    os.mkfifo(fifo)
    body = json.loads((folder / aot.MANIFEST).read_text())
    body["sources"][str(fifo)] = [1, 1, "0" * 64]
    (folder / aot.MANIFEST).write_text(json.dumps(body))


def _link_module(folder: Path) -> None:
    aot.module_path(folder).unlink()
    aot.module_path(folder).symlink_to("/bin/true")


def _fifo_manifest(folder: Path) -> None:
    (folder / aot.MANIFEST).unlink()
    os.mkfifo(folder / aot.MANIFEST)


def _chown(folder: Path) -> None:
    if os.getuid() != 0:
        pytest.skip("changing a folder's owner needs root")
    os.chown(folder, 12345, 12345)


#: (case, how the store is damaged after it is made, a word the refusal must hold)
DAMAGES: dict[str, tuple[Callable[[Path], Any], str]] = {
    "truncated module": (lambda f: aot.module_path(f).write_bytes(MODULE_BYTES[:100]), "bytes"),
    "empty module": (lambda f: aot.module_path(f).write_bytes(b""), "bytes"),
    "planted module": (
        lambda f: aot.module_path(f).write_bytes(MODULE_BYTES[::-1]),
        "SHA-256",
    ),
    "no module": (lambda f: aot.module_path(f).unlink(), "No such file"),
    "module is a link": (_link_module, "not a regular file"),
    "folder group-writable": (lambda f: f.chmod(0o775), "writable by group or others"),
    "module other-writable": (lambda f: aot.module_path(f).chmod(0o646), "writable"),
    "folder of another user": (_chown, "owned by another user"),
    "source /dev/zero": (
        lambda f: _edit(f, lambda b: b["sources"].update({"/dev/zero": [1, 1, "0" * 64]})),
        "/dev/zero changed",
    ),
    "source fifo": (_fifo_source, "changed"),
    "sources emptied": (lambda f: _edit(f, lambda b: b.update(sources={})), "do not cover"),
    "kernel not covered": (
        lambda f: _edit(f, lambda b: b["exports"].update({"chaingeo.x.other:k": {}})),
        "do not cover x.other",
    ),
    "no module hash": (lambda f: _edit(f, lambda b: b.pop("module")), "missing or mistyped"),
    "old format": (lambda f: _edit(f, lambda b: b.update(format=1)), "format"),
    "nested manifest": (lambda f: (f / aot.MANIFEST).write_text("[" * 200_000), "nested"),
    "huge manifest": (lambda f: os.truncate(f / aot.MANIFEST, 3 * 1024**3), "bytes; at most"),
    "manifest fifo": (_fifo_manifest, "not"),
    "export name": (
        lambda f: _edit(f, lambda b: b["exports"].update({"chaingeo.pkg.kernels:k": {"a": 5}})),
        "mistyped",
    ),
}


def _edit(folder: Path, change: Callable[[dict[str, Any]], Any]) -> None:
    body = json.loads((folder / aot.MANIFEST).read_text())
    change(body)
    (folder / aot.MANIFEST).write_text(json.dumps(body))


@pytest.mark.parametrize("case", sorted(DAMAGES))
def test_a_damaged_store_is_refused_before_its_module_is_imported(
    tmp_path: Path, case: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    damage, word = DAMAGES[case]
    folder = _store(tmp_path)
    damage(folder)
    found = _bounded(lambda: aot.status(folder))
    assert not found.usable and word in found.sentence, found.sentence

    def no_import(*args: Any, **kwargs: Any) -> Any:
        raise AssertionError("the module was imported")

    monkeypatch.setattr(aot, "_loaded", None)
    monkeypatch.setattr(importlib.util, "module_from_spec", no_import)
    assert _bounded(lambda: aot.load(folder)) is None
    assert aot.refused and word in aot.refused


def test_precompile_status_says_why(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    folder = _store(tmp_path)
    aot.module_path(folder).write_bytes(MODULE_BYTES[:-1])
    monkeypatch.setenv(aot.DIR_ENV, str(tmp_path))
    assert main(["precompile", "--status"]) == 0
    out = capsys.readouterr().out
    assert "not used" in out and "ready" not in out


def test_an_unusable_store_falls_back_to_numba_with_one_warning_line(tmp_path: Path) -> None:
    folder = _store(tmp_path)
    aot.module_path(folder).write_bytes(MODULE_BYTES[::-1])
    env = {**os.environ, aot.DIR_ENV: str(tmp_path), "CHAINGEO_JIT": "aot"}
    code = "from chaingeo.kernels import jit; print(jit.mode())"
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120
    )
    assert done.returncode == 0 and done.stdout.strip() == "numba", done.stderr
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and "SHA-256" in lines[0] and "using numba" in lines[0]
