"""A judge for generated videos of a puzzle being taken apart (``chain judge-video``).

Video models asked to show a Lu Ban lock come apart push beams through each other, break,
fuse, add and lose pieces (CHAIN judged this by hand). This judge reads a video (bounded by
:mod:`chaingeo.core.limits` before decoding), segments pieces by their hinted colours
(:mod:`chaingeo.worldmodel.judge_segment`), tracks them
(:mod:`chaingeo.worldmodel.judge_track`), reads each colour's existence from its pixels
(:mod:`chaingeo.worldmodel.judge_exist`) and, when the level is given and the video is drawn by
our own camera, checks every lattice move it can read against the kinematics
(:mod:`chaingeo.worldmodel.judge_pose`). What it cannot decide it says in ``undecided``, never
as a verdict.
"""

from __future__ import annotations

import itertools
import os
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Final

import numpy as np
import numpy.typing as npt
from PIL import Image

from chaingeo.core import limits
from chaingeo.core.arrays import U8, Bools
from chaingeo.core.errors import ChainGeoError
from chaingeo.worldmodel.judge_drift import Drift
from chaingeo.worldmodel.judge_exist import Existence, join
from chaingeo.worldmodel.judge_motion import SilhouetteMotion, pass_throughs
from chaingeo.worldmodel.judge_palette import video_model
from chaingeo.worldmodel.judge_segment import (
    RENDER_SHADES,
    SHADES,
    ColorModel,
    Colors,
    class_masks,
    confusable,
    dilate,
    ground_and_unknown,
    min_area,
    palette_model,
    shrink,
)
from chaingeo.worldmodel.judge_shape import broken_pieces
from chaingeo.worldmodel.judge_track import (
    VIOLATIONS,
    Event,
    Obj,
    Tracker,
    frame_objects,
)
from chaingeo.worldmodel.judge_unify import one_piece_groups, unified

#: The evidence picture: the two frames around an event, each at this many times working size.
EVIDENCE_ZOOM: Final = 2
#: Reach (share of the frame's longer side) within which fragments of a piece's colour in the
#: other frame make its loss or appearance a misreading.
NEAR_SHARE: Final = 0.1
#: Mean change (RGB levels) below which a region's picture is the same in two frames.
UNCHANGED: Final = 12.0
#: A piece that vanishes is sunk among others when this share of the ring round its last
#: silhouette lies on other pieces, and this share of its area still shows in its colour
#: within SUNK_REACH pixels.
SUNK_WALLED: Final = 0.5
SUNK_LEFT: Final = 0.15
SUNK_REACH: Final = 6
#: The box's wire frame in our renders: grey level, its spread (anti-aliasing), and the largest
#: channel spread of a neutral grey.
WIRE_GREY: Final = 90.0
WIRE_SPREAD: Final = 35.0
WIRE_CHROMA: Final = 12
_TINTS: Final = ((255, 0, 255), (0, 255, 255), (255, 255, 0), (0, 255, 0))


class VideoJudgeError(ChainGeoError, ValueError):
    """A video that cannot be judged: missing, too large, or not a readable video."""


@dataclass(frozen=True)
class Clip:
    """A decoded video at working size: frames, frame rate and original size (w, h)."""

    frames: tuple[U8, ...]
    fps: float
    size: tuple[int, int]


def _check_header(frames: float, w: int, h: int) -> None:
    if w <= 0 or h <= 0:
        raise VideoJudgeError(f"frames of {w}x{h} pixels")
    if w * h > limits.MAX_VIDEO_FRAME_PIXELS:
        raise VideoJudgeError(
            f"frames of {w}x{h} pixels; at most {limits.MAX_VIDEO_FRAME_PIXELS} are read"
        )
    if frames > limits.MAX_VIDEO_FRAMES:
        raise VideoJudgeError(f"{frames:.0f} frames; at most {limits.MAX_VIDEO_FRAMES} are read")
    if frames * w * h > limits.MAX_VIDEO_TOTAL_PIXELS:
        raise VideoJudgeError(
            f"{frames:.0f} frames of {w}x{h}; at most {limits.MAX_VIDEO_TOTAL_PIXELS} pixels"
        )


