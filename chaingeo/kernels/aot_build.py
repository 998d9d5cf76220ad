"""Compile the kernels a workload used into one extension module (numba's ahead-of-time
compiler, ``numba.pycc``), and store it with its manifest (:mod:`chaingeo.kernels.aot`).

Why a workload: a numba kernel has no fixed signature; it is compiled for the argument types it
is called with. Running representative work under numba first and reading each dispatcher's
compiled signatures gives exactly the signatures the same work needs later; a call outside them
is a :class:`chaingeo.kernels.aot.KernelMiss` and the caller falls back to numba.

Each signature is exported through a generated one-line wrapper that calls the numba dispatcher,
so the kernel itself is compiled with its own options (``boundscheck``, ``inline``) as it is
under numba, and code is generated for this machine's CPU, as numba's JIT does.
"""

from __future__ import annotations

import os
import shutil
import sys
import tempfile
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from chaingeo.kernels import aot
from chaingeo.kernels.kernel_keys import type_key


@dataclass(frozen=True)
class Export:
    """One compiled signature of one kernel."""

    kernel: str  # "module:qualname"
    key: str  # the arguments' key (kernel_keys)
    signature: Any  # numba Signature, return type included
    dispatcher: Any


def exports(dispatchers: Iterable[Any]) -> list[Export]:
    """The signatures the dispatchers have been compiled for, in a stable order; those whose
    argument types have no key (and ``inline="always"`` helpers, never called from Python) are
    left to numba."""
    found: list[Export] = []
    for d in dispatchers:
        if d.targetoptions.get("inline") == "always":
            continue
        for args in d.signatures:
            try:
                keys = [type_key(t) for t in args]
            except Exception:  # a type numba has and numpy lacks: left to numba, like no key
                continue
            if any(k is None for k in keys):
                continue
            sig = d.overloads[args].signature
            found.append(Export(aot.kernel_name(d.py_func), ";".join(keys), sig, d))  # type: ignore[arg-type]
    return sorted(found, key=lambda e: (e.kernel, e.key))


def build(found: list[Export], folder: Path | None = None) -> aot.Manifest:
    """Compile ``found`` into the store (replacing what is there) and return the manifest."""
    import numba
    from llvmlite import binding  # type: ignore[import-untyped]
    from numba.pycc import CC  # type: ignore[attr-defined]

    target = folder or aot.store_dir()
    target.parent.mkdir(parents=True, exist_ok=True)
    work = Path(tempfile.mkdtemp(prefix=".build-", dir=target.parent))
    try:
        cc = CC(aot.MODULE)  # type: ignore[no-untyped-call]
        cc.output_dir = str(work)
        cc.target_cpu = binding.get_host_cpu_name()
        cc.verbose = False
        table: dict[str, dict[str, str]] = {}
        for i, e in enumerate(found):
            name = f"k{i}"
            export = cc.export(name, e.signature)  # type: ignore[no-untyped-call]
            export(_wrapper(e.dispatcher, len(e.signature.args), name))
            table.setdefault(e.kernel, {})[e.key] = name
        cc.compile()
        module = aot.module_path(work)
        stamp = (module.stat().st_size, aot.file_digest(module))
        manifest = aot.Manifest(table, np.__version__, numba.__version__, _sources(), stamp)
        (work / aot.MANIFEST).write_text(manifest.to_json(), encoding="utf-8")
        _replace(work, target)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    return manifest


def _wrapper(dispatcher: Any, arity: int, name: str) -> Any:
    """``def name(a0, ..., aN): return kernel(a0, ..., aN)``: pycc needs a plain function of
    fixed arity; the call inside is compiled by numba like any kernel-to-kernel call."""
    params = ", ".join(f"a{i}" for i in range(arity))
    namespace: dict[str, Any] = {"kernel": dispatcher}
    exec(f"def {name}({params}):\n    return kernel({params})\n", namespace)  # our own text
    return namespace[name]


def _sources() -> dict[str, tuple[int, int, str]]:
    """Every source file of the package this process imported but the builder's and the
    loader's (the command, this module, :mod:`chaingeo.kernels.aot`): the kernels and every
    constant they compiled in come from these (numba's own cache checks only each kernel's
    file)."""
    stamps: dict[str, tuple[int, int, str]] = {}
    for name, module in list(sys.modules.items()):
        path = getattr(module, "__file__", None)
        if not (name == "chaingeo" or name.startswith("chaingeo.")) or not path:
            continue
        if name.startswith("chaingeo.cli.") or name in ("chaingeo.cli", __name__, aot.__name__):
            continue
        if not path.endswith(".py"):
            continue
        st = os.stat(path)
        stamps[os.path.abspath(path)] = (st.st_size, st.st_mtime_ns, aot.file_digest(path))
    return stamps


def _replace(work: Path, target: Path) -> None:
    """Move the finished build into place; the old one is removed only once the new is whole."""
    old = target.with_name(target.name + ".old")
    shutil.rmtree(old, ignore_errors=True)
    if target.exists():
        target.rename(old)
    fresh = Path(tempfile.mkdtemp(prefix=".fresh-", dir=target.parent))
    for f in work.iterdir():
        shutil.move(str(f), fresh / f.name)
    fresh.rename(target)
    shutil.rmtree(old, ignore_errors=True)
