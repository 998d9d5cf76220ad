"""The judge's corruption set (chain bench judge): cases are seeded and show what they claim;
the judge catches a small seeded subset and leaves clean clips alone (the full set is slow)."""

from __future__ import annotations

import hashlib

import numpy as np
import pytest

from chaingeo.benchmarks.judge import score, wilson
from chaingeo.envs.worldmodel.corrupt import CLASSES, make_case
from chaingeo.envs.worldmodel.judge_video import judge_frames


def _digest(frames: tuple[np.ndarray, ...]) -> str:
    h = hashlib.sha256()
    for f in frames:
        h.update(f.tobytes())
    return h.hexdigest()


def test_a_case_is_the_same_bytes_from_the_same_seed() -> None:
    a, b = make_case(3, "recolour_abrupt", "flat"), make_case(3, "recolour_abrupt", "flat")
    assert _digest(a.frames) == _digest(b.frames) and (a.frame, a.pieces) == (b.frame, b.pieces)
    c = make_case(4, "recolour_abrupt", "flat")
    assert _digest(c.frames) != _digest(a.frames)


def test_a_vanished_piece_is_gone_from_its_pixels() -> None:
    """Ground truth by construction: where the piece showed, the corrupted frame differs."""
    case = make_case(0, "vanish_white", "shaded")
    t = case.frame
    assert 0 < t < len(case.frames) and case.truth
    where = case.truth[1]
    assert where.sum() > 100
    px = case.frames[t][where].astype(np.int64)
    assert float(px.mean()) > 200  # white, through blur, noise and JPEG


def test_wilson_interval() -> None:
    lo, hi = wilson(95, 100)
    assert lo == pytest.approx(0.888, abs=1e-3) and hi == pytest.approx(0.978, abs=1e-3)
    assert wilson(0, 0) == (0.0, 1.0)


#: A seeded subset the judge catches (class, seed, style) and clean clips it passes.
CAUGHT = (
    ("vanish_background", 0, "flat"),
    ("teleport", 8, "flat"),
    ("vanish_neighbour", 12, "shaded"),
)
CLEAN = ((80, "flat"), (82, "shaded"))


@pytest.mark.parametrize(("kind", "seed", "style"), CAUGHT)
def test_the_judge_catches_a_seeded_corruption(kind: str, seed: int, style: str) -> None:
    case = make_case(seed, kind, style)
    verdict = judge_frames(list(case.frames))
    assert score(case, list(verdict.violations)), [
        (e.kind, e.frame, e.piece) for e in verdict.violations
    ]
    for e in verdict.violations:
        assert e.kind and e.piece and e.frame >= 0 and e.detail


@pytest.mark.parametrize(("seed", "style"), CLEAN)
def test_the_judge_leaves_a_clean_clip_alone(seed: int, style: str) -> None:
    case = make_case(seed, "clean", style)
    verdict = judge_frames(list(case.frames))
    assert verdict.valid, [(e.kind, e.frame, e.piece) for e in verdict.violations]


@pytest.mark.slow
@pytest.mark.parametrize("kind", CLASSES)
@pytest.mark.parametrize("style", ["flat", "shaded"])
def test_every_class_builds_in_both_styles(kind: str, style: str) -> None:
    case = make_case(7, kind, style)
    assert case.kind == kind and case.style == style and case.pieces
    assert 0 < case.frame <= case.end < len(case.frames)
