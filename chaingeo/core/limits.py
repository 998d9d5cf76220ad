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
import math
import re
from collections.abc import Callable
from typing import Any, Final

import numpy as np

from chaingeo.core.errors import ChainGeoError

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
#: The XML tree of an ``.xmpuzzle``: nesting and elements, checked as it is built (issue #37,
#: item 4: a deep stored solution broke the recursion limit; millions of elements cost a
#: gigabyte), and the grid cells of all shapes together, before any voxel string is read.
#: BurrTools' examples: depth 19, 1,004 elements, 27 grids of 216 cells.
MAX_BT_XML_DEPTH: Final = 256
MAX_BT_XML_ELEMENTS: Final = 100_000
MAX_BT_TOTAL_GRID_CELLS: Final = 2_000_000

#: The ``optimal_steps`` re-check of ``chain validate``: a search capped at this many states
#: (the same cap the tests use); larger puzzles are reported as not re-checked.
RECHECK_MAX_STATES: Final = 200_000


# ---------------------------------------------------------------------------------------------
# The evaluation harness: model servers and their replies (untrusted like agent text).
# ---------------------------------------------------------------------------------------------

#: Characters of a model reply searched for ``<action>``/``<plan>`` tags (one linear scan); a
#: longer reply is an unparseable step, unread.
MAX_REPLY_CHARS: Final = 200_000
#: Characters of one tool call's JSON arguments (like agent text), and tool calls taken from
#: one reply (the rest are dropped and said so); a call's numbers obey the agent-text limits.
MAX_TOOL_ARGUMENT_CHARS: Final = MAX_TEXT_CHARS
MAX_TOOL_CALLS: Final = 64
#: Bytes of one server answer, read before parsing; digits of any integer in it (usage counts,
#: timestamps); one usage field (tokens of one call). Past any: a protocol error of the server.
MAX_ANSWER_BYTES: Final = 16 * 1024 * 1024
MAX_ANSWER_INT_DIGITS: Final = 20
MAX_USAGE_TOKENS: Final = 10**9
#: A USD price per million tokens (prices files); with the usage bound every cost is finite.
MAX_PRICE_USD: Final = 1_000_000.0
#: Seconds: the longest ``Retry-After`` honoured, and all retries of one call together
#: (requests and waits); the request timeout is a wall-clock deadline for connect + answer.
MAX_RETRY_AFTER_SECONDS: Final = 60.0
MAX_RETRY_SECONDS: Final = 900.0
#: Same-origin HTTP 307/308 redirects followed per request (other redirects never are).
MAX_REDIRECTS: Final = 3
#: Run folders read back (``chain report``, ``--resume``): bytes of ``header.json``, of
#: ``episodes.jsonl`` and of one stored picture, and the samples per level a record may name
#: (each checked before the work; records are checked field by field as they are read).
MAX_RUN_HEADER_BYTES: Final = 1024 * 1024
MAX_RUN_LOG_BYTES: Final = 1024 * 1024 * 1024
MAX_RUN_IMAGE_BYTES: Final = 64 * 1024 * 1024
MAX_SAMPLES: Final = 10_000
#: Run logs: characters of one logged string (longer ones keep a head and their length and
#: SHA-256), bytes of one reply's record (a step, a plan, a candidate) and of one episode's
#: record; past the episode budget later steps keep only their outcome.
MAX_LOG_FIELD_CHARS: Final = 16_384
MAX_LOG_REPLY_BYTES: Final = 64 * 1024
MAX_LOG_EPISODE_BYTES: Final = 4 * 1024 * 1024

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


class LimitError(ChainGeoError, ValueError):
    """Input past one of these limits; ``reason`` says which, ``field`` where when known (the
    path of a JSON value, e.g. ``stats.score``)."""

    def __init__(self, reason: str, field: str | None = None) -> None:
        super().__init__(reason if field is None else f"{field}: {reason}")
        self.reason = reason
        self.field = field


def _bounded_int(text: str) -> int:
    digits = len(text.lstrip("-"))
    if digits > MAX_INT_DIGITS:
        raise LimitError(f"a number of {digits} digits; at most {MAX_INT_DIGITS} are allowed")
    return int(text)


