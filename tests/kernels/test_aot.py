"""Kernels compiled ahead of time (``chain precompile``): dispatch by argument types, refusal of
a build that no longer matches the sources, the same figures as numba's on files the workload
never saw, and a fall back to numba, without printing a file twice, when a call was not
compiled."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from chaingeo.kernels import aot
from chaingeo.kernels.kernel_keys import args_key
from tests.support.paths import DATA
from tests.support.shared_files import BT as SHARED_BT

BT = DATA / "burrtools"


def _kernel(a: Any, b: Any) -> Any:
    return "python"


def test_a_kernel_calls_the_export_of_its_argument_types_and_misses_others() -> None:
    ints, floats = np.zeros(3, np.int64), np.zeros(3)
    calls: list[tuple[Any, ...]] = []

    def compiled(*args: Any) -> str:
        calls.append(args)
        return "compiled"

    kernel = aot.AotKernel(_kernel, {args_key((ints, 5)) or "": compiled})
    assert kernel(ints, 5) == "compiled" and calls == [(ints, 5)]
    assert kernel.__name__ == "_kernel" and kernel.py_func is _kernel
    for args in ((floats, 5), (ints, 5.0), (ints[::2], 5), (ints, "5")):
        with pytest.raises(aot.KernelMiss) as miss:
            kernel(*args)
        assert miss.value.kernel == f"{__name__}:_kernel"
        assert miss.value.key == args_key(args)
    assert not isinstance(aot.KernelMiss("k", None), Exception)  # analysis code never catches it


def _manifest(source: Path) -> aot.Manifest:
    st = source.stat()
    stamp = (st.st_size, st.st_mtime_ns, aot.file_digest(str(source)))
    kernel = f"{source.parent.name}.{source.stem}:k"  # its module is among the sources
    module = (5, "ab" * 32)
    return aot.Manifest({kernel: {"<i8": "k0"}}, np.__version__, "0", {str(source): stamp}, module)


def test_a_build_is_stale_once_a_source_or_numpy_differs(tmp_path: Path) -> None:
    source = tmp_path / "kernels.py"
    source.write_text("X = 1\n")
    manifest = aot.Manifest.from_json(_manifest(source).to_json())
    assert manifest == _manifest(source) and manifest.stale() is None
    os.utime(source, ns=(1, 1))  # touched, same text (a checkout): still usable
    assert manifest.stale() is None
    source.write_text("X = 2\n")
    assert manifest.stale() == f"{source} changed"
    assert aot.Manifest(manifest.exports, "0.0", "0", {}).stale() is not None
    source.unlink()
    assert manifest.stale() == f"{source} is gone"
    for text in ("", "[]", '{"format": 99}', '{"format": 1, "sources": {"a": [1]}}'):
        assert aot.Manifest.from_json(text) is None


def test_no_store_is_said_plainly(tmp_path: Path) -> None:
    found = aot.status(tmp_path / "none")
    assert (found.manifest, found.usable) == (None, False)
    assert "chain precompile" in found.sentence
    (tmp_path / aot.MANIFEST).write_text("{")
    assert not aot.status(tmp_path).usable


# -- with the user's build (CI runs `chain precompile` first) ------------------------------


def _chain(kernels: Path | None, *args: str, jit: str = "auto") -> list[dict[str, Any]]:
    env = {k: v for k, v in os.environ.items() if k != "CHAINGEO_JIT"}
    if kernels is not None:
        env[aot.DIR_ENV] = str(kernels.parent)
    cmd = [sys.executable, "-m", "chaingeo.cli.main", "analyze", "--jit", jit, *args]
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=600, env=env, check=False)
    assert done.returncode in (0, 2), done.stderr
    return [json.loads(line) for line in done.stdout.splitlines()]


def _figures(row: dict[str, Any]) -> dict[str, Any]:
    if "problems" in row:
        row = {**row, "problems": [_figures(p) for p in row["problems"]]}
    return {k: v for k, v in row.items() if k not in ("seconds", "kernels")}


#: Inputs the precompile workload does not hold as such: shipped levels by id, test-only
#: BurrTools files (the examples' seeds and sizes differ), and BurrTools' own files.
FILES = [
    "puzzle-easy-01-luban-3-piece",
    str(BT / "linked_rings.xmpuzzle"),
    str(BT / "ring_maze.xmpuzzle"),
]
MORE = [
    "puzzle-easy-04-burr6",
    "puzzle-mid-04-burr12",
    str(BT / "soma_problems.xmpuzzle"),
    str(BT / "solid_burrs.xmpuzzle"),
]
MORE += [str(p) for p in sorted(SHARED_BT.glob("*.xmpuzzle"))] if SHARED_BT else []


def _same_figures(kernels: Path, files: list[str], mirrors: str) -> None:
    ahead = _chain(kernels, "--mirrors", mirrors, *files, jit="aot")
    numba = _chain(None, "--mirrors", mirrors, *files, jit="numba")
    assert [r["kernels"] for r in ahead] == ["aot"] * len(files)
    assert [_figures(r) for r in ahead] == [_figures(r) for r in numba]


def test_precompiled_kernels_give_numbas_figures(user_kernels: Path) -> None:
    _same_figures(user_kernels, FILES, "drop")


@pytest.mark.slow
@pytest.mark.parametrize("mirrors", ["keep", "drop"])
def test_precompiled_kernels_give_numbas_figures_on_more_files(
    user_kernels: Path, mirrors: str
) -> None:
    """The heavy variant of the test above: larger puzzles and BurrTools' own files."""
    _same_figures(user_kernels, FILES + MORE, mirrors)


def test_a_call_not_precompiled_starts_numba_for_the_files_not_yet_printed(
    user_kernels: Path, tmp_path: Path
) -> None:
    partial = tmp_path / user_kernels.name
    shutil.copytree(user_kernels, partial)
    body = json.loads((partial / aot.MANIFEST).read_text())
    body["exports"] = {}  # every call misses
    (partial / aot.MANIFEST).write_text(json.dumps(body))
    bad = tmp_path / "bad.xmpuzzle"
    bad.write_bytes(b"not a puzzle")
    files = [str(bad), FILES[1]]
    rows = _chain(partial, *files)
    assert [("error" in r, r.get("kernels")) for r in rows] == [(True, None), (False, "numba")]
    assert _figures(rows[1]) == _figures(_chain(None, FILES[1], jit="numba")[0])
    env = {**os.environ, aot.DIR_ENV: str(partial.parent)}
    cmd = [sys.executable, "-m", "chaingeo.cli.main", "analyze", *files]
    assert subprocess.run(cmd, capture_output=True, env=env, check=False).returncode == 2
    forced = subprocess.run(
        [*cmd[:-2], "--jit", "aot", FILES[1]], capture_output=True, text=True, env=env, check=False
    )
    assert forced.returncode == 2 and "chain precompile" in forced.stderr
