"""Video limits on decoded frames as they arrive (issue #37, item 5): a raw H.264 stream or a
streamed MKV says nothing of its frame count, so the header check passed and every frame was
decoded; now each decoded frame counts against the frame and total-pixel limits and decoding
stops at the first one past them."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from chaingeo.core import limits
from chaingeo.worldmodel.judge_video import VideoJudgeError, read_clip

ffmpeg = pytest.importorskip("imageio_ffmpeg")


def _stream(tmp_path: Path, fmt: str, suffix: str, frames: int = 240) -> Path:
    out = tmp_path / f"clip{suffix}"
    cmd = [ffmpeg.get_ffmpeg_exe(), "-v", "error", "-f", "lavfi", "-i", "testsrc=s=160x120:r=30"]
    cmd += ["-frames:v", str(frames), "-c:v", "libx264", "-f", fmt, "pipe:1"]
    out.write_bytes(subprocess.run(cmd, capture_output=True, check=True, timeout=120).stdout)
    return out


@pytest.mark.parametrize(("fmt", "suffix"), [("h264", ".h264"), ("matroska", ".mkv")])
def test_total_pixels_are_counted_on_decoded_frames(
    tmp_path: Path, fmt: str, suffix: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    clip = _stream(tmp_path, fmt, suffix)
    assert len(read_clip(clip).frames) == 240  # within the limits: every frame
    monkeypatch.setattr(limits, "MAX_VIDEO_TOTAL_PIXELS", 160 * 120 * 20)
    with pytest.raises(VideoJudgeError, match="pixels in 21 frames"):
        read_clip(clip)


def test_frames_are_counted_on_decoded_frames(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    clip = _stream(tmp_path, "h264", ".h264", frames=40)
    monkeypatch.setattr(limits, "MAX_VIDEO_FRAMES", 12)
    with pytest.raises(VideoJudgeError, match="more than 12 frames"):
        read_clip(clip)
