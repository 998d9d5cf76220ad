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
import stat
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
#: Bumped when the manifest's meaning changes (2: the module's size and SHA-256).
FORMAT: Final = 2


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
    """What a stored build holds and what it was built from, the module's own bytes included."""

    exports: Mapping[str, Mapping[str, str]]  # "module:qualname" -> args key -> export name
    numpy: str
    numba: str
    sources: Mapping[str, tuple[int, int, str]]  # path -> (size, mtime_ns, sha256)
    module: tuple[int, str] = (0, "")  # the extension module's (size, sha256)

    def to_json(self) -> str:
        body = {
            "format": FORMAT,
            "exports": {k: dict(v) for k, v in sorted(self.exports.items())},
            "numpy": self.numpy,
            "numba": self.numba,
            "sources": {k: list(v) for k, v in sorted(self.sources.items())},
            "module": {"size": self.module[0], "sha256": self.module[1]},
        }
        return json.dumps(body, indent=1, sort_keys=True)

    @staticmethod
    def from_json(text: str | bytes) -> Manifest | None:
        found = _parse_manifest(text)
        return found if isinstance(found, Manifest) else None

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


def _parse_manifest(text: str | bytes) -> Manifest | str:
    """The manifest, or why it is not one this version trusts: read with the bounded JSON
    reader, every field typed, the module's size and SHA-256 present, and sources that cover
    the module of every exported kernel (an empty list would switch the staleness check off)."""
    from chaingeo.core.files import UnreadableFile, parse_json

    try:
        body = parse_json(text)
    except UnreadableFile as e:
        return e.reason
    if not isinstance(body, dict) or body.get("format") != FORMAT:
        return f"not a format-{FORMAT} manifest (run `chain precompile` again)"
    try:
        sources = {str(k): _stamp(v) for k, v in body["sources"].items()}
        exports = {
            str(k): {str(a): _name(e) for a, e in v.items()} for k, v in body["exports"].items()
        }
        module = body["module"]
        size, digest = module["size"], module["sha256"]
        if not (_whole(size) and isinstance(digest, str) and len(digest) == 64):
            raise ValueError("module")
        numpy, numba = str(body["numpy"]), str(body["numba"])
    except (ValueError, KeyError, TypeError, IndexError, AttributeError):
        return "a manifest with missing or mistyped fields"
    covered = {_module_of(p) for p in sources}
    missing = sorted({".".join(k.split(":")[0].split(".")[-2:]) for k in exports} - covered)
    if not sources or missing:
        return f"its sources do not cover {missing[0] if missing else 'any kernel'}"
    return Manifest(exports, numpy, numba, sources, (size, digest))


def _whole(v: Any) -> bool:
    return isinstance(v, int) and not isinstance(v, bool) and v >= 0


def _stamp(v: Any) -> tuple[int, int, str]:
    if not (isinstance(v, list) and len(v) == 3 and _whole(v[0]) and _whole(v[1])):
        raise ValueError("stamp")
    if not (isinstance(v[2], str) and len(v[2]) == 64):
        raise ValueError("stamp")
    return (v[0], v[1], v[2])


def _name(v: Any) -> str:
    if not (isinstance(v, str) and v.isidentifier()):
        raise ValueError("export")
    return v


def _module_of(path: str) -> str:
    """The last two parts of a source's module name (``motion.turns_sweep_kernel`` from
    ``.../motion/turns_sweep_kernel.py``):
    the installed layout maps folders, so a full name cannot be told from the path alone."""
    parts = Path(path).with_suffix("").parts
    if parts and parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts[-2:])


def file_digest(path: str | os.PathLike[str]) -> str:
    """The SHA-256 of a regular file of bounded size (never ``/dev/zero`` or a FIFO); an empty
    string when it cannot be read, which matches no recorded digest."""
    import hashlib  # only for a file whose stamp changed (its import costs ~5 ms)

    from chaingeo.core.files import UnreadableFile, read_bounded
    from chaingeo.core.limits import MAX_KERNEL_FILE_BYTES

    try:
        return hashlib.sha256(read_bounded(path, MAX_KERNEL_FILE_BYTES)).hexdigest()
    except UnreadableFile:
        return ""


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
#: Why the last :func:`load` refused a store that exists (None: it loaded, or there is none).
refused: str | None = None


