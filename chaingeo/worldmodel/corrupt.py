"""Seeded corruptions of our plan videos, the video judge's test set (``chain bench judge``).

A case is a window of a shipped puzzle's optimal-plan video, drawn flat (as ``chain video``
draws it) or shaded (:mod:`chaingeo.worldmodel.shaded`), and either left clean or given
one corruption at a random frame and piece: the piece vanishes (to the background behind it,
to white, to a touching neighbour's colour), is recoloured (abruptly, gradually), splits in two,
merges into a touching piece, is duplicated, teleports, or passes through another piece. Most
are made in the scene (the renderer draws what a video model would show); vanishing to the
background or to white paints the piece's own pixels. Ground truth is known by construction;
a draw whose change would not be visible (too small, hidden, at the border) is drawn again, so
every corrupted case shows its corruption.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import lru_cache
from typing import Final

import numpy as np
import numpy.typing as npt

from chaingeo.core.arrays import U8, Bools
from chaingeo.core.level import Level, load_level
from chaingeo.core.suite import suite_folder
from chaingeo.pictures.raster import Posed, parse_color
from chaingeo.pictures.scene import render_frame
from chaingeo.worldmodel.judge_gap import gap_covered
from chaingeo.worldmodel.judge_segment import components, dilate, shrink
from chaingeo.worldmodel.shaded import Part, Shader, random_look
from chaingeo.worldmodel.video import _puzzle_shots

#: Bumped whenever the cases a seed gives change (cached cases are keyed by it), per class.
VERSIONS: Final = {"split": 2, "pass_through": 2}
#: Corruption classes, and the verdict kinds that count as catching each.
CLASSES: Final = (
    "vanish_background",
    "vanish_white",
    "vanish_neighbour",
    "recolour_abrupt",
    "recolour_gradual",
    "split",
    "merge",
    "duplicate",
    "teleport",
    "pass_through",
)
ACCEPT: Final[dict[str, frozenset[str]]] = {
    "vanish_background": frozenset({"disappear"}),
    "vanish_white": frozenset({"disappear"}),
    "vanish_neighbour": frozenset({"disappear", "recolour", "merge"}),
    "recolour_abrupt": frozenset({"recolour"}),
    "recolour_gradual": frozenset({"recolour"}),
    "split": frozenset({"split"}),
    "merge": frozenset({"merge", "recolour", "disappear"}),
    "duplicate": frozenset({"duplicate", "appear"}),
    "teleport": frozenset({"teleport"}),
    "pass_through": frozenset({"pass_through"}),
}
STYLES: Final = ("flat", "shaded")
#: Shipped puzzles of at most six pieces whose colours are far apart (the levels the set draws
#: from; twelve-piece levels and look-alike teal/turquoise ones are out of the judge's scope).
LEVELS: Final = (
    "puzzle-easy-01-luban-3-piece",
    "puzzle-easy-02-luban-6-piece",
    "puzzle-easy-03-luban-6-piece",
    "puzzle-easy-04-burr6",
    "puzzle-easy-07-burr3",
    "puzzle-easy-09-cube3",
    "puzzle-hard-04-burr6x8",
    "puzzle-mid-05-burr6",
    "puzzle-mid-08-burr3",
    "puzzle-mid-10-cube4",
)
#: Frames per case, the size of a flat frame, label offset of a duplicate, frames of a gradual
#: change, and cells a piece passing through another moves per frame.
LENGTH: Final = 36
FLAT_SIZE: Final = 320
COPY: Final = 100
GRADUAL: Final = (5, 10)
PASS_SPEED: Final = 0.34
#: Least visible area of a piece a corruption starts on (share of the frame) and draws tried.
MIN_SHARE: Final = 0.006
#: A pass-through shows when, over its crossing, pixels inside both pieces' own silhouettes
#: (each drawn alone) in two consecutive frames turn from one piece to the other (their
#: surfaces' depth order crossing, uncovered by any third piece) over at least this share of
#: the least visible area in all; a crossing behind other pieces or along the line of sight
#: shows no such pixels and is drawn again.
PASS_SEEN: Final = 0.5
TRIES: Final = 40

Colors = list[tuple[str, tuple[int, int, int]]]
Scene = list[list[Part]]


@dataclass(frozen=True)
class Case:
    """One test video with its ground truth: the class ("clean" or one of CLASSES), the first
    frame the corruption shows in and the last of its onset, the pieces a verdict may name."""

    seed: int
    level: str
    style: str
    kind: str
    frame: int
    end: int
    pieces: tuple[str, ...]
    frames: tuple[U8, ...]
    colors: tuple[tuple[str, tuple[int, int, int]], ...]
    #: Where the pieces involved show just before and at the first corrupted frame.
    truth: tuple[Bools, ...] = ()


@lru_cache(maxsize=16)
def _level(name: str) -> Level:
    return load_level(suite_folder("puzzle") / f"{name}.json")


@lru_cache(maxsize=16)
def _shots(
    name: str,
) -> tuple[list[list[Part]], tuple[tuple[int, ...], tuple[int, ...]], list[str]]:
    level = _level(name)
    shots, captions, frame = _puzzle_shots(level, list(level.solution.moves))  # type: ignore[union-attr]
    names = sorted(p.name for p in level.pieces)
    rgb = {p.name: parse_color(p.rgb) for p in level.pieces}
    scene = [
        [Part(names.index(n) + 1, level.shapes[n].voxels, rgb[n], r, t) for n, r, t in shot]
        for shot in shots
    ]
    return scene, (tuple(frame[0]), tuple(frame[1])), captions


class _Renderer:
    """Draws a scene's frames in one style, with paints (label -> RGB, or -1 for the picture
    without that part) applied to a part's own pixels; and the masks of parts."""

    def __init__(self, name: str, style: str, rng: np.random.Generator, start: int) -> None:
        level = _level(name)
        _, self.frame, captions = _shots(name)
        self.captions = captions[start : start + LENGTH]
        self.style, self.level = style, level
        self.legend = sorted((p.name, parse_color(p.rgb)) for p in level.pieces)
        self.shader = Shader(self.frame, random_look(rng, LENGTH)) if style == "shaded" else None
        self.noise = np.random.default_rng(rng.integers(2**63))

    def _flat(self, parts: list[Part], i: int) -> U8:
        posed = [Posed(p.cells, _int(p.rgb), p.rotation, p.translation) for p in parts]
        img = render_frame(posed, self.legend, self.frame, "iso", FLAT_SIZE, self.captions[i])
        return shrink(np.asarray(img.convert("RGB"), dtype=np.uint8))

    def labels(self, parts: list[Part], i: int) -> npt.NDArray[np.int32]:
        """Which part each pixel shows (0: none): the shaded label buffer, or for a flat
        picture the pixels that change when a part is left out (its face colours)."""
        if self.shader is not None:
            return self.shader.draw(parts, i)[1]
        full = self._flat(parts, i)
        out = np.zeros(full.shape[:2], dtype=np.int32)
        for p in parts:
            alone = self._flat([q for q in parts if q is not p], i)
            seen = (full != alone).any(axis=2) & (full.max(axis=2) > 60)
            out[seen & (out == 0)] = p.label
        return out

    def picture(self, parts: list[Part], i: int, paint: dict[int, tuple[float, ...]]) -> U8:
        if self.shader is None:
            img = self._flat(parts, i)
            if paint:
                lab = self.labels(parts, i)
                img = img.copy()
                for label, rgb in paint.items():
                    m = lab == label
                    if rgb[0] < 0:
                        img[m] = self._flat([p for p in parts if p.label != label], i)[m]
                    else:
                        img[m] = np.array(rgb, dtype=np.uint8)
            return img
        pic, lab = self.shader.draw(parts, i)
        for label, rgb in paint.items():
            big = np.repeat(np.repeat(lab == label, 2, axis=0), 2, axis=1)
            if rgb[0] < 0:
                other, _ = self.shader.draw([p for p in parts if p.label != label], i)
                pic[big] = other[big]
            else:
                pic[big] = np.array(rgb) / 255.0 * 0.97
        return self.shader.finish(pic, self.noise)


