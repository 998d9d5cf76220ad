"""Every bound on hostile input, in one place.

Level files come from other people and agent text from untrusted models, so nothing they hold
may make the engine do work proportional to a number they chose, recurse without bound or raise
anything but the typed error for that input (:class:`chaingeo.core.level.LevelError` for files;
``UnparseableActionError`` / ``IllegalActionError`` for agent text). Each bound is checked
before the work it protects, and each is far above what a real level needs (the shipped suite
peaks at 36 pieces, 577 voxels, coordinates under 40, budgets of 116 steps and 16 KB files).
"""

from __future__ import annotations

import json
import re
from typing import Any, Final

import numpy as np

#: Largest coordinate magnitude in a level file (voxels, box sizes): a lattice level never
#: needs more, and every later span (kinematics, insertions) is bounded by a few times this.
MAX_COORD: Final = 1024
#: Voxels in one piece, and in all pieces of a level together.
MAX_PIECE_VOXELS: Final = 4096
MAX_LEVEL_VOXELS: Final = 32_768
#: Pieces in one level.
MAX_PIECES: Final = 256
#: Bytes of one level file (checked with ``stat`` before reading).
MAX_FILE_BYTES: Final = 4 * 1024 * 1024
#: Nesting of JSON arrays and objects (a level needs 5; checked before parsing).
MAX_JSON_DEPTH: Final = 64
#: Digits of one integer literal in a level file (int64 needs 19).
MAX_INT_DIGITS: Final = 19
#: The step budget of a level (``max_steps``); also caps stored plans.
MAX_STEPS: Final = 10_000
#: A move distance in a level file.
MAX_DISTANCE: Final = 4 * MAX_COORD

#: Characters of one agent turn; longer text is rejected unread.
MAX_TEXT_CHARS: Final = 4096
#: Magnitude of a number in agent text (cells, distances, offsets); larger ones are rejected
#: before any geometry sees them. Digits are counted first, so no huge int is ever built.
MAX_AGENT_NUMBER: Final = 100_000
MAX_AGENT_DIGITS: Final = len(str(MAX_AGENT_NUMBER))

#: BurrTools ``.xmpuzzle`` files: the XML once decompressed (a gzip bomb stops here), the cells
#: of one voxel grid (``x * y * z``), shapes and problems per file, and the pieces of one
#: problem (the sum of the parts' ``max``; also :data:`MAX_PIECES`). BurrTools' own examples
#: stay far below (160 KB of XML, 6x6x6 grids, 27 shapes, 150 pieces).
MAX_XMPUZZLE_XML_BYTES: Final = 32 * 1024 * 1024
MAX_BT_GRID_CELLS: Final = 1_000_000
MAX_BT_SHAPES: Final = 4096
MAX_BT_PROBLEMS: Final = 1024

#: The ``optimal_steps`` re-check of ``chain validate``: a search capped at this many states
#: (the same cap the tests use); larger puzzles are reported as not re-checked.
RECHECK_MAX_STATES: Final = 200_000


#: A JSON string (or an unterminated one up to the end): it always matches, so it never
#: backtracks across the text.
_STRING_RE: Final = re.compile(r'"(?:[^"\\]|\\.)*(?:"|\\?\Z)', re.DOTALL)


def json_depth(text: str) -> int:
    """The deepest nesting of ``[``/``{`` in JSON text, ignoring brackets inside strings.

    Linear and non-recursive (numpy over the bytes), so it can run before ``json.loads``,
    which recurses. Malformed text gives some number; the parser then reports the error.
    """
    stripped = _STRING_RE.sub('""', text)
    raw = np.frombuffer(stripped.encode("utf-8", "replace"), dtype=np.uint8)
    if raw.size == 0:
        return 0
    step = np.zeros(raw.shape, dtype=np.int64)
    step[(raw == ord("[")) | (raw == ord("{"))] = 1
    step[(raw == ord("]")) | (raw == ord("}"))] = -1
    return int(np.cumsum(step).max(initial=0))


class LimitError(ValueError):
    """Input past one of these limits; ``reason`` says which."""

    def __init__(self, reason: str) -> None:
        super().__init__(reason)
        self.reason = reason


def _bounded_int(text: str) -> int:
    digits = len(text.lstrip("-"))
    if digits > MAX_INT_DIGITS:
        raise LimitError(f"a number of {digits} digits; at most {MAX_INT_DIGITS} are allowed")
    return int(text)


def loads_bounded(text: str) -> Any:
    """``json.loads`` with the nesting depth checked first (the decoder recurses) and integer
    literals of at most :data:`MAX_INT_DIGITS` digits; :class:`LimitError` past either."""
    depth = json_depth(text)
    if depth > MAX_JSON_DEPTH:
        raise LimitError(f"JSON nested {depth} deep; at most {MAX_JSON_DEPTH}")
    return json.loads(text, parse_int=_bounded_int)


# ---------------------------------------------------------------------------------------------
# Gymnasium environments: fixed observation sizes (chaingeo/envs/gym.py)
# ---------------------------------------------------------------------------------------------
# A vector environment batches every sub-environment's observation into one array per key, so
# nothing an environment hands out may change shape with the level drawn. These are the fixed
# sizes; a level past one is refused with a LimitError when it is drawn.

#: Characters of one text observation (``Text`` space; shorter text is not padded by us, the
#: space's ``max_length`` is the bound). The shipped suite peaks at 13,871 with the text state.
MAX_OBSERVATION_CHARS: Final = 1 << 16
#: Length of the stacking ``action_mask`` (every action that can ever be legal in a level: each
#: piece's placements, the pickups, ``finish``), zero-padded past the level's own catalogue.
#: The shipped suite peaks at 5,234.
MAX_STACKING_ACTIONS: Final = 1 << 14