class _PixelBudget:
    """The limits checked on each decoded frame as it arrives (a header can lie or say
    nothing: a raw H.264 stream or a streamed MKV has no frame count): its pixels, the frames
    so far and the pixels of all of them together."""

    def __init__(self) -> None:
        self.frames = 0
        self.pixels = 0

    def take(self, frame: npt.NDArray[Any]) -> npt.NDArray[Any]:
        if frame.ndim != 3 or frame.shape[2] < 3:
            raise VideoJudgeError(f"a frame of shape {frame.shape}")
        pixels = frame.shape[0] * frame.shape[1]
        self.frames += 1
        self.pixels += pixels
        if pixels > limits.MAX_VIDEO_FRAME_PIXELS:
            raise VideoJudgeError(
                f"a frame of {frame.shape[1]}x{frame.shape[0]} pixels; "
                f"at most {limits.MAX_VIDEO_FRAME_PIXELS} are read"
            )
        if self.frames > limits.MAX_VIDEO_FRAMES:
            raise VideoJudgeError(f"more than {limits.MAX_VIDEO_FRAMES} frames")
        if self.pixels > limits.MAX_VIDEO_TOTAL_PIXELS:
            raise VideoJudgeError(
                f"more than {limits.MAX_VIDEO_TOTAL_PIXELS} pixels in {self.frames} frames"
            )
        return frame


def _read_gif(path: Path) -> Clip:
    with Image.open(path) as im:
        w, h = im.size
        _check_header(0, w, h)
        budget = _PixelBudget()
        out = []
        for i in itertools.count():
            try:
                im.seek(i)
            except EOFError:
                break
            frame = budget.take(np.asarray(im.convert("RGB"), dtype=np.uint8))
            out.append(shrink(frame))
        ms = float(im.info.get("duration", 100) or 100)
    return Clip(tuple(out), 1000.0 / ms, (w, h))


def _read_ffmpeg(path: Path) -> Clip:
    import imageio.v2 as imageio

    reader = imageio.get_reader(str(path), format="FFMPEG")
    try:
        meta = reader.get_meta_data()
        w, h = (int(v) for v in meta.get("size", (0, 0)))
        fps = float(meta.get("fps") or 0.0)
        duration = float(meta.get("duration") or 0.0)
        _check_header(duration * max(fps, 1.0), w, h)
        out: list[U8] = []
        budget = _PixelBudget()
        for frame in reader:  # type: ignore[attr-defined]
            arr = budget.take(np.asarray(frame, dtype=np.uint8))
            out.append(shrink(np.ascontiguousarray(arr[..., :3])))
    finally:
        reader.close()
    return Clip(tuple(out), fps or 25.0, (w, h))


def read_clip(path: Path) -> Clip:
    """The frames of a GIF (Pillow) or any video ffmpeg reads, each shrunk to working size;
    :class:`VideoJudgeError` for a missing, oversized or unreadable file."""
    try:
        size = os.stat(path).st_size
    except OSError as e:
        raise VideoJudgeError(f"{path}: cannot open ({e.strerror or e})") from None
    if not path.is_file():
        raise VideoJudgeError(f"{path}: not a file")
    if size > limits.MAX_VIDEO_BYTES:
        raise VideoJudgeError(f"{path}: {size} bytes; at most {limits.MAX_VIDEO_BYTES} are read")
    try:
        with open(path, "rb") as f:
            gif = f.read(6) in (b"GIF87a", b"GIF89a")
        clip = _read_gif(path) if gif else _read_ffmpeg(path)
    except VideoJudgeError as e:
        raise VideoJudgeError(f"{path}: {e}") from None
    except ImportError:
        raise VideoJudgeError(
            f"{path}: reading this format needs the extra 'video' (imageio, imageio-ffmpeg)"
        ) from None
    except Exception as e:  # decoders raise anything on a hostile file
        raise VideoJudgeError(f"{path}: not a readable video ({type(e).__name__})") from None
    if not clip.frames:
        raise VideoJudgeError(f"{path}: no frames")
    return clip


