"""The renderer: exact hidden-face removal, true colours, deterministic PNG bytes, clear errors."""

from __future__ import annotations

import hashlib
import io
import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image

from chaingeo.core.colors import PALETTE
from chaingeo.core.geometry import Shape
from chaingeo.core.level import stacking_level
from chaingeo.core.piecesets import BEDLAM_SOLUTION
from chaingeo.pictures.raster import SHADE, parse_color, png_bytes
from chaingeo.pictures.scene import (
    _FLOOR,
    CAMERAS,
    VIEWS,
    PieceMap,
    render_images,
    render_level_tray,
    render_solution_views,
    render_tray,
    render_tray_image,
    render_views,
    solution_pieces,
    view_projector,
)
from tests.support.paths import ROOT
from tests.support.pictures import bedlam_half


def _chunks(png: bytes) -> list[bytes]:
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    out, i = [], 8
    while i < len(png):
        (n,) = struct.unpack(">I", png[i : i + 4])
        out.append(png[i + 4 : i + 8])
        i += 12 + n
    return out


@st.composite
def scenes(draw: st.DrawFn, box: int = 4) -> PieceMap:
    """A few pieces filling random cells of a small box (pieces need not be connected here:
    the renderer draws any cells)."""
    n = draw(st.integers(1, 4))
    cells = [(x, y, z) for x in range(box) for y in range(box) for z in range(box)]
    owner = draw(st.lists(st.integers(-1, n - 1), min_size=len(cells), max_size=len(cells)))
    pieces: dict[str, tuple[Shape, str]] = {}
    for k in range(n):
        mine = [c for c, o in zip(cells, owner, strict=True) if o == k]
        if mine:
            pieces[PALETTE[k].name] = (Shape(mine), PALETTE[k].hex)
    if not pieces:
        pieces["red"] = (Shape([(0, 0, 0)]), PALETTE[0].hex)
    return pieces


def test_png_bytes_are_deterministic_and_carry_no_metadata() -> None:
    boxed, tray = bedlam_half()
    a = render_views(boxed, (4, 4, 4), size=256)
    b = render_views(dict(reversed(list(boxed.items()))), [4, 4, 4], size=256)
    assert a == b
    assert render_tray(tray, 256) == render_tray(dict(reversed(list(tray.items()))), 256)
    for data in [*a.values(), render_tray(tray, 256)]:
        assert _chunks(data) == [b"IHDR", b"IDAT", b"IEND"]
        img = Image.open(io.BytesIO(data))
        assert img.size == (256, 256) and img.mode == "RGB"


def test_same_bytes_in_a_fresh_interpreter_with_another_hash_seed() -> None:
    boxed, tray = bedlam_half()
    here = hashlib.sha256(
        b"".join(render_views(boxed, (4, 4, 4), size=200).values()) + render_tray(tray, 200)
    ).hexdigest()
    code = (
        "import hashlib\n"
        "from tests.support.pictures import bedlam_half\n"
        "from chaingeo.pictures.scene import render_views, render_tray\n"
        "b, tr = bedlam_half()\n"
        "print(hashlib.sha256(b''.join(render_views(b, (4, 4, 4), size=200).values())"
        " + render_tray(tr, 200)).hexdigest())\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code],
        capture_output=True,
        text=True,
        check=True,
        cwd=ROOT,
        env={"PYTHONHASHSEED": "12345", "PATH": ""},
    )
    assert out.stdout.strip() == here


def test_png_writer_round_trips_pixels() -> None:
    rng = np.random.default_rng(np.random.SeedSequence([7, 0]))
    arr = rng.integers(0, 256, size=(37, 53, 3), dtype=np.uint8)
    back = np.asarray(Image.open(io.BytesIO(png_bytes(Image.fromarray(arr)))))
    assert np.array_equal(back, arr)