def _key(p: Part) -> tuple[object, ...]:
    return (p.label, p.rgb, p.translation.tobytes(), p.rotation.tobytes(), p.cells.tobytes())


def _int(rgb: tuple[float, ...]) -> tuple[int, int, int]:
    return (round(rgb[0]), round(rgb[1]), round(rgb[2]))


class _Draft:
    """A case being built: the scene window, paints per frame, and checks on visibility."""

    def __init__(self, name: str, style: str, rng: np.random.Generator) -> None:
        scene, _, _ = _shots(name)
        start = int(rng.integers(0, max(1, len(scene) - LENGTH + 1)))
        self.scene: Scene = [list(s) for s in scene[start : start + LENGTH]]
        self.render = _Renderer(name, style, rng, start)
        self.paint: list[dict[int, tuple[float, ...]]] = [{} for _ in self.scene]
        self.names = sorted(p.name for p in _level(name).pieces)
        level = _level(name)
        rgb = {q.name: parse_color(q.rgb) for q in level.pieces}
        self.rgb = {i + 1: rgb[n] for i, n in enumerate(self.names)}
        self._labels: dict[tuple[object, ...], npt.NDArray[np.int32]] = {}

    def labels(self, i: int) -> npt.NDArray[np.int32]:
        key = (i, *sorted(_key(p) for p in self.scene[i]))
        if key not in self._labels:
            self._labels[key] = self.render.labels(self.scene[i], i)
        return self._labels[key]

    def mask(self, i: int, label: int) -> Bools:
        lab = self.labels(i)
        out: Bools = (lab == label) | (lab == label + COPY)
        return out

    def least(self) -> int:
        lab = self.labels(0)
        return max(150, round(MIN_SHARE * lab.size))

    def silhouette(self, i: int, label: int) -> Bools:
        """Where the part shows in frame ``i`` drawn alone: its full silhouette."""
        p = self.part(i, label)
        if p is None:
            return np.zeros(self.labels(0).shape, dtype=bool)
        key = ("alone", i, _key(p))
        if key not in self._labels:
            self._labels[key] = self.render.labels([p], i)
        out: Bools = self._labels[key] > 0
        return out

    def crossed(self, i: int, k: int, j: int) -> int:
        """Pixels inside both parts' silhouettes in frames ``i - 1`` and ``i`` that show one
        of the two in one frame and the other in the next: where the depth order of the two
        surfaces turned (a third part covering a pixel shows neither)."""
        inside = np.ones(self.labels(i).shape, dtype=bool)
        for u in (i - 1, i):
            inside &= self.silhouette(u, k) & self.silhouette(u, j)
        a, b = self.labels(i - 1), self.labels(i)
        turned = inside & (((a == k) & (b == j)) | ((a == j) & (b == k)))
        return int(turned.sum())

    def shown(self, i: int, label: int, share: float = 1.0) -> bool:
        """Visible enough, and off the picture's border."""
        m = self.mask(i, label)
        inner = m[4:-4, 4:-4].sum()
        return bool(m.sum() >= share * self.least() and inner == m.sum())

    def touching(self, i: int, label: int) -> list[int]:
        lab = self.labels(i)
        near = dilate(self.mask(i, label), 3)
        return sorted({int(v) for v in np.unique(lab[near]) if v and v != label and v < COPY})

    def alone(self, i: int, label: int) -> bool:
        """In open view: no other part's pixels within a few pixels."""
        lab = self.labels(i)
        m = lab == label
        near = dilate(m, 3) & ~m
        return bool(m.any() and (lab[near] > 0).sum() <= 0.1 * near.sum())

    def pieces(self, i: int) -> list[int]:
        return [p.label for p in self.scene[i] if p.label < COPY]

    def part(self, i: int, label: int) -> Part | None:
        return next((p for p in self.scene[i] if p.label == label), None)

    def set_part(self, i: int, label: int, new: Part | None) -> None:
        rest = [p for p in self.scene[i] if p.label != label]
        self.scene[i] = rest + ([new] if new is not None else [])

    def frames(self) -> tuple[U8, ...]:
        return tuple(self.render.picture(s, i, self.paint[i]) for i, s in enumerate(self.scene))


