"""Split signatures: what makes two levels "the same puzzle" for keeping training data out of
the shipped test suite.

The dedup signature (``provenance.signature``) is the multiset of piece shapes only. A training
level leaks when a model could have seen the test level's answer, so the split signature adds
what the answer depends on: the box (stacking, sizes sorted: a box is the same box turned) or
the assembled shape (puzzles, up to translation and the 24 rotations). Goals are left out on
purpose: an assembly level teaches its disassembly's answer and the other way round.
"""

from __future__ import annotations

import hashlib
from collections.abc import Iterable, Sequence
from functools import cache
from pathlib import Path

from chaingeo.core.geometry import Shape
from chaingeo.core.level import Level, load_levels
from chaingeo.core.suite import suite_folder

#: Bump when the recipe changes (it is hashed in, so old and new never compare equal).
SIGNATURE_VERSION = "split/1"


def _form_text(shape: Shape) -> str:
    return ",".join(f"{x} {y} {z}" for x, y, z in shape.canonical().cells)


def _digest(parts: Iterable[str]) -> str:
    return hashlib.sha1("|".join(parts).encode("ascii")).hexdigest()


def stacking_signature(shapes: Iterable[Shape], box: Sequence[int]) -> str:
    """The piece multiset up to rotation, plus the box up to rotation (its sorted sizes)."""
    forms = sorted(_form_text(s) for s in shapes)
    dims = "x".join(str(int(v)) for v in sorted(box))
    return _digest([SIGNATURE_VERSION, "stacking", dims, ";".join(forms)])


def puzzle_signature(assembled: Iterable[Shape]) -> str:
    """The assembled shape up to translation and the 24 rotations, plus the piece multiset up
    to rotation; ``assembled``: every piece in its assembled position."""
    shapes = list(assembled)
    whole = Shape([c for s in shapes for c in s.cells])
    forms = sorted(_form_text(s) for s in shapes)
    return _digest([SIGNATURE_VERSION, "puzzle", _form_text(whole), ";".join(forms)])


def level_signature(level: Level) -> str:
    """The split signature of a level of either family."""
    shapes = [p.shape for p in level.pieces]
    if level.family == "stacking":
        assert level.box is not None
        return stacking_signature(shapes, level.box)
    return puzzle_signature(shapes)


def suite_signatures(folder: str | Path) -> frozenset[str]:
    """The split signatures of every level under ``folder``."""
    return frozenset(level_signature(lv) for lv in load_levels(folder))


@cache
def shipped_signatures() -> frozenset[str]:
    """The split signatures of the shipped suite: what a training split must avoid."""
    return suite_signatures(suite_folder())