@settings(max_examples=15)
@given(scenes())
def test_axis_views_show_the_nearest_cube_in_its_true_colour(pieces: PieceMap) -> None:
    """In each axis view every column shows the colour of its nearest cube, or the empty wall."""
    size = 320
    images = render_images(pieces, (4, 4, 4), ("front", "side", "top"), size)
    owner = {c: parse_color(col) for shape, col in pieces.values() for c in shape}
    for view in ("front", "side", "top"):
        cam = CAMERAS[view]
        depth = cam.depth_axis
        assert depth is not None
        toward = int(np.sign(cam.toward_viewer[depth]))
        proj = view_projector(pieces, (4, 4, 4), view, size)
        pix = np.asarray(images[view])
        others = [i for i in range(3) if i != depth]
        for a in range(4):
            for b in range(4):
                line = []
                for d in range(4):
                    c = [0, 0, 0]
                    c[others[0]], c[others[1]], c[depth] = a, b, d
                    line.append(tuple(c))
                filled = [c for c in line if c in owner]
                # a point 22% into the cell from one corner: clear of edges and centred labels
                p = np.array(line[0], dtype=float)
                p[others[0]] += 0.22
                p[others[1]] += 0.22
                p[depth] = 4.0 if toward > 0 else 0.0
                x, y = (int(v + 0.5) for v in proj(p))
                got = tuple(int(v) for v in pix[y, x])
                if filled:
                    near = max(filled, key=lambda c: c[depth] * toward)
                    assert got == owner[near], (view, line, got)
                else:
                    assert got not in owner.values(), (view, line, got)


