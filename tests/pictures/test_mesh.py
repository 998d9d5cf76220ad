"""Piece meshes: watertight, exact volume, exact erosion; exports load back with trimesh."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.cli.commands.export import FORMATS as CLI_FORMATS
from chaingeo.cli.main import main
from chaingeo.core.geometry import Shape
from chaingeo.core.level import save_level, stacking_level
from chaingeo.core.piecesets import BEDLAM_SOLUTION
from chaingeo.pictures.mesh import (
    FORMATS,
    eroded_mesh,
    export_level,
    export_pieces,
    load_meshes,
    piece_mesh,
)
from tests.support.strategies import polycubes

#: Two cubes of one piece meeting only along an edge (through a third cube): the union has a
#: non-manifold edge, which manifold3d keeps as two coincident sheets.
EDGE_CONTACT = Shape([(0, 0, 0), (0, 0, 1), (0, 1, 1), (1, 1, 1), (1, 1, 0)])


def voxel_erosion_volume(shape: Shape, eps: float) -> float:
    """Volume of the shape eroded by ``eps`` (L-infinity), from the voxels alone: split each
    cell into 3x3x3 boxes (widths eps, 1 - 2 eps, eps per axis); a box survives when every
    cell its points are within ``eps`` of is filled."""
    cells = shape.cell_set
    widths = {-1: eps, 0: 1 - 2 * eps, 1: eps}
    total = 0.0
    for x, y, z in shape.cells:
        for jx in (-1, 0, 1):
            for jy in (-1, 0, 1):
                for jz in (-1, 0, 1):
                    reach = [
                        (x + dx, y + dy, z + dz)
                        for dx in {0, jx}
                        for dy in {0, jy}
                        for dz in {0, jz}
                    ]
                    if all(c in cells for c in reach):
                        total += widths[jx] * widths[jy] * widths[jz]
    return total


def _bedlam_pieces() -> dict[str, tuple[Shape, str]]:
    return {
        n.lower(): (s, f"#{30 + 15 * i:02x}80{200 - 10 * i:02x}")
        for i, (n, s) in enumerate(sorted(BEDLAM_SOLUTION.items()))
    }


@settings(max_examples=40)
@given(polycubes(1, 9))
def test_piece_mesh_is_watertight_with_the_voxel_volume(shape: Shape) -> None:
    mesh = piece_mesh(shape, "#e6194b")
    assert mesh.is_watertight and mesh.is_winding_consistent and mesh.is_volume
    assert mesh.volume == pytest.approx(len(shape), abs=1e-9)
    lo, hi = mesh.bounds
    assert np.array_equal(lo, shape.min_corner) and np.array_equal(hi, shape.max_corner + 1)


def test_edge_contact_piece_stays_watertight() -> None:
    mesh = piece_mesh(EDGE_CONTACT)
    assert mesh.is_watertight and mesh.volume == pytest.approx(5.0)


@settings(max_examples=10)
@given(polycubes(1, 6), st.sampled_from([1e-3, 0.05, 0.3]))
def test_erosion_is_exact(shape: Shape, eps: float) -> None:
    eroded = eroded_mesh(shape, eps)
    assert eroded.is_watertight
    assert eroded.volume == pytest.approx(voxel_erosion_volume(shape, eps), abs=1e-9)


def test_erosion_of_the_edge_contact_piece() -> None:
    eroded = eroded_mesh(EDGE_CONTACT, 0.1)
    assert eroded.volume == pytest.approx(voxel_erosion_volume(EDGE_CONTACT, 0.1), abs=1e-9)
    with pytest.raises(ValueError, match="erosion"):
        eroded_mesh(EDGE_CONTACT, 0.5)


@pytest.mark.parametrize("fmt", FORMATS)
def test_export_round_trips_through_trimesh(fmt: str) -> None:
    pieces = _bedlam_pieces()
    data = export_pieces(pieces, fmt)
    assert data == export_pieces(dict(reversed(list(pieces.items()))), fmt)  # same bytes
    meshes = load_meshes(data, fmt)
    assert sum(m.volume for m in meshes) == pytest.approx(64.0)
    if fmt == "stl":  # triangle soup, one solid: the volume survives, the pieces do not
        assert len(meshes) == 1
        return
    assert len(meshes) == len(pieces)
    volumes = sorted(round(m.volume, 9) for m in meshes)
    assert volumes == sorted(float(len(s)) for s, _ in pieces.values())
    assert all(m.is_watertight for m in meshes)


def test_glb_keeps_names_and_colours() -> None:
    pieces = _bedlam_pieces()
    scene = trimesh.load(io.BytesIO(export_pieces(pieces, "glb")), file_type="glb")
    assert isinstance(scene, trimesh.Scene)
    assert sorted(scene.geometry) == sorted(pieces)
    for name, (_, color) in pieces.items():
        rgb = [int(color[i : i + 2], 16) for i in (1, 3, 5)]
        material = scene.geometry[name].visual.material
        assert list(material.baseColorFactor[:3]) == rgb


def test_export_rejects_bad_requests() -> None:
    with pytest.raises(ValueError, match="unknown mesh format"):
        export_pieces(_bedlam_pieces(), "ply")
    with pytest.raises(ValueError, match="no pieces"):
        export_pieces({}, "glb")
    assert CLI_FORMATS == FORMATS


def test_chain_export_writes_each_format(tmp_path: Path) -> None:
    level = stacking_level("bedlam-known", "hard", (4, 4, 4), list(BEDLAM_SOLUTION.values()))
    path = save_level(level, tmp_path / "bedlam.json")
    for fmt in FORMATS:
        out = tmp_path / "out" / f"bedlam.{fmt}"
        assert main(["export", str(path), "--format", fmt, "--out", str(out)]) == 0
        assert out.read_bytes() == export_level(level, fmt)
        assert sum(m.volume for m in load_meshes(out.read_bytes(), fmt)) == pytest.approx(64.0)
