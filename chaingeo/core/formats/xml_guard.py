"""XML from other people's files: no DTD reaches a parser that would expand it.

A DOCTYPE can declare entities that expand without bound (the "billion laughs") or name
external files. ElementTree expands internal entities, so :func:`doctype_problem` looks first,
with expat itself: it decodes the bytes exactly as ElementTree's expat will (the byte order
mark, the declared encoding, UTF-16 in either order), so no encoding hides a declaration from
it, and it stops at the first element, before which any DOCTYPE must stand. Searching the raw
bytes for ``<!DOCTYPE`` misses it in UTF-16.
"""

from __future__ import annotations

from typing import Any
from xml.parsers import expat

from chaingeo.core.errors import ChainGeoError


class _Stop(ChainGeoError):
    """Raised from an expat handler to end the scan; ``reason`` None means the XML is clean."""

    def __init__(self, reason: str | None) -> None:
        super().__init__(reason)
        self.reason = reason


def _refuse(what: str) -> Any:
    def handler(*_: Any) -> None:
        raise _Stop(f"{what} is not allowed (entities could expand without bound)")

    return handler


def _clean(*_: Any) -> None:
    raise _Stop(None)


def doctype_problem(data: bytes) -> str | None:
    """Why ``data`` may not be parsed (a DOCTYPE or entity declaration, or XML expat cannot
    even read up to its first element), or None when the prolog is clean."""
    parser = expat.ParserCreate()
    parser.StartDoctypeDeclHandler = _refuse("a DOCTYPE")
    parser.EntityDeclHandler = _refuse("an entity declaration")
    parser.StartElementHandler = _clean
    try:
        parser.Parse(data, True)
    except _Stop as stop:
        return stop.reason
    except expat.ExpatError as e:
        return f"invalid XML: {expat.ErrorString(e.code)} at line {e.lineno} column {e.offset}"
    except ValueError as e:  # e.g. an encoding expat cannot use
        return f"invalid XML: {e}"
    return "invalid XML: no element"