def _ray_cast(
    cells: np.ndarray, origins: np.ndarray, direction: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Nearest cube hit per ray: (cell index or -1, face normal index, margin of the hit point
    from the face's border, in cell units)."""
    inv = 1.0 / np.where(direction == 0, 1e-300, direction)
    t0 = (cells[None, :, :] - origins[:, None, :]) * inv
    t1 = (cells[None, :, :] + 1 - origins[:, None, :]) * inv
    tmin = np.minimum(t0, t1)
    tnear = tmin.max(axis=2)
    tfar = np.maximum(t0, t1).min(axis=2)
    hit = tnear < tfar
    tnear = np.where(hit, tnear, np.inf)
    best = tnear.argmin(axis=1)
    rows = np.arange(len(origins))
    ok = np.isfinite(tnear[rows, best])
    axis = tmin[rows, best].argmax(axis=1)
    point = origins + tnear[rows, best][:, None] * direction
    local = point - cells[best]
    normal = np.where(direction[axis] > 0, 2 * axis + 1, 2 * axis)  # face toward the ray
    margin = np.ones(len(origins))
    for i in range(3):
        m = np.minimum(local[:, i], 1 - local[:, i])
        margin = np.where(axis == i, margin, np.minimum(margin, m))
    return np.where(ok, best, -1), normal, margin


@settings(max_examples=12)
@given(scenes())
def test_oblique_view_matches_a_ray_caster(pieces: PieceMap) -> None:
    """Painter's order is exact: wherever a ray from the camera hits a cube face well inside
    its border, the picture shows that face's shaded colour."""
    size = 256
    image = np.asarray(render_images(pieces, None, ("iso",), size)["iso"]).astype(int)
    proj = view_projector(pieces, None, "iso", size)
    cam = CAMERAS["iso"]
    names = sorted(pieces)
    cells = np.concatenate([pieces[n][0].voxels for n in names]).astype(float)
    rgb = np.concatenate(
        [np.tile(parse_color(pieces[n][1]), (len(pieces[n][0]), 1)) for n in names]
    )
    ys, xs = (a.ravel() for a in np.mgrid[40:size:5, 8:size:5])
    v = np.array(cam.toward_viewer)

    def cast(dx: float, dy: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        sx = (xs + 0.5 + dx - proj.origin[0]) / proj.scale  # pixel centres
        sy = -(ys + 0.5 + dy - proj.origin[1]) / proj.scale
        origins = sx[:, None] * proj.right + sy[:, None] * proj.up + 100.0 * v
        return _ray_cast(cells, origins, -v)

    which, normal, margin = cast(0.0, 0.0)
    # a sample counts when every ray within 1.5 px hits the same face: clear of all edges
    good = (which >= 0) & (margin > 0.08)
    for dx, dy in ((1.5, 0), (-1.5, 0), (0, 1.5), (0, -1.5), (1.5, 1.5), (-1.5, -1.5)):
        w2, n2, _ = cast(dx, dy)
        good &= (w2 == which) & (n2 == normal)
    assert good.sum() > 20
    for k in np.flatnonzero(good):
        expected = np.rint(rgb[which[k]] * SHADE[normal[k]])
        got = image[ys[k], xs[k]]
        assert np.abs(got - expected).max() <= 2, (k, got, expected)


def test_tray_shows_every_piece_in_its_colour_and_handles_empty() -> None:
    _, tray = bedlam_half()
    img = np.asarray(render_tray_image(tray, 384))
    flat = img.reshape(-1, 3)
    for _shape, color in tray.values():
        assert (flat == np.array(parse_color(color))).all(axis=1).sum() > 30  # its top faces
    empty = Image.open(io.BytesIO(render_tray({}, 200)))
    assert empty.size == (200, 200)


def test_every_view_renders_an_empty_scene_and_a_puzzle_scene() -> None:
    assert set(render_views({}, (3, 3, 3), size=160)) == set(VIEWS)
    far = {"red": (Shape([(-5, 2, 0), (-4, 2, 0)]), (230, 25, 75))}
    assert set(render_views(far, None, size=160)) == set(VIEWS)


def test_level_wrappers() -> None:
    level = stacking_level("bedlam-known", "hard", (4, 4, 4), list(BEDLAM_SOLUTION.values()))
    views = render_solution_views(level, size=160)
    assert set(views) == set(VIEWS)
    top = np.asarray(Image.open(io.BytesIO(views["top"]))).reshape(-1, 3)
    floor = (top == np.array(_FLOOR)).all(axis=1).sum()
    assert floor == 0  # the packed box is full: no floor shows from above
    half = dict(list(solution_pieces(level).items())[:3])
    top = np.asarray(render_images(half, level.box, ("top",), 160)["top"]).reshape(-1, 3)
    assert (top == np.array(_FLOOR)).all(axis=1).sum() > 0
    assert Image.open(io.BytesIO(render_level_tray(level, 160))).size == (160, 160)


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: render_views({}, (2, 2, 2), views=("back",)), "unknown view"),
        (lambda: render_views({}, (2, 2, 2), size=64), "at least"),
        (lambda: render_views({"a": (Shape([(0, 0, 0)]), "#12345")}, None), "#rrggbb"),
        (lambda: render_views({"a": (Shape([(0, 0, 0)]), (1, 2, 300))}, None), "0..255"),
        (lambda: render_views({}, (2, 0, 2)), "positive"),
        (
            lambda: render_views(
                {
                    "a": (Shape([(0, 0, 0)]), "#ff0000"),
                    "b": (Shape([(0, 0, 0), (1, 0, 0)]), "#00ff00"),
                },
                None,
            ),
            "overlap at",
        ),
    ],
)
def test_bad_input_raises_a_clear_error(call: object, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        call()  # type: ignore[operator]


def test_chain_render_writes_the_pictures(tmp_path: Path) -> None:
    from chaingeo.cli.main import main
    from chaingeo.core.level import save_level

    level = stacking_level("bedlam-known", "hard", (4, 4, 4), list(BEDLAM_SOLUTION.values()))
    path = save_level(level, tmp_path / "bedlam.json")
    assert main(["render", str(path), "--out", str(tmp_path / "pics"), "--size", "160"]) == 0
    written = sorted(p.name for p in (tmp_path / "pics").iterdir())
    assert written == sorted(f"bedlam-known-{v}.png" for v in (*VIEWS, "pieces"))
    assert (tmp_path / "pics" / "bedlam-known-iso.png").read_bytes() == render_solution_views(
        level, size=160
    )["iso"]