@dataclass(frozen=True)
class Status:
    """What a store holds (``manifest``), whether it can be used, and a sentence saying so."""

    manifest: Manifest | None
    usable: bool
    sentence: str


def _owner_problem(path: Path) -> str | None:
    """Why ``path`` may hold code someone else put there: not ours, or writable by others, or
    (for a file) a link or not a regular file."""
    try:
        st = os.lstat(path)
    except OSError as e:
        return f"{path}: {e.strerror or e}"
    if not (stat.S_ISDIR(st.st_mode) or stat.S_ISREG(st.st_mode)):
        return f"{path} is not a regular file or folder"
    if st.st_uid != os.getuid():
        return f"{path} is owned by another user"
    if st.st_mode & 0o022:
        return f"{path} is writable by group or others"
    return None


def status(directory: Path | None = None) -> Status:
    """The stored build checked before anything is loaded: the folder and its files owned by
    this user and writable by no one else, the manifest well formed, the module's size and
    SHA-256 those the manifest records, and the sources unchanged."""
    folder = directory or store_dir()
    if not (folder / MANIFEST).exists() and not (folder / MANIFEST).is_symlink():
        return Status(None, False, f"no ahead-of-time kernels in {folder} (run `chain precompile`)")
    for path in (folder, folder / MANIFEST, module_path(folder)):
        problem = _owner_problem(path)
        if problem:
            return Status(None, False, f"not used: {problem}")
    from chaingeo.core.files import UnreadableFile, read_bounded
    from chaingeo.core.limits import MAX_KERNEL_FILE_BYTES, MAX_KERNEL_MANIFEST_BYTES

    try:
        found = _parse_manifest(read_bounded(folder / MANIFEST, MAX_KERNEL_MANIFEST_BYTES))
    except UnreadableFile as e:
        found = e.reason
    if isinstance(found, str):
        return Status(None, False, f"not used: {folder / MANIFEST}: {found}")
    size = os.lstat(module_path(folder)).st_size
    if size != found.module[0] or size > MAX_KERNEL_FILE_BYTES:
        return Status(found, False, f"not used: {MODULE} is {size} bytes, not the manifest's")
    if file_digest(module_path(folder)) != found.module[1]:
        return Status(found, False, f"not used: {MODULE}'s SHA-256 is not the manifest's")
    why = found.stale()
    if why:
        return Status(found, False, f"stale: {why} (run `chain precompile` again)")
    n, kernels = sum(len(v) for v in found.exports.values()), len(found.exports)
    return Status(found, True, f"ready: {n} compiled signatures of {kernels} kernels")


def load(directory: Path | None = None) -> Loaded | None:
    """The stored build if it passes :func:`status` (checked and loaded once a process), else
    ``None``: the module is imported only after its bytes were hashed."""
    global _loaded, refused
    if _loaded is not None:
        return _loaded
    folder = directory or store_dir()
    found = status(folder)
    if not found.usable or found.manifest is None:
        refused = None if found.sentence.startswith("no ahead-of-time") else found.sentence
        return None
    spec = importlib.util.spec_from_file_location(
        MODULE, module_path(folder), loader=None, submodule_search_locations=None
    )
    if spec is None or spec.loader is None:
        return None
    try:
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        loaded = Loaded(found.manifest, module)
        for table in found.manifest.exports.values():
            for export in table.values():
                getattr(module, export)
    except (ImportError, AttributeError, OSError) as e:
        refused = f"not used: {MODULE} cannot be imported ({type(e).__name__})"
        return None
    _loaded = loaded
    return _loaded


def module_path(folder: Path) -> Path:
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