# ---------------------------------------------------------------------------------------------
# The verdict
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Verdict:
    """Violations (events of a kind in VIOLATIONS), notes (entered, left, hidden) and what
    could not be decided, with the colour classes used."""

    violations: tuple[Event, ...]
    notes: tuple[Event, ...]
    undecided: tuple[str, ...]
    model: ColorModel
    frames: int

    @property
    def valid(self) -> bool:
        return not self.violations

    def to_json(self, evidence: dict[int, str] | None = None) -> dict[str, Any]:
        def row(i: int, e: Event) -> dict[str, Any]:
            r: dict[str, Any] = {"kind": e.kind, "frame": e.frame, "piece": e.piece}
            r["frames"] = [e.frame, e.until]
            if e.other is not None:
                r["other"] = e.other
            r["detail"] = e.detail
            if evidence and i in evidence:
                r["evidence"] = evidence[i]
            return r

        return {
            "valid": self.valid,
            "frames": self.frames,
            "colors": {"from": self.model.source, "pieces": list(self.model.names)},
            "violations": [row(i, e) for i, e in enumerate(self.violations)],
            "notes": [row(-1, e) for e in self.notes],
            "undecided": list(self.undecided),
        }


def judge_frames(
    frames: tuple[U8, ...] | list[U8],
    colors: Colors | None = None,
    level: Any = None,
) -> Verdict:
    """The verdict on working-size frames; ``colors`` (name, RGB) of the pieces if known (else
    clustered from the first frame); ``level`` enables the kinematic check of our renders, and
    the reading of occlusion and shading by our renderer's model."""
    try:
        if not colors:
            model = video_model(frames)
        else:
            model = palette_model(colors, RENDER_SHADES if level is not None else SHADES)
    except ValueError as e:
        raise VideoJudgeError(str(e)) from None
    area = min_area(frames[0].shape)
    masks = [class_masks(f, model) for f in frames]
    if not colors:
        owner = one_piece_groups(masks, len(model.names), area)
        if owner != list(range(len(owner))):
            model = unified(model, owner)
            masks = [class_masks(f, model) for f in frames]
    wire = level is not None and getattr(level, "box", None) is not None
    read = [ground_and_unknown(f, m) for f, m in zip(frames, masks, strict=True)]
    dark = None if colors else [u for _, u in read]
    objects = [
        frame_objects(m, area, _wire(f, m) if wire else None, None if dark is None else dark[t])
        for t, (f, m) in enumerate(zip(frames, masks, strict=True))
    ]
    events = Tracker(objects, model.names).events()
    shape = frames[0].shape[:2]
    kept = [[_union(objs, k, shape) for k in range(len(model.names))] for objs, _ in objects]
    solids = [solid for _, solid in objects]
    grounds = [g for g, _ in read]
    events = join(events, Existence(kept, grounds, model.names, area).events())
    events = join(events, Drift(list(frames), [o for o, _ in objects], model.names).events())
    parts = [[sum(o.parts for o in objs if o.cls == k) for k in range(len(model.names))]
             for objs, _ in objects]  # fmt: skip
    events = join(events, broken_pieces(frames, kept, grounds, parts, model.names, area))
    motion = SilhouetteMotion(kept, model.names, area)
    events = join(events, motion.teleports())
    undecided: list[str] = []
    if level is not None and colors:
        events, undecided = _with_level(level, colors, model.names, events, kept, area)
    else:
        events = join(events, pass_throughs(kept, grounds, model.names, area))
        undecided.append(
            "pass_through: read from silhouettes only (two pieces' depth order turning where "
            "both lie); a crossing hidden from view needs the level's geometry and a known "
            "camera (give --level for a video drawn by chain video)"
        )
    events = [_sunk(e, masks, solids, model.names) for e in events]
    misread = [e for e in events if _misread(frames, masks, kept, e, model.names)]
    undecided += [f"frame {e.frame}: {e.detail} (but it was misread)" for e in misread]
    events = [e for e in events if e not in misread]
    hidden = [e for e in events if e.kind == "hidden"]
    undecided += [f"frame {e.frame}: {e.detail} (occluded, or lost)" for e in hidden]
    events = [_spanned(e, kept, model.names) for e in events]
    violations = tuple(e for e in events if e.kind in VIOLATIONS)
    notes = tuple(e for e in events if e.kind not in VIOLATIONS)
    return Verdict(violations, notes, tuple(undecided), model, len(frames))


