"""Kernels compiled ahead of time: load them, check they match the sources, call them.

Why: a process that runs numba's cached kernels pays ~0.5 s before the first one runs
(importing numba 0.18 s, its implementation registries 0.15 s, relinking each cached kernel),
which is most of ``chain analyze`` on a small file. ``chain precompile`` compiles the kernels a
representative workload calls, once per argument signature, into one extension module with
numba's ahead-of-time compiler (:mod:`chaingeo.kernels.aot_build`); loading it costs
milliseconds and does not import numba.

The module is stored per user (:func:`store_dir`) with a manifest: each kernel's exports by
argument key (:mod:`chaingeo.kernels.kernel_keys`), the numpy it was built against, and every
source file the build had imported from the package (size, mtime, SHA-256). It is used only when
all of those still match (a file whose stamp changed is hashed again); otherwise
:func:`load` returns ``None`` and the caller uses numba as before.

In ahead-of-time mode (:func:`chaingeo.kernels.jit.set_mode`) every kernel is an
:class:`AotKernel`; a call with argument types the build did not see raises :class:`KernelMiss`,
a ``BaseException`` no analysis code catches, and the command starts again with numba.
"""

from __future__ import annotations

import importlib.machinery
import importlib.util
import json
import os
import sys
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Final

import numpy as np

from chaingeo.kernels.kernel_keys import args_key

#: Overrides where compiled kernels are stored.
DIR_ENV: Final = "CHAINGEO_KERNEL_DIR"
#: The extension module's name (one per store).
MODULE: Final = "chaingeo_kernels"
MANIFEST: Final = "manifest.json"
#: Bumped when the manifest's meaning changes.
FORMAT: Final = 1


class KernelMiss(BaseException):
    """A kernel was called with argument types it was not compiled for ahead of time (a
    ``BaseException``: analysis code never swallows it; the command retries with numba)."""

    def __init__(self, kernel: str, key: str | None) -> None:
        super().__init__(f"{kernel}: no ahead-of-time kernel for arguments {key}")
        self.kernel = kernel
        self.key = key


def store_dir() -> Path:
    """Where this Python's compiled kernels live: ``$CHAINGEO_KERNEL_DIR``, else the user
    cache (``$XDG_CACHE_HOME`` or ``~/.cache``)/chaingeo/kernels, one folder per interpreter
    and machine."""
    root = os.environ.get(DIR_ENV)
    if not root:
        cache = os.environ.get("XDG_CACHE_HOME") or os.path.join(Path.home(), ".cache")
        root = os.path.join(cache, "chaingeo", "kernels")
    tag = f"{sys.implementation.cache_tag}-{sys.platform}-{os.uname().machine}"
    return Path(root) / tag


@dataclass(frozen=True)
class Manifest:
    """What a stored build holds and what it was built from."""

    exports: Mapping[str, Mapping[str, str]]  # "module:qualname" -> args key -> export name
    numpy: str
    numba: str
    sources: Mapping[str, tuple[int, int, str]]  # path -> (size, mtime_ns, sha256)

    def to_json(self) -> str:
        body = {
            "format": FORMAT,
            "exports": {k: dict(v) for k, v in sorted(self.exports.items())},
            "numpy": self.numpy,
            "numba": self.numba,
            "sources": {k: list(v) for k, v in sorted(self.sources.items())},
        }
        return json.dumps(body, indent=1, sort_keys=True)

    @staticmethod
    def from_json(text: str) -> Manifest | None:
        try:
            body = json.loads(text)
            if body.get("format") != FORMAT:
                return None
            sources = {
                str(k): (int(v[0]), int(v[1]), str(v[2])) for k, v in body["sources"].items()
            }
            exports = {
                str(k): {str(a): str(e) for a, e in v.items()} for k, v in body["exports"].items()
            }
            return Manifest(exports, str(body["numpy"]), str(body["numba"]), sources)
        except (ValueError, KeyError, TypeError, IndexError, AttributeError):
            return None

    def stale(self) -> str | None:
        """Why the build no longer matches this installation, or ``None`` when it does."""
        if self.numpy != np.__version__:
            return f"built against numpy {self.numpy}, running {np.__version__}"
        for path, (size, mtime, digest) in self.sources.items():
            try:
                st = os.stat(path)
            except OSError:
                return f"{path} is gone"
            if (st.st_size, st.st_mtime_ns) != (size, mtime) and file_digest(path) != digest:
                return f"{path} changed"
        return None


