"""The run directory: a header, one JSONL record per episode, images by content hash.

Layout of ``RUN/``::

    header.json      what was run: git commit, package versions, level-set hash, agent config,
                     protocol, seeds (canonical JSON; never a secret)
    episodes.jsonl   one line per finished episode, appended and fsynced as it finishes
    images/          PNG files named ``<sha256>.png``; records refer to them by name

A killed run leaves at most one partial line at the end of ``episodes.jsonl``; reading ignores
it and resuming cuts it off before appending, so no finished episode is lost and none is
recorded twice. Everything written passes through :mod:`chaingeo.evaluation.sanitize` with
:meth:`RunLog.redact`, which replaces each registered secret (API keys) wherever it appears, so
a key echoed back by a server never lands in a log either; there text is made encodable, numbers
finite and each record bounded in bytes, so a hostile reply can neither stop the writer nor fill
the disk.
"""

from __future__ import annotations

import datetime as _dt
import hashlib
import json
import os
import platform
import shutil
import subprocess
import tempfile
from collections.abc import Iterable, Mapping
from importlib import metadata
from pathlib import Path
from typing import Any, Final

from chaingeo.core import canonical_json, limits
from chaingeo.core.errors import ChainGeoError
from chaingeo.core.files import (
    UnreadableFile,
    atomic_write,
    lock_folder,
    parse_json,
    read_bounded,
    read_json,
    unlock_folder,
)
from chaingeo.evaluation.records import header_problem, record_problem
from chaingeo.evaluation.sanitize import clean, dumps_line

RUN_FORMAT: Final = "chain-run/1"
HEADER: Final = "header.json"
EPISODES: Final = "episodes.jsonl"
IMAGES: Final = "images"
REDACTED: Final = "[REDACTED]"
#: Header fields that must match for ``--resume`` to continue a run.
IDENTITY_FIELDS: Final = ("agent", "protocol", "level_set_hash", "seed", "samples", "levels")
PACKAGES: Final = (
    "chaingeo",
    "numpy",
    "numba",
    "pillow",
    "matplotlib",
    "trimesh",
    "manifold3d",
)


class RunError(ChainGeoError, ValueError):
    """A run directory that cannot be used as asked (exists, differs, unreadable)."""


def git_commit(start: Path | None = None) -> dict[str, Any]:
    """The commit of the checkout holding this package (and whether files were modified)."""
    root = start or Path(__file__).resolve().parents[2]
    try:
        head = subprocess.run(
            ["git", "-C", str(root), "rev-parse", "HEAD"],
            capture_output=True,
            text=True,
            timeout=10,
            check=True,
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "-C", str(root), "status", "--porcelain", "--untracked-files=no"],
            capture_output=True,
            text=True,
            timeout=10,
            check=True,
        ).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return {"commit": None, "dirty": None}
    return {"commit": head, "dirty": bool(dirty)}


def package_versions(names: Iterable[str] = PACKAGES) -> dict[str, str | None]:
    out: dict[str, str | None] = {"python": platform.python_version()}
    for name in names:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = None
    return out


def make_header(
    *,
    agent: Mapping[str, Any],
    protocol: Mapping[str, Any],
    level_set_hash: str,
    levels: Iterable[str],
    seed: int,
    samples: int,
    extra: Mapping[str, Any] | None = None,
) -> dict[str, Any]:
    return {
        "format": RUN_FORMAT,
        "created": _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "git": git_commit(),
        "packages": package_versions(),
        "platform": platform.platform(),
        "agent": dict(agent),
        "protocol": dict(protocol),
        "level_set_hash": level_set_hash,
        "levels": sorted(levels),
        "seed": seed,
        "samples": samples,
        **dict(extra or {}),
    }


def episode_key(level_id: str, sample: int) -> str:
    return f"{level_id}#{sample}"


