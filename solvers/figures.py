"""The figures of one analysed puzzle as a typed value: what :func:`chaingeo.analyze` returns and
``chain analyze`` prints (:meth:`PuzzleFigures.to_json`, one JSON line).

Why a class and not the dict it replaces: a caller reads ``figures.level`` and its type checker
knows it is ``str | None``; the JSON stays byte for byte what the command printed before.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field, fields
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from chaingeo.core.kinematics import Move
    from chaingeo.core.turns import TurnMove

__all__ = ["PuzzleFigures"]

#: Keys every figures object of one puzzle (or problem) carries, null when unknown.
ALWAYS: tuple[str, ...] = ("assemblies", "solutions", "level", "moves", "optimal_steps")
#: Keys written only when set (``counts_complete`` only when false).
OPTIONAL: tuple[str, ...] = (
    "convention",
    "problem",
    "name",
    "limit",
    "limit_cap",
    "optimal_error",
    "optimal_limit_cap",
    "optimal_bounds",
    "disassembly_error",
)
#: What the run adds at the top: the source named, the kernels' mode, the wall time.
META: tuple[str, ...] = ("file", "kernels", "seconds")


@dataclass(frozen=True)
class PuzzleFigures:
    """Assemblies, solutions, level, moves and o_i of a puzzle (or of one problem of a
    BurrTools file); a file of several problems analysed whole has them in ``problems`` and
    its own figures None (``several`` true, even when the file has no problem).

    ``counts_complete`` false: a cap (``limit``, the field of ``SearchLimits`` in
    ``limit_cap``) cut counting short and the counts are lower bounds. ``optimal_error``: why o_i
    is unknown (``optimal_limit_cap`` the cap reached; ``optimal_bounds`` what the search proved
    by then: ``lo <= o_i <= hi``). ``plan``: one optimal full disassembly
    when o_i was searched (not written to JSON). ``convention``: how the counts treat mirror
    images (``burrtxt``: an assembly and its mirror image are one, as burrTxt prints;
    ``mirrors-kept``: BurrTools' stored figures); None when nothing was counted."""

    assemblies: int | None = None
    solutions: int | None = None
    level: str | None = None
    moves: int | None = None
    optimal_steps: int | None = None
    counts_complete: bool = True
    convention: str | None = None
    limit: str | None = None
    limit_cap: str | None = None
    optimal_error: str | None = None
    optimal_limit_cap: str | None = None
    optimal_bounds: tuple[int, int] | None = None
    disassembly_error: str | None = None
    problem: int | None = None
    name: str | None = None
    problems: tuple[PuzzleFigures, ...] = ()
    several: bool = False
    file: str | None = None
    kernels: str | None = None
    seconds: float | None = None
    plan: tuple[Move | TurnMove, ...] = field(default=(), compare=False, repr=False)

    @property
    def o_i(self) -> int | None:
        """The fewest moves of any full disassembly (the paper's o_i): ``optimal_steps``."""
        return self.optimal_steps

    @classmethod
    def from_dict(cls, row: Mapping[str, Any]) -> PuzzleFigures:
        """The figures of a dict as :meth:`to_dict` writes it (``plan`` may ride along)."""
        known = {f.name for f in fields(cls)} - {"several"}
        unknown = sorted(set(row) - known)
        if unknown:
            raise ValueError(f"not a figures key: {', '.join(unknown)}")
        kw = dict(row)
        kw["problems"] = tuple(cls.from_dict(p) for p in row.get("problems", ()))
        kw["several"] = "problems" in row
        kw["plan"] = tuple(row.get("plan", ()))
        if row.get("optimal_bounds") is not None:
            lo, hi = row["optimal_bounds"]
            kw["optimal_bounds"] = (int(lo), int(hi))
        return cls(**kw)

    @classmethod
    def from_json(cls, text: str) -> PuzzleFigures:
        return cls.from_dict(json.loads(text))

    def to_dict(self, flags: Mapping[str, str] | None = None) -> dict[str, Any]:
        """The JSON object; with ``flags`` (a cap's field -> the option that raises it) the
        ``limit`` and ``optimal_error`` texts name that option and the ``*_cap`` keys go, as
        ``chain analyze`` prints them."""
        out: dict[str, Any] = {k: getattr(self, k) for k in META if getattr(self, k) is not None}
        if self.several:
            out["problems"] = [p.to_dict(flags) for p in self.problems]
            return out
        out.update({k: getattr(self, k) for k in ALWAYS})
        out.update({k: getattr(self, k) for k in OPTIONAL if getattr(self, k) is not None})
        if self.optimal_bounds is not None:
            out["optimal_bounds"] = list(self.optimal_bounds)
        if not self.counts_complete:
            out["counts_complete"] = False
        if flags is not None:
            for cap, text in (("limit_cap", "limit"), ("optimal_limit_cap", "optimal_error")):
                cap_field = out.pop(cap, None)
                if text in out:
                    out[text] = with_flag(out[text], cap_field, flags)
        return out

    def to_json(self, flags: Mapping[str, str] | None = None) -> str:
        """One line of JSON, keys sorted (see :meth:`to_dict`)."""
        return json.dumps(self.to_dict(flags), sort_keys=True)

    def cut_short(self) -> list[PuzzleFigures]:
        """The figures (this one or its problems) whose counting a cap cut short."""
        return [f for f in (self, *self.problems) if not f.counts_complete]


def with_flag(reason: str, cap: str | None, flags: Mapping[str, str]) -> str:
    """``reason`` and the option that raises cap ``cap`` (a ``SearchLimits`` field), if any."""
    flag = flags.get(cap or "")
    return f"{reason}; raise it with {flag}" if flag else reason