def file_digest(path: str) -> str:
    import hashlib  # only for a file whose stamp changed (its import costs ~5 ms)

    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


@dataclass(frozen=True)
class Loaded:
    """A loaded build: its manifest and its extension module."""

    manifest: Manifest
    module: Any

    def exports_of(self, name: str) -> dict[str, Callable[..., Any]]:
        """The compiled functions of kernel ``name`` ("module:qualname") by argument key."""
        table = self.manifest.exports.get(name, {})
        return {key: getattr(self.module, export) for key, export in table.items()}


_loaded: Loaded | None = None


@dataclass(frozen=True)
class Status:
    """What a store holds (``manifest``), whether it can be used, and a sentence saying so."""

    manifest: Manifest | None
    usable: bool
    sentence: str


def status(directory: Path | None = None) -> Status:
    """The stored build's manifest, checked against this installation."""
    folder = directory or store_dir()
    try:
        manifest = Manifest.from_json((folder / MANIFEST).read_text(encoding="utf-8"))
    except OSError:
        return Status(None, False, f"no ahead-of-time kernels in {folder} (run `chain precompile`)")
    if manifest is None:
        return Status(None, False, f"{folder / MANIFEST} is unreadable or of another format")
    if not _module_path(folder).is_file():
        return Status(None, False, f"{folder} has a manifest but no {MODULE} module")
    why = manifest.stale()
    if why:
        return Status(manifest, False, f"stale: {why} (run `chain precompile` again)")
    n, kernels = sum(len(v) for v in manifest.exports.values()), len(manifest.exports)
    return Status(manifest, True, f"ready: {n} compiled signatures of {kernels} kernels")


def load(directory: Path | None = None) -> Loaded | None:
    """The stored build if it matches this installation (checked and loaded once a process),
    else ``None``."""
    global _loaded
    if _loaded is not None:
        return _loaded
    folder = directory or store_dir()
    found = status(folder)
    if not found.usable or found.manifest is None:
        return None
    spec = importlib.util.spec_from_file_location(
        MODULE, _module_path(folder), loader=None, submodule_search_locations=None
    )
    if spec is None or spec.loader is None:
        return None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    _loaded = Loaded(found.manifest, module)
    return _loaded


def _module_path(folder: Path) -> Path:
    return folder / f"{MODULE}{importlib.machinery.EXTENSION_SUFFIXES[0]}"


def kernel_name(fn: Callable[..., Any]) -> str:
    return f"{fn.__module__}:{fn.__qualname__}"


class AotKernel:
    """A kernel in ahead-of-time mode: calls go to the export compiled for the arguments'
    types; anything else raises :class:`KernelMiss`."""

    def __init__(self, fn: Callable[..., Any], exports: dict[str, Callable[..., Any]]) -> None:
        self.py_func = fn
        self.__name__ = fn.__name__
        self.__qualname__ = fn.__qualname__
        self.__module__ = fn.__module__
        self.__doc__ = fn.__doc__
        self.__wrapped__ = fn
        self._exports = exports
        self._name = kernel_name(fn)

    def resolve(self, args: tuple[Any, ...]) -> Callable[..., Any]:
        """The compiled function for ``args``' types (:class:`KernelMiss` if none)."""
        key = args_key(args)
        found = self._exports.get(key) if key is not None else None
        if found is None:
            raise KernelMiss(self._name, key)
        return found

    def __call__(self, *args: Any) -> Any:
        return self.resolve(args)(*args)
