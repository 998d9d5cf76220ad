"""The one sanitiser every logged (or printed) value passes through.

Model servers send whatever they like: lone surrogates (valid in a Python ``str`` from
``json.loads``, not encodable as UTF-8), non-finite numbers, megabytes of text. A log line must
still be written, whole and in bounds, so that one hostile reply never stops a run or fills a
disk. Here: invalid code points become U+FFFD, non-finite floats become ``null``, secrets are
redacted before anything is cut (a cut can never leave half a key), strings longer than a cap
keep their head plus their length and SHA-256, each reply's record fits
:data:`~chaingeo.core.limits.MAX_LOG_REPLY_BYTES` and an episode's
:data:`~chaingeo.core.limits.MAX_LOG_EPISODE_BYTES` (later steps then keep only their outcome).
"""

from __future__ import annotations

import hashlib
import json
import math
import re
from collections.abc import Callable, Mapping
from typing import Any, Final

from chaingeo.core import limits

#: Every surrogate code point: in a ``str`` each one is unpaired, so none can be encoded.
_SURROGATE_RE: Final = re.compile("[\ud800-\udfff]")
#: A data URL of base64 bytes (an image a model pasted into its reply).
_DATA_URL_RE: Final = re.compile(r"data:[\w.+-]{1,40}/[\w.+-]{1,40};base64,[A-Za-z0-9+/=]{256,}")
#: The field caps tried, longest first, until a reply's record fits its budget; the last keeps
#: an image's file name (64 hex digits + ``.png``) whole.
_CAPS: Final = (limits.MAX_LOG_FIELD_CHARS, 2048, 256, 80)
#: Step fields kept when the episode's budget is spent: the outcome and what was played (for
#: `replay`), never the reply.
_OUTCOME_FIELDS: Final = ("turn", "call", "sent", "action", "legal", "error", "usage", "images")

Redact = Callable[[str], str]


def _same(text: str) -> str:
    return text


def clean_text(text: str) -> str:
    """``text`` with every code point UTF-8 cannot encode (lone surrogates) as U+FFFD."""
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:
        return _SURROGATE_RE.sub("\ufffd", text)
    return text


def _digest(text: str) -> str:
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def _data_url(match: re.Match[str]) -> str:
    head, _, data = match.group(0).partition(",")
    return f"{head},[{len(data)} characters, sha256 {_digest(data)}]"


def shorten(text: str, cap: int) -> str:
    """``text`` whole when it has at most ``cap`` characters, else its head and a marker with
    its length and SHA-256 (base64 data URLs are always replaced by such a marker)."""
    if len(text) >= 256 and ";base64," in text:
        text = _DATA_URL_RE.sub(_data_url, text)
    if len(text) <= cap:
        return text
    return f"{text[:cap]} [... truncated: {len(text)} characters, sha256 {_digest(text)}]"


def clean(value: Any, cap: int = limits.MAX_LOG_FIELD_CHARS, redact: Redact = _same) -> Any:
    """A JSON value safe to write: text cleaned, redacted and shortened to ``cap``, non-finite
    floats as ``None``, tuples as lists, anything else as its (cleaned) text."""
    if isinstance(value, str):
        return shorten(redact(clean_text(value)), cap)
    if value is None or isinstance(value, bool | int):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, Mapping):
        return {clean(str(k), cap, redact): clean(v, cap, redact) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [clean(v, cap, redact) for v in value]
    return clean(str(value), cap, redact)


def size(value: Any) -> int:
    """Bytes of ``value`` as a log line writes it (a cleaned value)."""
    return len(json.dumps(value, ensure_ascii=False, allow_nan=False).encode("utf-8"))


def fit(value: Any, budget: int, redact: Redact = _same) -> Any:
    """``value`` cleaned with the longest field cap that keeps it within ``budget`` bytes (the
    shortest cap when none does: its size is then bounded by its shape alone)."""
    out = value
    for cap in _CAPS:
        out = clean(value, cap, redact)
        if size(out) <= budget:
            break
    return out


def _outcome(step: Mapping[str, Any], redact: Redact) -> dict[str, Any]:
    kept = {k: step[k] for k in _OUTCOME_FIELDS if k in step}
    return {**clean(kept, _CAPS[-1], redact), "compacted": True}


def bound_record(record: Mapping[str, Any], redact: Redact = _same) -> dict[str, Any]:
    """An episode record cleaned and within its budgets: every step and the plan within the
    reply budget, the whole within the episode budget (steps past it compacted to outcomes,
    counted in ``log_compacted_steps``)."""
    steps = record.get("steps")
    rest = {k: v for k, v in record.items() if k not in ("steps", "plan")}
    out: dict[str, Any] = fit(rest, limits.MAX_LOG_REPLY_BYTES, redact)
    if "plan" in record:
        out["plan"] = fit(record["plan"], limits.MAX_LOG_REPLY_BYTES, redact)
    if not isinstance(steps, list | tuple):
        if steps is not None:
            out["steps"] = clean(steps, _CAPS[-1], redact)
        return out
    used = size(out)
    kept: list[Any] = []
    compacted = 0
    for step in steps:
        item = fit(step, limits.MAX_LOG_REPLY_BYTES, redact)
        if used + size(item) > limits.MAX_LOG_EPISODE_BYTES and isinstance(step, Mapping):
            item = _outcome(step, redact)
            compacted += 1
        used += size(item) + 1
        kept.append(item)
    out["steps"] = kept
    if compacted:
        out["log_compacted_steps"] = compacted
    return out


def dumps_line(value: Mapping[str, Any], redact: Redact = _same) -> str:
    """One JSON log line of an episode record: bounded, cleaned, finite, redacted."""
    record = bound_record(value, redact)
    return redact(json.dumps(record, sort_keys=True, ensure_ascii=False, allow_nan=False))
