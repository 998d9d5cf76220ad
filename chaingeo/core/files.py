"""Files in and out: the one bounded reader of input files and the one atomic-write helper
(a reader never sees half of a file we write)."""

from __future__ import annotations

import os
import stat
import uuid
from pathlib import Path

from chaingeo.core.errors import ChainGeoError


class UnreadableFile(ChainGeoError):
    """An input file that cannot be read as given; ``reason`` says why (the caller names the
    file in its own error type)."""

    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


def read_bounded(path: str | os.PathLike[str], max_bytes: int) -> bytes:
    """The bytes of a regular file of at most ``max_bytes``, refused before reading when it is
    larger or not a regular file (a FIFO would block the read forever)."""
    try:
        st = Path(path).stat()
        if not stat.S_ISREG(st.st_mode):
            raise UnreadableFile("not a regular file")
        if st.st_size > max_bytes:
            raise UnreadableFile(f"{st.st_size} bytes; at most {max_bytes}")
        with open(path, "rb") as fh:
            raw = fh.read(max_bytes + 1)
    except OSError as e:
        raise UnreadableFile(f"cannot read: {e.strerror or e}") from None
    if len(raw) > max_bytes:  # it grew since stat
        raise UnreadableFile(f"more than {max_bytes} bytes")
    return raw


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