class RunLog:
    """Writer and reader of one run directory."""

    def __init__(self, path: str | os.PathLike[str], secrets: Iterable[str] = ()) -> None:
        self.path = Path(path)
        self._secrets = sorted({s for s in secrets if s}, key=len, reverse=True)
        self._lock: int | None = None

    # -- opening ---------------------------------------------------------------------------

    @staticmethod
    def create(
        path: str | os.PathLike[str],
        header: Mapping[str, Any],
        *,
        resume: bool = False,
        secrets: Iterable[str] = (),
    ) -> RunLog:
        """Start a new run, or with ``resume`` continue one whose header agrees. The folder's
        lock is held until :meth:`close` (a second writer is refused: two resumes at once
        recorded episodes twice); a new run is made whole in a temporary folder and renamed
        into place, so a full disk leaves no half run that ``--resume`` would refuse."""
        log = RunLog(path, secrets)
        log._lock = lock_folder(log.path)
        try:
            log._open(header, resume)
        except BaseException:
            log.close()
            raise
        return log

    def _open(self, header: Mapping[str, Any], resume: bool) -> None:
        if (self.path / HEADER).exists():
            if not resume:
                raise RunError(f"{self.path}: a run is already there; pass --resume to continue it")
            old = self.header()
            for key in IDENTITY_FIELDS:
                if old.get(key) != header.get(key):
                    raise RunError(
                        f"{self.path}: cannot resume: {key} differs from the recorded run "
                        f"({_short(old.get(key))} there, {_short(header.get(key))} now)"
                    )
            self._drop_partial_tail()
            return
        if self.path.exists() and (not self.path.is_dir() or any(self.path.iterdir())):
            raise RunError(f"{self.path}: exists and is not a run directory")
        text = canonical_json.dumps(clean(dict(header), redact=self.redact))
        fresh = Path(tempfile.mkdtemp(prefix=f".{self.path.name}.", dir=self.path.parent))
        try:
            fresh.chmod(0o755)
            (fresh / IMAGES).mkdir()
            atomic_write(fresh / HEADER, self.redact(text).encode("utf-8"), durable=True)
            (fresh / EPISODES).touch()
            if self.path.exists():
                self.path.rmdir()  # empty, checked above
            fresh.rename(self.path)
        finally:
            shutil.rmtree(fresh, ignore_errors=True)

    def close(self) -> None:
        """Release the folder's lock (a writer's; readers never take it)."""
        if self._lock is not None:
            unlock_folder(self._lock)
            self._lock = None

    def header(self) -> dict[str, Any]:
        """The header, read with the bounded JSON reader and checked (:func:`header_problem`)."""
        try:
            data = read_json(self.path / HEADER, limits.MAX_RUN_HEADER_BYTES)
        except UnreadableFile as e:
            raise RunError(f"{self.path}: no readable {HEADER}: {e.reason}") from None
        if not isinstance(data, dict) or data.get("format") != RUN_FORMAT:
            raise RunError(f"{self.path}/{HEADER}: not a {RUN_FORMAT} header")
        problem = header_problem(data)
        if problem:
            raise RunError(f"{self.path}/{HEADER}: {problem}")
        return data

    # -- writing ---------------------------------------------------------------------------

    def redact(self, text: str) -> str:
        for secret in self._secrets:
            text = text.replace(secret, REDACTED)
        return text

    def append(self, record: Mapping[str, Any]) -> None:
        """One line (sanitised and bounded), written whole, flushed and fsynced."""
        data = (dumps_line(record, self.redact) + "\n").encode("utf-8")
        fd = os.open(self.path / EPISODES, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
        try:
            view = memoryview(data)
            while view:
                n = os.write(fd, view)
                view = view[n:]
            os.fsync(fd)
        finally:
            os.close(fd)

    def put_image(self, png: bytes) -> str:
        """Store a PNG under its SHA-256 (once) and return the file name records use."""
        name = hashlib.sha256(png).hexdigest() + ".png"
        target = self.path / IMAGES / name
        if not target.exists():
            target.parent.mkdir(parents=True, exist_ok=True)
            atomic_write(target, png, durable=True)
        return name

    def _drop_partial_tail(self) -> None:
        """Cut a last line that a killed writer left unfinished."""
        file = self.path / EPISODES
        if not file.exists():
            file.touch()
            return
        try:
            data = read_bounded(file, limits.MAX_RUN_LOG_BYTES)
        except UnreadableFile as e:
            raise RunError(f"{file}: {e.reason}") from None
        keep = data.rfind(b"\n") + 1
        if keep != len(data):
            with open(file, "r+b") as fh:
                fh.truncate(keep)
                fh.flush()
                os.fsync(fh.fileno())

    # -- reading ---------------------------------------------------------------------------

    def records(self) -> list[dict[str, Any]]:
        """Every complete record, in file order (a partial last line is ignored)."""
        return read_records(self.path / EPISODES)

    def latest(self) -> dict[str, dict[str, Any]]:
        """The last record of each episode key (a retried episode replaces its error)."""
        out: dict[str, dict[str, Any]] = {}
        for rec in self.records():
            out[str(rec["key"])] = rec
        return out

    def finished_keys(self, retry_errors: bool = False) -> set[str]:
        return {
            k for k, r in self.latest().items() if not (retry_errors and r.get("status") == "error")
        }


def read_records(file: Path) -> list[dict[str, Any]]:
    """The records of ``episodes.jsonl``, each line through the bounded JSON reader and checked
    field by field (:func:`record_problem`); RunError naming the line otherwise."""
    try:
        data = read_bounded(file, limits.MAX_RUN_LOG_BYTES)
    except UnreadableFile as e:
        raise RunError(f"{file}: {e.reason}") from None
    lines = data.split(b"\n")
    out: list[dict[str, Any]] = []
    for i, raw in enumerate(lines):
        if not raw.strip():
            continue
        try:
            rec = parse_json(raw)
        except UnreadableFile as e:
            if i == len(lines) - 1:  # unfinished last line of a killed run
                break
            raise RunError(f"{file}: line {i + 1}: {e.reason}") from None
        problem = record_problem(rec)
        if problem:
            raise RunError(f"{file}: line {i + 1} is not an episode record: {problem}")
        out.append(rec)
    return out


def _short(value: Any) -> str:
    text = json.dumps(value, sort_keys=True)
    return text if len(text) <= 80 else text[:77] + "..."
