"""Videos of plans: deterministic frames, the start and the goal on the first and last frames,
turns, stacking, GIF and MP4 files read back, and the command."""

from __future__ import annotations

import hashlib
import itertools
from pathlib import Path

import numpy as np
import numpy.typing as npt
import pytest
from PIL import Image

from chaingeo.cli.main import main
from chaingeo.core.level import Level, StackingSolution, load_level
from chaingeo.pictures.legend import legend_layout
from chaingeo.pictures.raster import SHADE, Posed, parse_color
from chaingeo.pictures.scene import render_frame
from chaingeo.worldmodel.video import (
    PlanVideo,
    VideoError,
    mp4_available,
    plan_video,
    puzzle_video,
    write_gif,
    write_mp4,
)
from tests.support.paths import LEVELS

TURNS = LEVELS / "puzzle" / "puzzle-easy-01-luban-3-piece.json"  # disassembly with a turn
SLIDES = LEVELS / "puzzle" / "puzzle-easy-04-burr6.json"  # disassembly, slides only
ASSEMBLE = LEVELS / "puzzle" / "puzzle-easy-07-burr3.json"
STACK = LEVELS / "stacking" / "stacking-2x2x3-easy-s103-000000.json"
SIZE = 256


def _hashes(video: PlanVideo) -> list[str]:
    return [hashlib.sha256(f.tobytes()).hexdigest() for f in video.frames]


def _shown(level: Level, image: Image.Image) -> set[str]:
    """Pieces whose colour (in any of the oblique view's six tones) covers part of the picture
    above the legend."""
    _, legend_h = legend_layout([(p.name, (0, 0, 0)) for p in level.pieces], SIZE)
    px: npt.NDArray[np.int64] = np.asarray(image).astype(np.int64)[: SIZE - int(legend_h) - 2]
    out = set()
    for p in level.pieces:
        rgb = np.array(parse_color(p.rgb), dtype=np.float64)
        tones = np.clip(np.rint(rgb[None, :] * SHADE[:, None]), 0, 255).astype(np.int64)
        hits = sum(int(np.all(px == t, axis=-1).sum()) for t in tones)
        if hits >= 8:
            out.add(p.name)
    return out


def _still(level: Level, video: PlanVideo, caption: str) -> Image.Image:
    """The level assembled (every piece where the file has it), drawn in the video's frame."""
    legend = [(p.name, parse_color(p.rgb)) for p in sorted(level.pieces, key=lambda p: p.name)]
    parts = [
        Posed(p.shape.voxels, parse_color(p.rgb), np.eye(3), np.zeros(3))
        for p in sorted(level.pieces, key=lambda p: p.name)
    ]
    return render_frame(parts, legend, video.frame, "iso", SIZE, caption)


def test_frames_are_deterministic_and_start_assembled_and_end_apart() -> None:
    level = load_level(TURNS)
    video = puzzle_video(level, size=SIZE)
    assert _hashes(video) == _hashes(puzzle_video(level, size=SIZE))
    assert len(video.frames) == len(video.captions) > 3 * level.optimal_steps
    assert video.frames[0].tobytes() == _still(level, video, video.captions[0]).tobytes()
    assert _shown(level, video.frames[0]) == {p.name for p in level.pieces}
    # disassembled: every piece a plan step took out is gone; the one left stays in view
    assert len(_shown(level, video.frames[-1])) == 1
    assert video.captions[-1] == "done: every piece apart"