def loads_bounded(text: str, object_pairs_hook: Callable[[Any], Any] | None = None) -> Any:
    """``json.loads`` with the nesting depth checked first (the decoder recurses), integer
    literals of at most :data:`MAX_INT_DIGITS` digits and finite numbers only; :class:`LimitError`
    past any of them. ``NaN``, ``Infinity`` and overflowing literals (``1e999``) are caught by
    the parser's own hooks, so no non-finite float ever leaves this function: each becomes a
    marker while parsing and the first one is reported with its path (:func:`_non_finite_path`)."""
    depth = json_depth(text)
    if depth > MAX_JSON_DEPTH:
        raise LimitError(f"JSON nested {depth} deep; at most {MAX_JSON_DEPTH}")
    found: list[_NonFinite] = []

    def non_finite(literal: str) -> _NonFinite:
        found.append(_NonFinite(literal))
        return found[-1]

    def finite_float(literal: str) -> float | _NonFinite:
        value = float(literal)
        return value if math.isfinite(value) else non_finite(literal)

    data = json.loads(
        text,
        parse_int=_bounded_int,
        parse_float=finite_float,
        parse_constant=non_finite,
        object_pairs_hook=object_pairs_hook,
    )
    if found:
        literal = found[0].literal
        shown = literal if len(literal) <= 24 else literal[:21] + "..."
        raise LimitError(f"{shown} is not a finite number", _non_finite_path(data))
    return data


# ---------------------------------------------------------------------------------------------
# Non-finite numbers in JSON (issue #21, item 9)
# ---------------------------------------------------------------------------------------------


class _NonFinite:
    """What :func:`loads_bounded` reads a non-finite number as, until it reports it."""

    __slots__ = ("literal",)

    def __init__(self, literal: str) -> None:
        self.literal = literal


def _non_finite_path(data: Any) -> str:
    """The path (``stats.a[2]``) of the first :class:`_NonFinite` in document order; keys are
    cut to 40 characters. Iterative: the depth is bounded already, but no recursion is needed."""
    stack: list[tuple[Any, str]] = [(data, "")]
    while stack:
        value, path = stack.pop()
        if isinstance(value, _NonFinite):
            return path or "(top level)"
        if isinstance(value, dict):
            items = [(v, f"{path}.{k[:40]}" if path else k[:40]) for k, v in value.items()]
        elif isinstance(value, list):
            items = [(v, f"{path}[{i}]") for i, v in enumerate(value)]
        else:
            continue
        stack.extend(reversed(items))
    return "(file)"


# ---------------------------------------------------------------------------------------------
# chain import: CHAIN's URDF/OBJ model folders (issue #21, item 11)
# ---------------------------------------------------------------------------------------------

#: Parts (URDF files) of one model folder, counted before any is read (the palette names 48
#: pieces; CHAIN's models have at most 15 parts).
MAX_MODEL_PARTS: Final = 64
#: Bytes of one URDF file (CHAIN's largest: 43 KB) and ``visual`` meshes in it (CHAIN's: 1).
MAX_URDF_BYTES: Final = 1024 * 1024
MAX_PART_MESHES: Final = 16
#: Bytes of one OBJ mesh file (CHAIN's largest: 650 KB), checked before reading.
MAX_MESH_BYTES: Final = 8 * 1024 * 1024
#: Vertices and triangles of one part, all its meshes together, counted in the text before
#: parsing (CHAIN's largest part: 6,381 and 12,838). The voxeliser's work is triangles times
#: samples, so this also bounds it per cell.
MAX_PART_VERTICES: Final = 100_000
MAX_PART_TRIANGLES: Final = 100_000
#: Sample-triangle pairs the voxeliser may evaluate for one part (cells of its bounding box
#: times 27 samples times triangles), checked before any: at most about 15 s of work here,
#: usually a third of that. CHAIN's largest part needs 3e7.
MAX_WINDING_PAIRS: Final = 300_000_000
#: Magnitude of a number in a URDF (``origin xyz``, ``rpy``, mesh ``scale``) or of an OBJ
#: vertex coordinate (CHAIN's stay under 100).
MAX_MODEL_NUMBER: Final = 1e6


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


