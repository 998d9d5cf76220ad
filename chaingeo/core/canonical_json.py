"""Canonical JSON: sorted keys, two-space indent, short lists on one line, a final newline.

The same value always gives the same bytes, so files diff cleanly and hash stably.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Mapping, Sequence

_SCALARS = (str, int, float, bool, type(None))


def _is_flat(value: object) -> bool:
    """A list of scalars, or a list of lists of scalars (voxel lists): written on one line."""
    if not isinstance(value, list | tuple):
        return False
    return all(
        isinstance(v, _SCALARS)
        or (isinstance(v, list | tuple) and all(isinstance(w, _SCALARS) for w in v))
        for v in value
    )


def _finite(value: object, path: str) -> None:
    """JSON has no NaN or infinity: say which value is one (``json.dumps`` would not)."""
    if isinstance(value, float) and not math.isfinite(value):
        raise ValueError(f"{path or '(top level)'}: {value} is not a finite number")
    if isinstance(value, list | tuple):
        for i, v in enumerate(value):
            _finite(v, f"{path}[{i}]")


def _scalars(value: object, path: str, separators: tuple[str, str] | None) -> str:
    """``json.dumps`` of a scalar or flat list; the path is looked for only when it fails."""
    try:
        return json.dumps(value, separators=separators, allow_nan=False)
    except ValueError:
        _finite(value, path)
        raise


def _encode(value: object, indent: int, path: str = "") -> str:
    pad = "  " * indent
    inner = "  " * (indent + 1)
    if isinstance(value, Mapping):
        if not value:
            return "{}"
        keys = sorted(value)
        if any(not isinstance(k, str) for k in keys):
            raise TypeError("canonical JSON needs string keys")
        items = [
            f"{inner}{json.dumps(k)}: {_encode(value[k], indent + 1, f'{path}.{k}' if path else k)}"
            for k in keys
        ]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(value, list | tuple):
        if _is_flat(value):
            return _scalars(value, path, (", ", ": "))
        items = [f"{inner}{_encode(v, indent + 1, f'{path}[{i}]')}" for i, v in enumerate(value)]
        return "[\n" + ",\n".join(items) + "\n" + pad + "]"
    if isinstance(value, _SCALARS):
        return _scalars(value, path, None)
    raise TypeError(f"not JSON-serialisable: {type(value).__name__}")


def dumps(value: Mapping[str, object] | Sequence[object]) -> str:
    """The canonical text; a ``ValueError`` naming the path of a non-finite number."""
    return _encode(value, 0) + "\n"


def sha256_hex(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()
