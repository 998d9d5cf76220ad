"""De-duplication by puzzle signature, with an atomic reservation per signature on disk.

A level is accepted only after its signature is *reserved*: a file named by the signature is
created in ``OUT/signatures/`` with the accepting level's id as its content. Creation is one
atomic ``link(2)`` of a fully written temporary file (so the content is never seen half
written), falling back to ``open(O_CREAT | O_EXCL)`` where hard links are not supported. Two
processes, or two machines sharing the folder, can therefore never both accept one puzzle.

Determinism (item ``i`` of seed ``s`` is the same bytes whatever the number of workers): the
reservation alone would make *which* of two equal puzzles wins depend on timing. So workers
never reserve: ``make`` stays a pure function of (config, seed, index), and the batch runner,
the only process that writes, takes results strictly in index order and reserves there. Within
a run the lowest index wins, whatever the parallelism; across runs sharing a folder, the
signatures already reserved count as taken, except by the very level that reserved them, so
re-running a command is idempotent.
"""

from __future__ import annotations

import errno
import os
import re
import uuid
from enum import Enum
from pathlib import Path
from typing import Final

_SIGNATURE_RE: Final = re.compile(r"[0-9a-f]{8,128}")
SIGNATURES_DIR: Final = "signatures"


class Reservation(Enum):
    NEW = "new"  # reserved now, for this owner
    OWN = "own"  # already reserved by this same owner (a re-run)
    TAKEN = "taken"  # reserved by another level


class SignatureStore:
    """The reservations of one output folder."""

    def __init__(self, folder: str | os.PathLike[str]) -> None:
        self.folder = Path(folder) / SIGNATURES_DIR
        self.folder.mkdir(parents=True, exist_ok=True)

    def _path(self, signature: str) -> Path:
        if not _SIGNATURE_RE.fullmatch(signature):
            raise ValueError(f"signature {signature!r} is not a lowercase hex digest")
        return self.folder / signature

    def owner(self, signature: str) -> str | None:
        """The id of the level holding ``signature``, or None if it is free."""
        try:
            return self._path(signature).read_text(encoding="utf-8")
        except FileNotFoundError:
            return None

    def reserve(self, signature: str, owner: str) -> Reservation:
        """Atomically claim ``signature`` for ``owner`` (a level id)."""
        target = self._path(signature)
        if _create_exclusive(target, owner):
            return Reservation.NEW
        return Reservation.OWN if self.owner(signature) == owner else Reservation.TAKEN

    def release(self, signature: str, owner: str) -> None:
        """Give a reservation back (only its owner may), e.g. when writing the level failed."""
        if self.owner(signature) == owner:
            self._path(signature).unlink()

    def signatures(self) -> list[str]:
        return sorted(p.name for p in self.folder.iterdir() if _SIGNATURE_RE.fullmatch(p.name))


def _create_exclusive(target: Path, content: str) -> bool:
    """Create ``target`` holding ``content`` unless it exists; True if this call created it."""
    tmp = target.with_name(f".{target.name}.{os.getpid()}.{uuid.uuid4().hex}.tmp")
    tmp.write_text(content, encoding="utf-8")
    try:
        os.link(tmp, target)
        return True
    except FileExistsError:
        return False
    except OSError as e:  # no hard links here (some network or FAT file systems)
        if e.errno not in (errno.EPERM, errno.ENOTSUP, errno.EOPNOTSUPP, errno.EXDEV):
            raise
        try:
            fd = os.open(target, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
        except FileExistsError:
            return False
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(content)
        return True
    finally:
        tmp.unlink(missing_ok=True)