_Found = tuple[int, int, tuple[int, ...]] | None


def _onset(d: _Draft, rng: np.random.Generator, need: int = 6) -> tuple[int, int] | None:
    """A frame (far enough from both ends) and a piece well in view there and just before."""
    t = int(rng.integers(3, LENGTH - need))
    here = d.pieces(t)
    if not here:
        return None
    k = int(rng.choice(here))
    if not all(d.shown(u, k) for u in (t - 1, t)):
        return None
    return t, k


def _onset_part(d: _Draft, rng: np.random.Generator, need: int) -> tuple[int, int, Part] | None:
    """:func:`_onset`, with the piece's part in that frame (a piece in view has one)."""
    got = _onset(d, rng, need)
    if got is None:
        return None
    t, k = got
    p = d.part(t, k)
    assert p is not None
    return t, k, p


def _span(rng: np.random.Generator, t: int) -> int:
    """The end of a vanishing: the clip's end, or at least ten frames on (it comes back)."""
    if rng.random() < 0.65:
        return LENGTH
    return int(rng.integers(min(LENGTH, t + 10), LENGTH + 1))


def _vanish_paint(d: _Draft, rng: np.random.Generator, white: bool) -> _Found:
    got = _onset(d, rng)
    if got is None:
        return None
    t, k = got
    if not all(d.shown(u, k, 0.5) for u in range(t, t + 4)):
        return None  # not on its way out of the picture anyway
    colour = (255.0, 255.0, 255.0) if white else (-1.0, 0.0, 0.0)
    for u in range(t, _span(rng, t)):
        d.paint[u][k] = colour
    return t, t, (k,)


