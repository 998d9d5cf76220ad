"""chain judge-video: our own videos of legal plans pass; corruptions of them are caught with
the right kind and frame; CHAIN's clips (when present) each get a verdict with reasons."""

from __future__ import annotations

import json
from functools import lru_cache
from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from chaingeo.cli.main import main
from chaingeo.core.arrays import U8, Bools
from chaingeo.core.level import Level
from chaingeo.core.suite import suite_folder
from chaingeo.worldmodel.judge_segment import (
    class_masks,
    components,
    min_area,
    palette_model,
    shrink,
)
from chaingeo.worldmodel.judge_video import (
    VideoJudgeError,
    judge_frames,
    judge_video,
    read_clip,
)
from chaingeo.worldmodel.video import puzzle_video, write_gif, write_mp4
from tests.support.judge_sweep import stacking_levels
from tests.support.shared_files import shared_dir

#: Levels whose optimal-plan videos the judge reads without a false alarm (see the report for
#: the levels where occlusion still fools it).
LEVELS = ("puzzle-easy-09-cube3", "puzzle-mid-08-burr3", "puzzle-easy-07-burr3")
VIDEOS = shared_dir("chain-videos", "CHAIN_VIDEOS_DIR")
Colors = list[tuple[str, tuple[int, int, int]]]


@lru_cache(maxsize=4)
def _level(name: str) -> Level:
    from chaingeo.core.level import load_level

    return load_level(next(suite_folder().rglob(f"{name}.json")))


def _colors(level: Level) -> Colors:
    return [(p.name, tuple(int(p.rgb[i : i + 2], 16) for i in (1, 3, 5))) for p in level.pieces]  # type: ignore[misc]


@lru_cache(maxsize=4)
def _frames(name: str) -> tuple[U8, ...]:
    video = puzzle_video(_level(name), size=256)
    return tuple(shrink(np.asarray(im.convert("RGB"), dtype=np.uint8)) for im in video.frames)


def _mask(frame: U8, colors: Colors, piece: int) -> Bools:
    return class_masks(frame, palette_model(colors))[piece]


def _kinds(
    frames: list[U8], colors: Colors | None, level: Level | None = None
) -> list[tuple[str, int, str]]:
    return [(e.kind, e.frame, e.piece) for e in judge_frames(frames, colors, level).violations]


@pytest.mark.parametrize(
    ("name", "with_level"),
    [
        *((n, True) for n in LEVELS),
        ("puzzle-easy-09-cube3", False),
        ("puzzle-easy-07-burr3", False),
    ],
)
def test_our_videos_of_legal_plans_pass(name: str, with_level: bool) -> None:
    colors = _colors(_level(name)) if with_level else None
    assert _kinds(list(_frames(name)), colors) == []


#: Levels whose videos the judge once misread (occlusion read as a split, a colour revealed
#: behind a moving piece read as a swap, a shaded grey read as another grey).
#: With whether our camera is fitted on them (mid-02 starts with its pieces too small to fit).
#: (easy-05, a colour revealed behind a moving piece once read as a swap, is in the slow sweep;
#: so is mid-02 here, for the time budget.)
ONCE_MISREAD = (
    ("puzzle-hard-10-cube4", True),
    pytest.param("puzzle-mid-02-interlocking-cube", False, marks=pytest.mark.slow),
)


def _sweep_verdict(name: str) -> dict[str, object]:
    from tests.support.judge_sweep import judged

    report = judged(name)
    assert report["valid"] is True, report["violations"]
    return report


@pytest.mark.parametrize(("name", "fitted"), ONCE_MISREAD)
def test_our_gif_of_a_once_misread_level_passes_with_the_level(name: str, fitted: bool) -> None:
    report = _sweep_verdict(name)
    undecided = report["undecided"]
    assert isinstance(undecided, list)
    assert fitted == (not any("not decidable" in u for u in undecided)), undecided


#: Stacking levels whose videos the judge once misread: a piece seen in two parts across the
#: box's wire frame read as a split; a piece lowered into the box among pieces placed before
#: (its last sliver cut into fragments by their edges) read as lost.
ONCE_MISREAD_STACKING = ("stacking-2x2x4-mid-s106-000001", "stacking-3x3x3-mid-s114-000003")


@pytest.mark.parametrize(
    "name",
    [ONCE_MISREAD_STACKING[0], pytest.param(ONCE_MISREAD_STACKING[1], marks=pytest.mark.slow)],
)
def test_our_gif_of_a_once_misread_stacking_level_passes_with_the_level(name: str) -> None:
    report = _sweep_verdict(name)
    notes = report["notes"]
    assert isinstance(notes, list)
    assert any(n["kind"] == "hidden" for n in notes), notes  # occlusion said, not a verdict