def test_a_turn_rotates_through_intermediate_poses() -> None:
    level = load_level(TURNS)
    video = puzzle_video(level, size=SIZE)
    turning = [i for i, c in enumerate(video.captions) if c.startswith("step 1/3: rotate")]
    assert len(turning) > 4
    mid = video.frames[turning[len(turning) // 2 - 1]]
    ends = {video.frames[turning[0] - 1].tobytes(), video.frames[turning[-1]].tobytes()}
    assert mid.tobytes() not in ends  # neither the start nor the end pose


def test_an_assembly_video_starts_apart_and_ends_assembled() -> None:
    level = load_level(ASSEMBLE)
    video = puzzle_video(level, size=SIZE)
    assert video.captions[0].startswith("start: the pieces apart")
    assert len(_shown(level, video.frames[0])) < len(level.pieces)
    assert video.frames[-1].tobytes() == _still(level, video, video.captions[-1]).tobytes()


def test_stacking_pieces_are_carried_into_the_box_and_never_vanish() -> None:
    level = load_level(STACK)
    video = plan_video(level, size=SIZE)
    everyone = {p.name for p in level.pieces}
    assert all(_shown(level, f) == everyone for f in video.frames[::7])
    assert video.captions[-1] == "done: the box full"
    sol = level.solution
    assert isinstance(sol, StackingSolution) and level.box is not None
    legend = [(p.name, parse_color(p.rgb)) for p in sorted(level.pieces, key=lambda p: p.name)]
    colors = dict(legend)
    parts = [
        Posed(sol.placements[n].voxels, colors[n], np.eye(3), np.zeros(3))
        for n in sorted(sol.placements)
    ]
    packed = render_frame(parts, legend, video.frame, "iso", SIZE, video.captions[-1], level.box)
    assert video.frames[-1].tobytes() == packed.tobytes()
    assert video.frames[0].tobytes() != packed.tobytes()


def test_a_plan_from_text_is_checked_by_the_level() -> None:
    level = load_level(SLIDES)
    text = "# two steps\nmove blue+green+purple +z 1\n\nmove blue+green+orange +x inf\nfinish\nx"
    partial = plan_video(level, text, 128)
    assert partial.captions[-1] == "end of the plan (goal not reached)"
    assert {c for c in partial.captions if c.startswith("step")} == {
        "step 1/2: move blue+green+purple +z 1",
        "step 2/2: move blue+green+orange +x inf",
    }
    with pytest.raises(VideoError, match="plan line 1"):
        plan_video(level, "move yellow +z inf", 128)
    with pytest.raises(VideoError, match="must assemble"):
        plan_video(load_level(ASSEMBLE), "", SIZE)


def _runs(video: PlanVideo) -> int:
    h = _hashes(video)
    return 1 + sum(a != b for a, b in itertools.pairwise(h))


def test_gif_reads_back(tmp_path: Path) -> None:
    level = load_level(STACK)
    video = plan_video(level, size=128)
    path = write_gif(video, tmp_path / "v.gif")
    with Image.open(path) as gif:
        count = int(getattr(gif, "n_frames", 1))
        assert count == _runs(video)  # Pillow stores a run of equal frames once
        total = 0
        for i in range(count):
            gif.seek(i)
            total += int(gif.info["duration"])
        assert total == len(video.frames) * round(1000 / video.fps)


@pytest.mark.skipif(not mp4_available(), reason="optional extra 'video' (imageio-ffmpeg)")
def test_mp4_reads_back_with_every_frame(tmp_path: Path) -> None:
    import imageio.v2 as imageio

    video = plan_video(load_level(STACK), size=128)
    path = write_mp4(video, tmp_path / "v.mp4")
    frames = imageio.mimread(str(path), format="FFMPEG", memtest=False)
    assert len(frames) == len(video.frames) and frames[0].shape == (128, 128, 3)
    assert write_mp4(video, tmp_path / "w.mp4").read_bytes() == path.read_bytes()


def test_chain_video_command(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    plan = tmp_path / "plan.txt"
    plan.write_text("move blue+green+purple +z 1\nmove blue+green+orange +x inf\n", "utf-8")
    out = tmp_path / "v.gif"
    args = ["video", str(SLIDES), "--plan", str(plan), "--out", str(out), "--size", "128"]
    assert main(args) == 0
    assert out.is_file() and "frames" in capsys.readouterr().out
    plan.write_text("move yellow +z inf\n", encoding="utf-8")
    assert main(args) == 2
    assert "plan line 1" in capsys.readouterr().err
    assert main(["video", str(TURNS), "--out", str(tmp_path / "v.avi")]) == 2


def test_mp4_without_the_extra_says_what_to_install(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import chaingeo.worldmodel.video as video_module

    monkeypatch.setattr(video_module, "mp4_available", lambda: False)
    video = plan_video(load_level(STACK), size=128)
    with pytest.raises(VideoError, match=r"chaingeo\[video\]"):
        video_module.write_video(video, tmp_path / "v.mp4")
    with pytest.raises(VideoError, match="unknown video format"):
        video_module.write_video(video, tmp_path / "v.webm")
    assert not (tmp_path / "v.mp4").exists()