# ---------------------------------------------------------------------------------------------
# chain export-dataset: the Hugging Face dataset folder (chaingeo/envs/dataset.py)
# ---------------------------------------------------------------------------------------------

#: Levels in one export, and plan steps (demonstration rows) over all of them, counted from the
#: levels' ``optimal_steps`` before anything is drawn (the shipped suite: 109 levels, 907 steps).
MAX_DATASET_LEVELS: Final = 100_000
MAX_DATASET_STEPS: Final = 1_000_000
#: Pixels of a side of one exported picture (the renderer's default is 512).
MAX_DATASET_IMAGE_SIZE: Final = 2048
#: Bytes of one Parquet shard (about, counted over the rows' pictures and texts): the Hub's
#: viewer and ``datasets`` stream shards of a few hundred MB best.
MAX_DATASET_SHARD_BYTES: Final = 256 * 1024 * 1024

# ---------------------------------------------------------------------------------------------
# chain judge-video: generated videos (untrusted files)
# ---------------------------------------------------------------------------------------------

#: Bytes of one video file (stat before opening; CHAIN's clips are at most 4 MB).
MAX_VIDEO_BYTES: Final = 512 * 1024 * 1024
#: Pixels of one frame (4K UHD), frames of one video (10 minutes at 30 fps) and pixels of all
#: frames together, checked from the container's header before decoding and on every decoded
#: frame as it arrives (a header can lie, and a raw H.264 stream or a streamed MKV has no
#: frame count: issue #37, item 5). CHAIN's clips: 2.1 Mpx frames, 150 frames, 3.1e8 pixels;
#: the total is five times that (decoding it takes seconds, not half a minute).
MAX_VIDEO_FRAME_PIXELS: Final = 3840 * 2160
MAX_VIDEO_FRAMES: Final = 18_000
MAX_VIDEO_TOTAL_PIXELS: Final = 1_600_000_000

# ---------------------------------------------------------------------------------------------
# chain check-trajectory: pose trajectory files (issue #22)
# ---------------------------------------------------------------------------------------------

#: Bytes of one trajectory file (checked before reading), its frames, its poses in all (frames
#: times pieces) and the magnitude of a translation or cell coordinate in it. A plan's own
#: trajectory of the shipped suite stays under 2,000 frames and 4 MB.
MAX_TRAJECTORY_BYTES: Final = 64 * 1024 * 1024
MAX_TRAJECTORY_FRAMES: Final = 50_000
MAX_TRAJECTORY_POSES: Final = 1_000_000
MAX_TRAJECTORY_COORD: Final = 1e6

# ---------------------------------------------------------------------------------------------
# chain serve: the environment server's sessions (chaingeo/integrations/serve)
# ---------------------------------------------------------------------------------------------
# Every client of the server is untrusted: a session is one WebSocket connection, and each is
# bounded here, checked before the work (a frame's size and nesting before it is parsed).

#: Sessions open at once (WebSocket connections with an environment); one more is refused.
MAX_SESSIONS: Final = 64
#: Seconds a session may stay silent before the server closes it.
SESSION_IDLE_SECONDS: Final = 900.0
#: Bytes of one request: a WebSocket frame or an HTTP body (a reply of MAX_REPLY_CHARS fits).
MAX_REQUEST_BYTES: Final = 1024 * 1024
#: Bytes one session may send in all, and messages (resets, steps, states) it may send in all:
#: a client that wants more opens a new session.
MAX_SESSION_BYTES: Final = 256 * 1024 * 1024
MAX_SESSION_MESSAGES: Final = 100_000
#: Characters of a study's participant id and of a study's name.
MAX_PARTICIPANT_CHARS: Final = 64

# ---------------------------------------------------------------------------------------------
# The precompiled-kernel store (chaingeo/kernels/aot.py, issue #37, item 2)
# ---------------------------------------------------------------------------------------------

#: Bytes of a store's manifest and of any file it hashes (the extension module, a source).
MAX_KERNEL_MANIFEST_BYTES: Final = 16 * 1024 * 1024
MAX_KERNEL_FILE_BYTES: Final = 256 * 1024 * 1024