@pytest.mark.parametrize("name", ONCE_MISREAD_STACKING[:1])  # one level: the time budget
def test_a_piece_blanked_out_of_our_stacking_gif_is_still_lost(name: str) -> None:
    """The box's wire frame and the pieces round a sunk piece excuse a vanishing only where its
    colour still shows: a piece deleted outright (in the box or waiting) is lost."""
    from tests.support.judge_sweep import level, rendered

    lv = level(name)
    frames, colors = list(read_clip(rendered(name)).frames), _colors(lv)
    n = len(frames)
    targets = [
        (t, k)
        for t in range(n // 5, n - 8, 5)
        for k in range(len(colors))
        if all(_in_view(frames[u], colors, k) for u in range(t, t + 7))
    ]
    assert len(targets) >= 2
    for t, k in (targets[0], targets[-1]):  # a piece waiting early, one placed late
        cut = frames[:t] + [_corrupt("disappear", f, colors, k) for f in frames[t:]]
        found = _kinds(cut, colors, lv)
        assert any(
            kind == "disappear" and abs(f - t) <= 2 and p == colors[k][0] for kind, f, p in found
        ), (t, colors[k][0], found)


@pytest.mark.slow
@pytest.mark.parametrize(
    "name",
    sorted(p.stem for p in suite_folder("puzzle").glob("*.json")) + stacking_levels(),
)
def test_our_gif_of_every_shipped_puzzle_passes_with_the_level(name: str) -> None:
    """Every shipped puzzle and every 4th shipped stacking level."""
    _sweep_verdict(name)


def _in_view(frame: U8, colors: Colors, k: int) -> bool:
    """Large, off the border and in one piece (not seen in parts round an occluder)."""
    m = _mask(frame, colors, k)
    whole = len(components(m, min_area(m.shape))) == 1
    return bool(m.sum() >= 300 and m[2:-2, 2:-2].sum() == m.sum() and whole)


def _still(frames: tuple[U8, ...], colors: Colors, k: int, t: int) -> bool:
    """The piece stays where it is from frame t - 1 to t + 6 (a swap of colours is told from
    motion by the place where each colour was)."""
    a = _mask(frames[t - 1], colors, k)
    return all((a & _mask(frames[u], colors, k)).sum() >= 0.9 * a.sum() for u in range(t, t + 7))


@lru_cache(maxsize=16)
def _targets(name: str, kind: str) -> tuple[tuple[int, int], ...]:
    """(frame, piece) pairs where the piece (and, for a swap, the next piece too) is well in
    view (large, off the border) for that frame and the next six: corruptions start there."""
    frames, colors = _frames(name), _colors(_level(name))
    n = len(frames)
    out = []
    for t in range(n // 5, n // 2, 3):
        for k in range(len(colors)):
            need = [k, (k + 1) % len(colors)] if kind == "recolour" else [k]
            if all(_in_view(frames[u], colors, q) for u in range(t, t + 7) for q in need) and (
                kind != "recolour" or all(_still(frames, colors, q, t) for q in need)
            ):
                out.append((t, k))
    return tuple(out)


BLANK = np.array([255, 255, 255], dtype=np.uint8)


@st.composite
def corrupted(draw: st.DrawFn, kind: str) -> tuple[list[U8], Colors, int, set[str], str]:
    """Frames corrupted from a drawn frame on, the colours, that frame, the pieces the
    violation may name (a swap of two colours names either) and the level."""
    name = draw(st.sampled_from(LEVELS))
    frames, colors = list(_frames(name)), _colors(_level(name))
    options = _targets(name, kind)
    if not options:
        return frames, colors, -1, set(), name
    t, k = draw(st.sampled_from(options))
    for i in range(t, len(frames)):
        frames[i] = _corrupt(kind, frames[i], colors, k)
    swapped = {colors[(k + 1) % len(colors)][0]} if kind == "recolour" else set()
    return frames, colors, t, {colors[k][0], *swapped}, name


def _corrupt(kind: str, frame: U8, colors: Colors, k: int) -> U8:
    out = frame.copy()
    m = _mask(frame, colors, k)
    ys = np.nonzero(m)[0]
    if kind == "disappear":
        out[m] = BLANK
    elif kind == "split":  # a background band through the middle, across the piece
        cy = int(np.median(ys))
        band = np.zeros_like(m)
        band[cy - 4 : cy + 5] = True
        out[m & band] = BLANK
    elif kind in ("recolour", "paint"):  # swapped with the next piece's colour / painted in it
        other = (k + 1) % len(colors)
        _paint(out, frame, m, colors[other][1])
        if kind == "recolour":
            _paint(out, frame, _mask(frame, colors, other), colors[k][1])
    return out


def _paint(out: U8, frame: U8, m: Bools, color: tuple[int, int, int]) -> None:
    rgb = np.array(color, dtype=np.float64)
    shade = frame[m].astype(np.float64).max(axis=1, keepdims=True) / 255.0
    out[m] = np.clip(rgb[None, :] * shade, 0, 255).astype(np.uint8)


@pytest.mark.parametrize("with_level", [False, True])
@pytest.mark.parametrize("kind", ["disappear", "split", "recolour"])
@settings(max_examples=2, deadline=None, derandomize=True)
@given(data=st.data())
def test_corruptions_are_caught_with_kind_and_frame(
    kind: str, with_level: bool, data: st.DataObject
) -> None:
    """With the level too: its model of occlusion and shading explains our renders, not
    corruptions of them."""
    frames, colors, t, pieces, name = data.draw(corrupted(kind))
    assume(t >= 0)
    found = _kinds(frames, colors, _level(name) if with_level else None)
    assert any(k == kind and abs(f - t) <= 2 and p in pieces for k, f, p in found), (
        kind,
        t,
        pieces,
        found,
    )


def _paste(frame: U8, src: U8, m: Bools, dy: int, dx: int) -> U8:
    out = frame.copy()
    ys, xs = np.nonzero(m)
    out[ys + dy, xs + dx] = src[ys, xs]
    return out


@pytest.mark.parametrize("with_level", [False, True])
def test_added_piece_is_caught(with_level: bool) -> None:
    """A copy of a piece appears in empty background mid-video."""
    name = "puzzle-easy-09-cube3"
    frames, colors = list(_frames(name)), _colors(_level(name))
    t = len(frames) // 2
    m = _mask(frames[t], colors, 1)
    ys, xs = np.nonzero(m)
    dy, dx = 8 - int(ys.min()) + 40, 8 - int(xs.min())  # the top-left corner is empty
    for i in range(t, len(frames)):
        frames[i] = _paste(frames[i], frames[t], m, dy, dx)
    found = _kinds(frames, colors, _level(name) if with_level else None)
    copy = ("appear", "duplicate")  # a copy while the piece is in view: duplicate
    assert any(k in copy and abs(f - t) <= 2 and p == colors[1][0] for k, f, p in found), found


def test_merge_of_two_pieces_is_caught() -> None:
    """One piece takes on its neighbour's colour and fuses with it."""
    name = "puzzle-easy-09-cube3"
    frames, colors = list(_frames(name)), _colors(_level(name))
    t = 2
    for i in range(t, len(frames)):
        frames[i] = _corrupt("paint", frames[i], colors, 2)
    found = _kinds(frames, colors)
    assert any(k in ("merge", "recolour") and f == t for k, f, _ in found), found


def test_one_noisy_frame_is_not_a_violation() -> None:
    name = "puzzle-mid-08-burr3"
    frames, colors = list(_frames(name)), _colors(_level(name))
    t = len(frames) // 2
    frames[t] = np.full_like(frames[t], 255)  # a blank frame
    rng = np.random.default_rng(0)
    frames[t + 5] = np.clip(frames[t + 5] + rng.normal(0, 6, frames[t].shape), 0, 255).astype(
        np.uint8
    )
    assert _kinds(frames, colors) == []


def test_a_gif_is_read_and_judged(tmp_path: Path) -> None:
    level = _level("puzzle-easy-09-cube3")
    gif = write_gif(puzzle_video(level, size=192), tmp_path / "v.gif")
    report = judge_video(gif, level, tmp_path / "ev")
    assert report["valid"] is True and report["violations"] == []


def test_an_mp4_is_read_and_judged(tmp_path: Path) -> None:
    """H.264 compression noise does not make a legal video invalid."""
    level = _level("puzzle-easy-09-cube3")
    mp4 = write_mp4(puzzle_video(level, size=256), tmp_path / "v.mp4")
    report = judge_video(mp4)
    assert report["valid"] is True and report["colors"]["from"] == "video"


def test_unreadable_input_exits_2(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "x.mp4"
    bad.write_bytes(b"not a video")
    assert main(["judge-video", str(bad)]) == 2
    assert main(["judge-video", str(tmp_path / "missing.mp4")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and all("judge-video: error" in line for line in err)
    with pytest.raises(VideoJudgeError):
        read_clip(bad)


def test_cli_verdict_and_exit_status(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    level = _level("puzzle-easy-09-cube3")
    frames = list(_frames("puzzle-easy-09-cube3"))
    colors = _colors(level)
    t = len(frames) // 2
    for i in range(t, len(frames)):
        frames[i] = _corrupt("disappear", frames[i], colors, 2)
    from PIL import Image

    images = [Image.fromarray(f) for f in frames]
    path = tmp_path / "bad.gif"
    images[0].save(path, save_all=True, append_images=images[1:], duration=100, loop=0)
    ev = tmp_path / "ev"
    code = main(["judge-video", str(path), "--level", str(level.id), "--evidence", str(ev)])
    report = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert code == 1 and report["valid"] is False
    assert {"kind", "frame", "frames", "piece"} <= set(report["violations"][0])
    assert all(Path(v["evidence"]).is_file() for v in report["violations"])
    gone = [v for v in report["violations"] if v["kind"] == "disappear"]
    assert gone and all(v["frame"] <= v["frames"][1] <= len(frames) - 1 for v in gone)
    assert all(v["frames"][1] > v["frames"][0] for v in gone)  # it stays gone a while


@pytest.mark.slow
@pytest.mark.skipif(VIDEOS is None, reason="../shared/chain-videos is not present")
def test_chain_clips_each_get_a_verdict_with_reasons() -> None:
    assert VIDEOS is not None
    for clip in sorted((VIDEOS / "puzzle-1").glob("*.mp4")):
        report = judge_video(clip)
        assert report["valid"] is False and report["violations"], clip.name  # none is valid
        for v in report["violations"]:
            assert v["detail"] and v["frame"] >= 0


def test_our_video_passes_the_kinematic_check() -> None:
    """With the level, every move read off our own video is checked; a legal plan passes."""
    level = _level("puzzle-mid-08-burr3")
    verdict = judge_frames(list(_frames("puzzle-mid-08-burr3")), _colors(level), level)
    assert verdict.violations == ()
    assert not any("not decidable" in u for u in verdict.undecided)


def _blocked_jumps(level: Level) -> list[tuple[int, int, int, int]]:
    """(piece, axis, sign, distance): a piece of the assembled level that cannot take one step
    that way, and the first distance at which it is free again (a jump through a piece)."""
    cells = [{tuple(c) for c in p.shape.voxels.tolist()} for p in level.pieces]
    out = []
    for i in range(len(cells)):
        rest = set().union(*(c for j, c in enumerate(cells) if j != i))
        for axis in range(3):
            for sign in (1, -1):

                def at(
                    k: int, i: int = i, axis: int = axis, sign: int = sign
                ) -> set[tuple[int, ...]]:
                    return {
                        tuple(v + (sign * k if a == axis else 0) for a, v in enumerate(c))
                        for c in cells[i]
                    }

                if not at(1) & rest:
                    continue
                k = next(k for k in range(2, 40) if not at(k) & rest)
                out.append((i, axis, sign, k))
    return out


@settings(max_examples=3, deadline=None, derandomize=True)
@given(st.sampled_from(["puzzle-mid-08-burr3", "puzzle-easy-07-burr3"]), st.data())
def test_a_piece_teleporting_through_another_is_caught(name: str, data: st.DataObject) -> None:
    from chaingeo.pictures.raster import Posed
    from chaingeo.pictures.scene import render_frame

    level = _level(name)
    i, axis, sign, k = data.draw(st.sampled_from(_blocked_jumps(level)))
    jump = np.zeros(3)
    jump[axis] = sign * k
    every = np.concatenate([p.shape.voxels for p in level.pieces])
    lo = np.minimum(every.min(axis=0), every.min(axis=0) + jump).astype(int)
    hi = np.maximum(every.max(axis=0), every.max(axis=0) + jump).astype(int) + 1
    legend = [(p.name, _colors(level)[n][1]) for n, p in enumerate(level.pieces)]
    frames = []
    for f in range(12):
        parts = [
            Posed(
                p.shape.voxels,
                legend[n][1],
                np.eye(3),
                jump if (n == i and f >= 6) else np.zeros(3),
            )
            for n, p in enumerate(level.pieces)
        ]
        image = render_frame(parts, legend, (tuple(lo), tuple(hi)), "iso", 256)
        frames.append(shrink(np.asarray(image, dtype=np.uint8)))
    verdict = judge_frames(frames, _colors(level), level)
    found = [(e.kind, e.frame, e.piece) for e in verdict.violations]
    assert ("pass_through", 6, level.pieces[i].name) in found, (
        i,
        axis,
        sign,
        k,
        found,
        verdict.undecided,
    )


def test_limits_are_checked_before_decoding(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from chaingeo.core import limits

    level = _level("puzzle-easy-09-cube3")
    gif = write_gif(puzzle_video(level, size=128), tmp_path / "v.gif")
    monkeypatch.setattr(limits, "MAX_VIDEO_FRAMES", 3)
    with pytest.raises(VideoJudgeError, match="frames"):
        read_clip(gif)
    monkeypatch.setattr(limits, "MAX_VIDEO_FRAMES", 10_000)
    monkeypatch.setattr(limits, "MAX_VIDEO_FRAME_PIXELS", 100)
    with pytest.raises(VideoJudgeError, match="pixels"):
        read_clip(gif)
    monkeypatch.setattr(limits, "MAX_VIDEO_BYTES", 10)
    with pytest.raises(VideoJudgeError, match="bytes"):
        read_clip(gif)
