"""Typed, bounded field access for reading ``chain-level/1`` files (see :mod:`chaingeo.core.level`):
every problem becomes one :class:`LevelError` naming the source, the field and the reason."""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from typing import Any

from chaingeo.core import limits
from chaingeo.core.errors import ChainGeoError
from chaingeo.core.geometry import Shape


class LevelError(ChainGeoError, ValueError):
    """A level that cannot be loaded or is not valid: which file, which field, and why."""

    def __init__(self, source: str, field: str, reason: str) -> None:
        super().__init__(f"{source}: {field}: {reason}")
        self.source = source
        self.field = field
        self.reason = reason


class Reader:
    """Typed field access that turns every problem into a LevelError for one source."""

    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, fld: str, reason: str) -> LevelError:
        return LevelError(self.source, fld, reason)

    def get(self, obj: Mapping[str, Any], key: str, fld: str) -> Any:
        if key not in obj:
            raise self.fail(fld, "missing field")
        return obj[key]

    def obj(self, value: Any, fld: str) -> Mapping[str, Any]:
        if not isinstance(value, dict):
            raise self.fail(fld, f"expected an object, got {kind_of(value)}")
        return value

    def lst(self, value: Any, fld: str) -> list[Any]:
        if not isinstance(value, list):
            raise self.fail(fld, f"expected a list, got {kind_of(value)}")
        return value

    def string(self, value: Any, fld: str, choices: Sequence[str] | None = None) -> str:
        if not isinstance(value, str):
            raise self.fail(fld, f"expected a string, got {kind_of(value)}")
        if choices is not None and value not in choices:
            raise self.fail(fld, f"{value!r} is not one of {list(choices)}")
        return value

    def integer(
        self, value: Any, fld: str, minimum: int | None = None, maximum: int | None = None
    ) -> int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.fail(fld, f"expected an integer, got {kind_of(value)}")
        if minimum is not None and value < minimum:
            raise self.fail(fld, f"must be >= {minimum}, got {value}")
        if maximum is not None and value > maximum:
            raise self.fail(fld, f"must be <= {maximum}, got {value}")
        return value

    def coord(self, value: Any, fld: str) -> int:
        return self.integer(value, fld, -limits.MAX_COORD, limits.MAX_COORD)

    def opt_integer(self, value: Any, fld: str) -> int | None:
        return None if value is None else self.integer(value, fld)

    def voxels(self, value: Any, fld: str) -> Shape:
        cells = self.lst(value, fld)
        if not cells:
            raise self.fail(fld, "a piece needs at least one voxel")
        if len(cells) > limits.MAX_PIECE_VOXELS:
            raise self.fail(
                fld, f"{len(cells)} voxels; a piece has at most {limits.MAX_PIECE_VOXELS}"
            )
        out: list[tuple[int, int, int]] = []
        seen: set[tuple[int, int, int]] = set()
        for i, c in enumerate(cells):
            f = f"{fld}[{i}]"
            if not (isinstance(c, list) and len(c) == 3):
                raise self.fail(f, f"a voxel is a list of three integers, got {short(c)}")
            cell = (self.coord(c[0], f), self.coord(c[1], f), self.coord(c[2], f))
            if cell in seen:
                raise self.fail(fld, f"voxel {list(cell)} is listed twice")
            seen.add(cell)
            out.append(cell)
        return Shape(out)


def kind_of(value: Any) -> str:
    return "null" if value is None else type(value).__name__


def short(value: Any) -> str:
    """``repr`` cut to a line, so an error message never echoes a huge value."""
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


def only_keys(
    r: Reader, obj: Mapping[str, Any], allowed: set[str], fld: str, what: str = "rule"
) -> None:
    extra = sorted(set(obj) - allowed)
    if extra:
        raise r.fail(f"{fld}.{extra[0]}", f"unknown {what}; known: {sorted(allowed)}")


def decode_json(text: str, source: str) -> Any:
    """``json.loads`` within :mod:`chaingeo.core.limits`; :class:`LevelError` otherwise."""
    try:
        return limits.loads_bounded(text)
    except limits.LimitError as e:
        raise LevelError(source, e.field or "(file)", e.reason) from None
    except json.JSONDecodeError as e:
        raise LevelError(
            source, "(file)", f"invalid JSON at line {e.lineno} column {e.colno}: {e.msg}"
        ) from None
    except (ValueError, RecursionError) as e:  # defensive: never a traceback for a file
        raise LevelError(source, "(file)", f"invalid JSON: {type(e).__name__}") from None
