"""Files in and out: the one bounded reader of input files (and of JSON documents: levels,
trajectories, run headers and records, kernel manifests, prices), and the one atomic-write helper
(a reader never sees half of a file we write)."""

from __future__ import annotations

import json
import os
import stat
import uuid
from collections import Counter
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from chaingeo.core import limits
from chaingeo.core.errors import ChainGeoError


class UnreadableFile(ChainGeoError):
    """An input file that cannot be read as given; ``reason`` says why (the caller names the
    file in its own error type)."""

    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


def read_bounded(path: str | os.PathLike[str], max_bytes: int) -> bytes:
    """The bytes of a regular file of at most ``max_bytes``, refused before reading when it is
    larger or not a regular file (``/dev/zero`` never ends, a FIFO would block forever). The file
    is opened without blocking and checked on the open descriptor, so it cannot be swapped for
    another between the check and the read."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError as e:
        raise UnreadableFile(f"cannot read: {e.strerror or e}") from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise UnreadableFile("not a regular file")
        if st.st_size > max_bytes:
            raise UnreadableFile(f"{st.st_size} bytes; at most {max_bytes}")
        with os.fdopen(fd, "rb", closefd=False) as fh:
            raw = fh.read(max_bytes + 1)
    except OSError as e:
        raise UnreadableFile(f"cannot read: {e.strerror or e}") from None
    finally:
        os.close(fd)
    if len(raw) > max_bytes:  # it grew since fstat
        raise UnreadableFile(f"more than {max_bytes} bytes")
    return raw


class JsonObject(dict[str, Any]):
    """A decoded JSON object; ``repeated`` names the keys written more than once (the last value
    is kept). A parser keeps them beside the object, never under a key of its own, which a
    document could write too."""

    repeated: tuple[str, ...] = ()


def _object(pairs: list[tuple[str, Any]]) -> JsonObject:
    out = JsonObject(pairs)
    if len(out) != len(pairs):
        counts = Counter(k for k, _ in pairs)
        out.repeated = tuple(sorted(k for k, n in counts.items() if n > 1))
    return out


def parse_json(text: str | bytes) -> Any:
    """A JSON document within :mod:`chaingeo.core.limits` (depth checked before parsing, integer
    digits, finite numbers), its objects as :class:`JsonObject`; :class:`UnreadableFile` naming
    what is wrong (and where) otherwise."""
    if isinstance(text, bytes):
        try:
            text = text.decode("utf-8")
        except UnicodeDecodeError:
            raise UnreadableFile("not UTF-8 text") from None
    try:
        return limits.loads_bounded(text, object_pairs_hook=_object)
    except limits.LimitError as e:
        raise UnreadableFile(str(e)) from None
    except json.JSONDecodeError as e:
        raise UnreadableFile(f"invalid JSON at line {e.lineno} column {e.colno}: {e.msg}") from None
    except (ValueError, RecursionError) as e:  # defensive: never a traceback for a file
        raise UnreadableFile(f"invalid JSON: {type(e).__name__}") from None


def read_json(path: str | os.PathLike[str], max_bytes: int) -> Any:
    """The one bounded JSON reader: :func:`read_bounded`, then :func:`parse_json`."""
    return parse_json(read_bounded(path, max_bytes))


def atomic_write(path: str | os.PathLike[str], data: bytes, *, durable: bool = False) -> Path:
    """Write ``data`` to a unique temporary file beside ``path`` and rename it into place
    (parents are created). ``durable`` also fsyncs the bytes before the rename, for files a
    killed run must find whole (run logs)."""
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = target.with_name(f".{target.name}.{os.getpid()}.{uuid.uuid4().hex}.tmp")
    try:
        with open(tmp, "wb") as fh:
            fh.write(data)
            if durable:
                fh.flush()
                os.fsync(fh.fileno())
        os.replace(tmp, target)
    finally:
        tmp.unlink(missing_ok=True)
    return target


@contextmanager
def atomic_path(path: str | os.PathLike[str], *, durable: bool = False) -> Iterator[Path]:
    """A unique temporary path beside ``path`` (same suffix, for writers that choose a format by
    it) to write to; renamed into place when the block ends, removed when it raises (a full
    disk leaves no partial file under the real name). ``durable`` fsyncs it first."""
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = target.with_name(f".{target.stem}.{os.getpid()}.{uuid.uuid4().hex[:12]}{target.suffix}")
    try:
        yield tmp
        if durable:
            fd = os.open(tmp, os.O_RDONLY)
            try:
                os.fsync(fd)
            finally:
                os.close(fd)
        os.replace(tmp, target)
    finally:
        tmp.unlink(missing_ok=True)


class FolderBusy(ChainGeoError, RuntimeError):
    """Another process is writing the same output folder."""


def lock_folder(folder: str | os.PathLike[str]) -> int:
    """Take the advisory lock of an output folder (``fcntl.flock`` on ``.NAME.lock`` beside it,
    so the folder itself may be created, replaced or renamed under it) and return its
    descriptor; :class:`FolderBusy` naming the holder's process when another has it. The lock
    ends with the descriptor (:func:`unlock_folder`, or the process' end, even by SIGKILL)."""
    import fcntl

    target = Path(folder).absolute()
    target.parent.mkdir(parents=True, exist_ok=True)
    lock = target.with_name(f".{target.name}.lock")
    fd = os.open(lock, os.O_RDWR | os.O_CREAT | getattr(os, "O_CLOEXEC", 0), 0o644)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        holder = os.pread(fd, 32, 0).decode("ascii", "replace").strip() or "?"
        os.close(fd)
        raise FolderBusy(
            f"{target}: another chain process (pid {holder}) is writing it; "
            "wait for it to finish or choose another folder"
        ) from None
    except OSError:
        os.close(fd)
        raise
    os.ftruncate(fd, 0)
    os.pwrite(fd, f"{os.getpid()}\n".encode("ascii"), 0)
    return fd


def unlock_folder(fd: int) -> None:
    """Release a lock taken by :func:`lock_folder`."""
    os.close(fd)


@contextmanager
def folder_locked(folder: str | os.PathLike[str]) -> Iterator[Path]:
    """``with folder_locked(out):`` holds :func:`lock_folder` for the block."""
    fd = lock_folder(folder)
    try:
        yield Path(folder)
    finally:
        unlock_folder(fd)