def vanish_background(d: _Draft, rng: np.random.Generator) -> _Found:
    return _vanish_paint(d, rng, False)


def vanish_white(d: _Draft, rng: np.random.Generator) -> _Found:
    return _vanish_paint(d, rng, True)


def _recolour_from(d: _Draft, t: int, k: int, rgb: tuple[float, ...], frames: int) -> None:
    old = np.array(d.rgb[k], dtype=np.float64)
    new = np.array(rgb, dtype=np.float64)
    for u in range(t, LENGTH):
        p = d.part(u, k)
        if p is not None:
            w = min(1.0, (u - t + 1) / frames)
            mix = tuple(float(v) for v in (1 - w) * old + w * new)
            d.set_part(u, k, replace(p, rgb=mix))  # type: ignore[arg-type]


def _touching_onset(d: _Draft, rng: np.random.Generator) -> tuple[int, int, int] | None:
    """A corruption's onset frame and piece, and a piece shown touching it then (None: none)."""
    got = _onset(d, rng)
    if got is None:
        return None
    t, k = got
    near = [j for j in d.touching(t, k) if d.shown(t, j)]
    if not near:
        return None
    return t, k, int(rng.choice(near))


def vanish_neighbour(d: _Draft, rng: np.random.Generator) -> _Found:
    got = _touching_onset(d, rng)
    if got is None:
        return None
    t, k, j = got
    _recolour_from(d, t, k, d.rgb[j], 1)
    return t, t, (k, j)


def _recolour(d: _Draft, rng: np.random.Generator, frames: int) -> _Found:
    got = _onset(d, rng, frames + 6)
    if got is None:
        return None
    t, k = got
    if not all(d.shown(u, k, 0.5) for u in range(t, t + frames + 4)):
        return None
    near = set(d.touching(t, k)) | {k}
    options = [j for j in d.rgb if j not in near]
    if not options:
        return None
    j = int(rng.choice(options))
    _recolour_from(d, t, k, d.rgb[j], frames)
    return t, t + frames - 1, (k, j)


def recolour_abrupt(d: _Draft, rng: np.random.Generator) -> _Found:
    return _recolour(d, rng, 1)


def recolour_gradual(d: _Draft, rng: np.random.Generator) -> _Found:
    return _recolour(d, rng, int(rng.integers(GRADUAL[0], GRADUAL[1] + 1)))


