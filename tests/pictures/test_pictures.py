"""Pictures that show the structure: the piece sheet (two opposite corners), titles, the
legend on every view, the exploded view."""

from __future__ import annotations

import io

import numpy as np
import numpy.typing as npt
from PIL import Image

from chaingeo.core.geometry import Shape
from chaingeo.core.level import load_level
from chaingeo.envs.machines import new_state
from chaingeo.envs.observation import TARGET_TITLES, render_state, target_scene
from chaingeo.pictures.legend import legend_layout
from chaingeo.pictures.pictures import exploded_pieces, render_exploded
from chaingeo.pictures.raster import SHADE, Posed, parse_color
from chaingeo.pictures.scene import (
    PIECES_TITLE,
    TRAY_TITLE,
    handed_pieces,
    render_frame,
    render_images,
    render_level_tray,
    render_tray,
    render_tray_image,
    render_views,
    solution_pieces,
)
from tests.support.paths import LEVELS

BURR = LEVELS / "puzzle" / "puzzle-easy-04-burr6.json"
STACK = LEVELS / "stacking" / "stacking-2x2x3-easy-s103-000000.json"
GREY = (200, 200, 200)


def _pixels(png: bytes) -> npt.NDArray[np.uint8]:
    return np.asarray(Image.open(io.BytesIO(png)).convert("RGB"))


def _has(img: npt.NDArray[np.uint8], rgb: tuple[int, ...], least: int = 20) -> bool:
    return int(np.all(img == np.array(rgb), axis=-1).sum()) >= least


def test_piece_sheet_shows_all_six_faces_of_a_piece() -> None:
    """Faces are shaded by their normal: one corner shows three tones, the opposite corner the
    other three; a sheet that drew each piece once would lack the bottom face's tone."""
    ell = Shape([(0, 0, 0), (1, 0, 0), (2, 0, 0), (0, 1, 0), (0, 0, 1)])
    img = np.asarray(render_tray_image({"grey": (ell, "#c8c8c8")}, 320))
    tones = [(round(200 * s),) * 3 for s in SHADE]
    assert all(_has(img, t) for t in tones), tones
    # Left half: from front-right-above (+x, -y, +z faces); right half: from back-left-below
    # (-x, +y, -z). A handful of edge pixels may blend to a tone by chance; faces are thousands.
    w = img.shape[1]
    left, right = img[:, : w // 2], img[:, w // 2 :]
    for face, tone in enumerate(tones):
        seen_left = face in (0, 3, 4)
        assert _has(left, tone, 500) == seen_left and _has(right, tone, 500) != seen_left


def test_sheet_titles_say_what_it_is() -> None:
    puzzle, stacking = load_level(BURR), load_level(STACK)
    assert render_level_tray(puzzle, 256) == render_tray(handed_pieces(puzzle), 256, PIECES_TITLE)
    assert render_level_tray(stacking, 256) == render_tray(handed_pieces(stacking), 256)
    a = _pixels(render_tray(handed_pieces(puzzle), 256, PIECES_TITLE))
    b = _pixels(render_tray(handed_pieces(puzzle), 256, TRAY_TITLE))
    rows = np.flatnonzero(np.any(a != b, axis=(1, 2)))
    assert len(rows) and rows.max() < 30  # only the title line differs


def test_target_is_titled_as_the_target() -> None:
    state = new_state(load_level(BURR))
    images = render_state(state, 256)
    want = render_views(target_scene(state), None, ("iso",), 256, TARGET_TITLES["disassemble"])
    assert images["target"] == want["iso"]
    plain = _pixels(render_views(target_scene(state), None, ("iso",), 256)["iso"])
    rows = np.flatnonzero(np.any(_pixels(images["target"]) != plain, axis=(1, 2)))
    assert len(rows) and rows.max() < 20  # the first title line, nothing else


def test_every_view_carries_a_legend_swatch_of_every_piece() -> None:
    level = load_level(BURR)
    pieces = solution_pieces(level)
    size = 320
    _, height = legend_layout([(n, (0, 0, 0)) for n in pieces], size)
    for view, image in render_images(pieces, None, size=size).items():
        strip = np.asarray(image)[size - int(height) :]
        for piece in level.pieces:
            assert _has(strip, parse_color(piece.rgb), 9), (view, piece.name)


def test_exploded_view_separates_the_pieces_along_their_first_moves() -> None:
    level = load_level(BURR)
    solved, apart = solution_pieces(level), exploded_pieces(level)
    assert set(apart) == set(solved)
    cells = [c for s, _ in apart.values() for c in s.cells]
    assert len(set(cells)) == len(cells)
    moved = [n for n in solved if apart[n][0].cells != solved[n][0].cells]
    assert len(moved) == len(solved)  # every piece leaves its place
    png = render_exploded(level, 256)
    assert png == render_exploded(level, 256) and _pixels(png).shape == (256, 256, 3)
    stacking = load_level(STACK)
    assert set(exploded_pieces(stacking)) == {p.name for p in stacking.pieces}


def test_a_frame_at_lattice_poses_is_the_still_picture() -> None:
    """render_frame goes through posed parts (rotation, real translation); on the lattice it
    must give the still renderer's bytes, a quarter turn included."""
    level = load_level(BURR)
    pieces = solution_pieces(level)
    every = np.concatenate([s.voxels for s, _ in pieces.values()])
    frame = (every.min(axis=0).tolist(), (every.max(axis=0) + 1).tolist())
    legend = [(n, parse_color(c)) for n, (_, c) in sorted(pieces.items())]
    eye, zero = np.eye(3), np.zeros(3)
    parts = [Posed(s.voxels, parse_color(c), eye, zero) for _, (s, c) in sorted(pieces.items())]
    still = render_images(pieces, None, ("iso",), 256)["iso"]
    assert render_frame(parts, legend, frame, "iso", 256).tobytes() == still.tobytes()
    # a quarter turn about z through the origin, then shifted back: cells (x, y) -> (-y - 1, x)
    one = Shape([(0, 0, 0), (1, 0, 0), (1, 1, 0)])
    turned = Shape([(-y - 1, x, z) for x, y, z in one.cells])
    quarter = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    part = Posed(one.voxels, (200, 30, 30), quarter, zero)
    box = ((-2, 0, 0), (0, 2, 1))
    want = render_images({"red": (turned, (200, 30, 30))}, None, ("iso",), 200)["iso"]
    got = render_frame([part], [("red", (200, 30, 30))], box, "iso", 200)
    assert got.tobytes() == want.tobytes()
    # off the lattice the frame still draws (and differs)
    half = Posed(one.voxels, (200, 30, 30), quarter, np.array([0.5, 0.0, 0.0]))
    assert render_frame([half], [("red", (200, 30, 30))], box, "iso", 200).tobytes() != (
        want.tobytes()
    )