def _wire(frame: U8, masks: list[Bools]) -> Bools:
    """Pixels of the box's wire frame our renderer draws over a stacking scene: a dark
    neutral grey (render._FRAME, anti-aliased) that is no piece's colour."""
    r, g, b = (frame[..., c].astype(np.int16) for c in range(3))  # per channel: cheaper
    spread = np.maximum(np.maximum(r, g), b) - np.minimum(np.minimum(r, g), b)
    grey = (spread <= WIRE_CHROMA) & (np.abs((r + g + b) / 3.0 - WIRE_GREY) <= WIRE_SPREAD)
    out: Bools = grey & ~np.logical_or.reduce(masks)
    return out


def _with_level(
    level: Any,
    colors: Colors,
    names: tuple[str, ...],
    events: list[Event],
    kept: list[list[Bools]],
    area: int,
) -> tuple[list[Event], list[str]]:
    """Events read with the level: pass-throughs added; a change the level drawn at the
    tracked poses shows (occlusion) becomes a note; a change naming a piece whose colour is
    too close to another's is undecided."""
    from chaingeo.worldmodel.judge_pose import pass_through

    found, undecided, fit = pass_through(level, kept, names)
    alike = {names[i] for i in confusable(colors)}
    index = {n: i for i, n in enumerate(names)}
    out: list[Event] = list(found)
    for e in events:
        who = [e.piece] + ([e.other] if e.other is not None else [])
        if e.kind not in VIOLATIONS:
            out.append(e)
        elif fit is not None and all(fit.explains(kept, e.frame, index[n], area) for n in who):
            out.append(replace(e, kind="occluded", detail=f"{e.detail}: as the level is drawn"))
        elif any(n in alike for n in who):
            undecided.append(
                f"frame {e.frame}: {e.detail} (the {'/'.join(who)} colour is too close to "
                "another piece's to tell)"
            )
        else:
            out.append(e)
    return sorted(out, key=lambda e: (e.frame, e.kind, e.piece)), undecided


def _misread(
    frames: tuple[U8, ...] | list[U8],
    masks: list[list[Bools]],
    kept: list[list[Bools]],
    e: Event,
    names: tuple[str, ...],
) -> bool:
    """Whether a piece said to vanish (appear) is still there (already there) in the other
    frame: drawn alike in both, or its colour seen nearby in fragments each below the least area
    (small cells in a small picture): a misreading, not an event."""
    if (
        e.kind not in ("disappear", "appear", "duplicate")
        or not e.masks
        or e.frame < 1
        or not e.masks[0].any()
    ):
        return False
    m = e.masks[0]
    a, b = frames[e.frame - 1][m].astype(np.int64), frames[e.frame][m].astype(np.int64)
    if float(np.abs(a - b).mean()) < UNCHANGED:
        return True
    other = e.frame if e.kind == "disappear" else e.frame - 1
    k = names.index(e.piece)
    near = dilate(m, max(2, round(NEAR_SHARE * max(m.shape))))
    fragments = masks[other][k] & ~kept[other][k]
    return float((fragments & near).sum()) >= 0.5 * float(m.sum())


def _spanned(e: Event, kept: list[list[Bools]], names: tuple[str, ...]) -> Event:
    """The frame range of an event whose end the tracker left open: a piece that disappeared
    stays gone (one that appeared stays) until its colour's area there turns back."""
    if e.last is not None or e.kind not in ("disappear", "appear", "duplicate") or not e.masks:
        return e
    m, k = e.masks[0], names.index(e.piece)
    gone = e.kind == "disappear"
    last = len(kept) - 1
    for u in range(e.frame + 1, len(kept)):
        seen = float((kept[u][k] & m).sum()) >= 0.5 * float(m.sum())
        if seen == gone:
            last = u - 1
            break
    return replace(e, last=last)


