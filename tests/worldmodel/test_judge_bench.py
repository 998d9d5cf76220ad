"""The judge's corruption set (chain bench judge): cases are seeded and show what they claim;
the judge catches a small seeded subset and leaves clean clips alone (the full set is slow)."""

from __future__ import annotations

import hashlib

import numpy as np
import pytest

from chaingeo.benchmarks.judge import score, wilson
from chaingeo.worldmodel.corrupt import ACCEPT, CLASSES, make_case
from chaingeo.worldmodel.judge_video import judge_frames


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


@pytest.mark.parametrize(
    ("seed", "style"), [(9, "flat"), pytest.param(19, "shaded", marks=pytest.mark.slow)]
)
def test_a_pass_through_shows_its_crossing(
    seed: int, style: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The kept draw turns, over its crossing, at least PASS_SEEN of the least area from one
    piece to the other inside both pieces' own silhouettes; a draw below it is drawn again."""
    from chaingeo.worldmodel import corrupt

    seen: list[tuple[int, int, int]] = []
    crossed = corrupt._Draft.crossed

    def spy(d: corrupt._Draft, i: int, k: int, j: int) -> int:
        n = crossed(d, i, k, j)
        seen.append((i, n, d.least()))
        return n

    monkeypatch.setattr(corrupt._Draft, "crossed", spy)
    case = make_case(seed, "pass_through", style)
    last = seen[-(case.end - case.frame + 1) :]  # the kept draw's frames
    assert [i for i, _, _ in last] == list(range(case.frame, case.end + 1))
    assert sum(n for _, n, _ in last) >= corrupt.PASS_SEEN * last[0][2]
    monkeypatch.setattr(corrupt, "PASS_SEEN", 1e9)  # no crossing shows that much
    monkeypatch.setattr(corrupt, "TRIES", 2)
    with pytest.raises(RuntimeError, match="no visible pass_through"):
        make_case(seed, "pass_through", style)


def test_verdict_kinds_are_the_issues_names() -> None:
    from chaingeo.worldmodel.judge_track import VIOLATIONS

    want = {"disappear", "appear", "recolour", "split", "merge", "duplicate", "teleport"}
    assert want | {"pass_through"} == set(VIOLATIONS)
    accepted = set().union(*ACCEPT.values())
    assert accepted <= set(VIOLATIONS)


def test_wilson_interval() -> None:
    lo, hi = wilson(95, 100)
    assert lo == pytest.approx(0.888, abs=1e-3) and hi == pytest.approx(0.978, abs=1e-3)
    assert wilson(0, 0) == (0.0, 1.0)


#: A seeded subset the judge catches (class, seed, style) and clean clips it passes.
CAUGHT = (
    ("vanish_background", 0, "flat"),
    ("teleport", 8, "flat"),
    ("duplicate", 27, "flat"),
    ("vanish_neighbour", 12, "shaded"),
    ("teleport", 78, "shaded"),
    ("pass_through", 9, "flat"),
    ("pass_through", 19, "shaded"),  # a bar sliding into another: caught since the 2x2 rule
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


def test_the_issue_example_a_piece_blanked_for_the_middle_third_is_lost() -> None:
    """Issue #35: one piece's colour replaced by the background for the middle third of our
    luban-6 plan video (its cube outlines stay) was judged valid with the level."""
    from chaingeo.core.level import load_level
    from chaingeo.core.suite import suite_folder
    from chaingeo.worldmodel.judge_segment import class_masks, palette_model, shrink
    from chaingeo.worldmodel.video import puzzle_video

    level = load_level(suite_folder("puzzle") / "puzzle-easy-02-luban-6-piece.json")
    frames = [
        shrink(np.asarray(f.convert("RGB"), dtype=np.uint8))
        for f in puzzle_video(level, size=256).frames
    ]
    colors = [
        (p.name, (int(p.rgb[1:3], 16), int(p.rgb[3:5], 16), int(p.rgb[5:7], 16)))
        for p in level.pieces
    ]
    k = [n for n, _ in colors].index("blue")
    n = len(frames)
    for i in range(n // 3, 2 * n // 3):
        f = frames[i] = frames[i].copy()
        m = class_masks(f, palette_model(colors))[k]
        f[m & (f.max(axis=2) > 60)] = 255  # the background's white; black outlines kept
    verdict = judge_frames(frames, colors, level)
    found = [(e.kind, e.frame, e.piece) for e in verdict.violations]
    assert any(
        kind == "disappear" and p == "blue" and abs(f - n // 3) <= 2 for kind, f, p in found
    ), found


@pytest.mark.slow
@pytest.mark.parametrize("kind", CLASSES)
@pytest.mark.parametrize("style", ["flat", "shaded"])
def test_every_class_builds_in_both_styles(kind: str, style: str) -> None:
    case = make_case(7, kind, style)
    assert case.kind == kind and case.style == style and case.pieces
    assert 0 < case.frame <= case.end < len(case.frames)


def _held_out() -> dict[str, tuple[int, int]]:
    """(caught, cases) per class on the whole held-out range (`chain bench judge`'s set)."""
    from chaingeo.benchmarks.judge import CLEAN, HELD_OUT, PER_CLASS, plan, run_range

    rows = run_range(plan(HELD_OUT, PER_CLASS, CLEAN), 2)
    out: dict[str, tuple[int, int]] = {}
    for _, kind, _, caught, _, _ in rows:
        if caught is not None:
            k, n = out.get(kind, (0, 0))
            out[kind] = (k + int(caught), n + 1)
    return out


#: Least share caught per class on the held-out range (what the judge reached, less a margin:
#: a regression guard), and the most false alarms on its 100 clean videos.
FLOORS = {
    "vanish_background": 0.85,
    "vanish_white": 0.85,
    "vanish_neighbour": 0.85,
    "recolour_abrupt": 0.85,
    "recolour_gradual": 0.85,
    "split": 0.9,
    "merge": 0.9,
    "duplicate": 0.95,
    "teleport": 0.9,
    "pass_through": 0.4,
}
MOST_FALSE_ALARMS = 0.04


@pytest.mark.slow
def test_the_held_out_set_keeps_its_figures() -> None:
    got = _held_out()
    for kind, floor in FLOORS.items():
        k, n = got[kind]
        assert k >= floor * n, (kind, k, n)
    k, n = got["clean"]
    assert n >= 100 and k <= MOST_FALSE_ALARMS * n, (k, n)
    assert sum(n for kind, (_, n) in got.items() if kind != "clean") >= 300


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="issue #35's target is not reached yet (see the benchmarks)")
def test_the_held_out_set_meets_the_issue_target() -> None:
    got = _held_out()
    assert all(k >= 0.95 * n for kind, (k, n) in got.items() if kind != "clean")
    k, n = got["clean"]
    assert k <= 0.02 * n