def _parts(m: Bools, least: int) -> int:
    return len(components(m, least))


def split(d: _Draft, rng: np.random.Generator) -> _Found:
    """The piece's cells cut across its longest extent; one half drifts a cell or more away
    along that axis over three frames, and keeps that gap."""
    got = _onset_part(d, rng, 8)
    if got is None:
        return None
    t, k, p = got
    cells = np.asarray(p.cells)
    axis = int(np.argmax(np.ptp(cells, axis=0)))
    cut = float(np.median(cells[:, axis])) + float(rng.choice([-0.5, 0.5]))
    far = cells[:, axis] > cut
    if far.all() or not far.any():
        return None
    gap = float(rng.uniform(1.0, 2.0))
    if _parts(d.mask(t - 1, k), d.least() // 3) != 1:
        return None
    for u in range(t, LENGTH):
        q = d.part(u, k)
        if q is None:
            continue
        shift = np.zeros(3)
        shift[axis] = gap * min(1.0, (u - t + 1) / 3)
        a = replace(q, cells=np.asarray(q.cells)[~far])
        b = replace(
            q, cells=np.asarray(q.cells)[far], translation=q.translation + q.rotation @ shift
        )
        d.set_part(u, k, a)
        d.scene[u].append(b)
    after = min(LENGTH - 1, t + 3)
    comps = components(d.mask(after, k), d.least() // 3)
    if len(comps) < 2:
        return None
    lab = d.labels(after)
    others = (lab > 0) & ~d.mask(after, k)
    if gap_covered(comps[0], comps[1], others):
        return None  # the gap lies behind another piece: no background between the halves
    return t, t + 2, (k,)


def merge(d: _Draft, rng: np.random.Generator) -> _Found:
    """The piece takes a touching piece's colour over three frames and moves with it from then
    on: two pieces become one."""
    got = _touching_onset(d, rng)
    if got is None:
        return None
    t, k, j = got
    pj, pk = d.part(t, j), d.part(t, k)
    assert pj is not None and pk is not None
    for u in range(t, LENGTH):
        qj = d.part(u, j)
        if qj is None:
            d.set_part(u, k, None)
            continue
        d.set_part(u, k, replace(pk, translation=pk.translation + qj.translation - pj.translation))
    _recolour_from(d, t, k, d.rgb[j], 3)
    return t, t + 2, (k, j)


def _offsets(rng: np.random.Generator, p: Part) -> list[npt.NDArray[np.float64]]:
    span = int(np.ptp(np.asarray(p.cells), axis=0).max()) + 1
    out = [
        sign * (span + extra) * np.eye(3)[axis] + sign2 * (span // 2) * np.eye(3)[(axis + 1) % 3]
        for axis in range(3)
        for sign in (1, -1)
        for sign2 in (1, 0, -1)
        for extra in range(0, 4)
    ]
    rng.shuffle(out)
    return out


def _placed(d: _Draft, rng: np.random.Generator, t: int, k: int, copy: bool) -> bool:
    """Put the piece (or a copy) at an offset where it stands alone in view from frame t on."""
    p = d.part(t, k)
    assert p is not None
    saved = [list(s) for s in d.scene]
    for off in _offsets(rng, p)[:8]:
        for u in range(t, LENGTH):
            q = d.part(u, k)
            if q is None:
                continue
            moved = replace(q, translation=q.translation + off)
            if copy:
                d.set_part(u, k + COPY, replace(moved, label=k + COPY))
            else:
                d.set_part(u, k, moved)
        lab = k + COPY if copy else k
        end = min(LENGTH, t + 4)
        if all(d.shown(u, lab) and d.alone(u, lab) for u in (t, *range(t + 1, end))):
            return True
        d.scene = [list(s) for s in saved]
    return False


def duplicate(d: _Draft, rng: np.random.Generator) -> _Found:
    got = _onset(d, rng)
    if got is None or not _placed(d, rng, got[0], got[1], True):
        return None
    return got[0], got[0], (got[1],)


def teleport(d: _Draft, rng: np.random.Generator) -> _Found:
    got = _onset(d, rng)
    if got is None:
        return None
    t, k = got
    before = np.argwhere(d.mask(t - 1, k)).mean(axis=0)
    if not _placed(d, rng, t, k, False):
        return None
    after = np.argwhere(d.mask(t, k)).mean(axis=0)
    if float(np.hypot(*(after - before))) < 0.12 * max(d.labels(t).shape):
        return None
    return t, t, (k,)


def _cells(p: Part) -> set[tuple[int, int, int]]:
    world = (np.asarray(p.cells) + 0.5) @ p.rotation.T + p.translation - 0.5
    return {(int(a), int(b), int(c)) for a, b, c in np.rint(world).astype(np.int64).tolist()}


def pass_through(d: _Draft, rng: np.random.Generator) -> _Found:
    """A piece at rest slides along an axis into a piece it touches, through it, and out on
    the far side (or as far as the clip goes), the other piece staying put."""
    got = _onset_part(d, rng, 10)
    if got is None:
        return None
    t, k, pk = got
    others = [p for p in d.scene[t] if p.label != k]
    ways = []
    for j in d.touching(t, k):
        pj = d.part(t, j)
        assert pj is not None
        theirs = _cells(pj)
        for axis in range(3):
            for sign in (1, -1):
                step = sign * np.eye(3)[axis]
                if _cells(replace(pk, translation=pk.translation + step)) & theirs:
                    ways.append((j, step))
    if not ways:
        return None
    j, step = ways[int(rng.integers(len(ways)))]
    every = set().union(*(_cells(p) for p in others))
    n = next(
        (
            m
            for m in range(2, 9)
            if not _cells(replace(pk, translation=pk.translation + m * step)) & every
        ),
        8,
    )
    frames = int(np.ceil(n / PASS_SPEED))
    base = [d.part(u, k) for u in range(t, LENGTH)]
    for u, q in zip(range(t, LENGTH), base, strict=True):
        if q is not None:
            go = min(float(n), (u - t + 1) * PASS_SPEED)
            d.set_part(u, k, replace(q, translation=q.translation + go * step))
    mid = min(LENGTH - 1, t + max(1, frames // 3))
    if not (d.shown(mid, k, 0.3) and d.shown(mid, j, 0.3)):
        return None
    end = min(LENGTH - 1, t + frames)
    if sum(d.crossed(u, k, j) for u in range(t, end + 1)) < PASS_SEEN * d.least():
        return None  # the crossing is hidden: no pixel shows it
    return t, end, (k, j)


CORRUPT: Final = {
    "vanish_background": vanish_background,
    "vanish_white": vanish_white,
    "vanish_neighbour": vanish_neighbour,
    "recolour_abrupt": recolour_abrupt,
    "recolour_gradual": recolour_gradual,
    "split": split,
    "merge": merge,
    "duplicate": duplicate,
    "teleport": teleport,
    "pass_through": pass_through,
}


def make_case(seed: int, kind: str | None = None, style: str | None = None) -> Case:
    """The case of ``seed``: its level, style and class drawn from it unless given ("clean"
    for none); every random choice comes from ``SeedSequence([seed, 35])``."""
    rng = np.random.default_rng(np.random.SeedSequence([seed, 35]))
    name = str(rng.choice(LEVELS))
    style = style or str(rng.choice(STYLES))
    kind = kind or str(rng.choice(("clean", *CLASSES)))
    for _ in range(TRIES):
        d = _Draft(name, style, rng)
        if kind == "clean":
            found: _Found = (-1, -1, ())
        else:
            found = CORRUPT[kind](d, rng)
        if found is None:
            name = str(rng.choice(LEVELS))
            continue
        t, end, labels = found
        names = tuple(d.names[q - 1] for q in labels)
        colors = tuple((n, _int(d.rgb[i + 1])) for i, n in enumerate(d.names))
        truth = tuple(d.mask(u, q) for q in labels for u in (t - 1, t))
        return Case(seed, name, style, kind, t, end, names, d.frames(), colors, truth)
    raise RuntimeError(f"seed {seed}: no visible {kind} corruption in {TRIES} draws")