def _sunk(e: Event, masks: list[list[Bools]], solids: list[Bools], names: tuple[str, ...]) -> Event:
    """A piece said lost whose last silhouette was mostly surrounded by other pieces (or the
    box's wire frame) and whose colour still shows in fragments where it was: it went out of
    sight among them (a piece lowered into a box behind pieces placed before), not lost."""
    if e.kind != "disappear" or not e.masks or e.frame < 1:
        return e
    m, k = e.masks[0], names.index(e.piece)
    ring = dilate(m, 2) & ~m
    walled = float((ring & solids[e.frame - 1]).sum()) >= SUNK_WALLED * float(ring.sum())
    left = float((masks[e.frame][k] & dilate(m, SUNK_REACH)).sum())
    if not walled or left < SUNK_LEFT * float(m.sum()):
        return e
    detail = f"the {e.piece} piece went out of sight among other pieces (fragments still seen)"
    return replace(e, kind="hidden", detail=detail)


def _union(objs: list[Obj], k: int, shape: tuple[int, ...]) -> Bools:
    """Class ``k``'s pixels that belong to objects (components past the least area)."""
    out = np.zeros(shape, dtype=bool)
    for o in objs:
        if o.cls == k:
            out |= o.mask
    return out


def _tinted(frame: U8, masks: tuple[Bools, ...], which: range) -> Image.Image:
    out = frame.astype(np.float64)
    for i in which:
        if i < len(masks):
            tint = np.array(_TINTS[min(i, len(_TINTS) - 1)], dtype=np.float64)
            m = masks[i]
            edge = m & ~(
                np.roll(m, 1, 0) & np.roll(m, -1, 0) & np.roll(m, 1, 1) & np.roll(m, -1, 1)
            )
            out[m] = 0.6 * out[m] + 0.4 * tint
            out[edge] = tint
    img = Image.fromarray(np.clip(out, 0, 255).astype(np.uint8))
    return img.resize(
        (img.width * EVIDENCE_ZOOM, img.height * EVIDENCE_ZOOM), Image.Resampling.NEAREST
    )


def write_evidence(verdict: Verdict, frames: tuple[U8, ...], folder: Path) -> dict[int, str]:
    """One PNG per violation: the frame before the event and the frame of the event side by
    side, the pieces involved outlined and tinted (magenta, cyan, yellow, green in turn);
    returns index -> file path."""
    from chaingeo.pictures.raster import png_bytes

    folder.mkdir(parents=True, exist_ok=True)
    out: dict[int, str] = {}
    for i, e in enumerate(verdict.violations):
        a = _tinted(frames[max(0, e.frame - 1)], e.masks, range(0, e.before))
        b = _tinted(frames[e.frame], e.masks, range(e.before, len(e.masks)))
        sheet = Image.new("RGB", (a.width + b.width + 4, a.height), (255, 255, 255))
        sheet.paste(a, (0, 0))
        sheet.paste(b, (a.width + 4, 0))
        path = folder / f"{i:02d}-{e.kind}-f{e.frame:04d}-{e.piece}.png"
        path.write_bytes(png_bytes(sheet))
        out[i] = str(path)
    return out


def judge_video(path: Path, level: Any = None, evidence: Path | None = None) -> dict[str, Any]:
    """The JSON report on a video file (see :func:`judge_frames`), evidence PNGs written to
    ``evidence`` when given."""
    clip = read_clip(path)
    colors = None
    if level is not None:
        colors = [(p.name, _rgb(p.rgb)) for p in level.pieces]
    verdict = judge_frames(clip.frames, colors, level)
    files = write_evidence(verdict, clip.frames, evidence) if evidence is not None else None
    report = {"video": str(path), "fps": clip.fps, "size": list(clip.size)}
    report.update(verdict.to_json(files))
    return report


def _rgb(hexa: str) -> tuple[int, int, int]:
    h = hexa.lstrip("#")
    return int(h[0:2], 16), int(h[2:4], 16), int(h[4:6], 16)
