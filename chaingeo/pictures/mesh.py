"""Watertight triangle meshes of voxel pieces, and export of levels and scenes to GLB, STL, OBJ.

A piece's mesh is the boolean union of its unit cubes computed by manifold3d, so it is a closed
2-manifold by construction: where two cubes of one piece touch only along an edge, manifold3d
keeps two coincident copies of the shared vertices instead of gluing the surfaces, and trimesh
is told not to merge them (``process=False``). Formats that store triangle soup (STL) lose
that distinction on reload; their volume stays exact.

Meshes are in the level's 0-based lattice units, one unit per cube, with z up.
"""

from __future__ import annotations

import io
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any, Final

import manifold3d
import numpy as np
import numpy.typing as npt
import trimesh
from trimesh.visual import TextureVisuals
from trimesh.visual.material import PBRMaterial

from chaingeo.core.geometry import Shape
from chaingeo.pictures.raster import ColorLike, parse_color

if TYPE_CHECKING:
    from chaingeo.core.level import Level

FORMATS: Final[tuple[str, ...]] = ("glb", "stl", "obj")
#: Piece name -> (its cells where they are, its colour), as in :mod:`chaingeo.pictures.scene`.
PieceMap = Mapping[str, tuple[Shape, ColorLike]]


def piece_manifold(shape: Shape) -> manifold3d.Manifold:
    """The union of the piece's unit cubes as a manifold3d solid."""
    if len(shape) == 0:
        raise ValueError("a piece needs at least one cell")
    unit = manifold3d.Manifold.cube([1.0, 1.0, 1.0])
    cubes = [unit.translate([float(v) for v in c]) for c in shape.cells]
    solid = manifold3d.Manifold.batch_boolean(cubes, manifold3d.OpType.Add)
    status = solid.status()
    if status != manifold3d.Error.NoError:  # pragma: no cover - manifold3d reports its own bugs
        raise RuntimeError(f"manifold3d failed on a union of cubes: {status}")
    return solid


def _mesh_copy(
    solid: manifold3d.Manifold,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]]:
    """Vertices and triangles of a solid as numpy arrays that own their memory.

    manifold3d's arrays are views into a nanobind ``Mesh64``; a view kept in a trimesh object
    keeps that instance alive, and at exit (the ``chain`` command freezes the collector there)
    nanobind reports every such instance as leaked. Copies let it go when this returns."""
    raw = solid.to_mesh64()
    vertices = np.array(raw.vert_properties[:, :3], dtype=np.float64, copy=True)
    faces = np.array(raw.tri_verts, dtype=np.int64, copy=True)
    return vertices, faces


def piece_mesh(
    shape: Shape, color: ColorLike | None = None, name: str = "piece"
) -> trimesh.Trimesh:
    """A closed, outward-oriented triangle mesh of the piece (coplanar faces merged), coloured
    with a PBR base colour when ``color`` is given."""
    vertices, faces = _mesh_copy(piece_manifold(shape))
    mesh = trimesh.Trimesh(vertices=vertices, faces=faces, process=False)
    if color is not None:
        r, g, b = parse_color(color)
        material = PBRMaterial(  # type: ignore[no-untyped-call]
            name=name, baseColorFactor=[r, g, b, 255], metallicFactor=0.0
        )
        mesh.visual = TextureVisuals(material=material)  # type: ignore[no-untyped-call]
    return mesh


def eroded_mesh(shape: Shape, eps: float) -> trimesh.Trimesh:
    """The piece shrunk by ``eps`` on every side (an L-infinity erosion: manifold3d's Minkowski
    difference with a cube of side ``2 eps``). Two pieces that only touch face to face are
    ``2 eps`` apart once both are eroded; the collision check relies on that."""
    if not 0 < eps < 0.5:
        raise ValueError(f"erosion must be in (0, 0.5), got {eps}")
    probe = manifold3d.Manifold.cube([2 * eps] * 3, center=True)
    vertices, faces = _mesh_copy(piece_manifold(shape).minkowski_difference(probe))
    return trimesh.Trimesh(vertices=vertices, faces=faces, process=False)


def scene_of(pieces: PieceMap) -> trimesh.Scene:
    """One coloured mesh per piece, named after the piece, in name order."""
    scene = trimesh.Scene()
    for name in sorted(pieces):
        shape, color = pieces[name]
        scene.add_geometry(piece_mesh(shape, color, name), node_name=name, geom_name=name)
    return scene


def _obj_bytes(pieces: PieceMap) -> bytes:
    """Wavefront OBJ, one ``o`` object per piece with per-vertex colours (``v x y z r g b``), so
    a single file carries names and colours without a side ``.mtl`` file."""
    lines = ["# chaingeo pieces: one object per piece, vertex colours in 0..1"]
    base = 1
    for name in sorted(pieces):
        shape, color = pieces[name]
        mesh = piece_mesh(shape)
        r, g, b = (c / 255.0 for c in parse_color(color))
        lines.append(f"o {name}")
        lines.extend(
            f"v {_num(x)} {_num(y)} {_num(z)} {r:.6f} {g:.6f} {b:.6f}"
            for x, y, z in mesh.vertices.tolist()
        )
        lines.extend(f"f {a + base} {b_ + base} {c + base}" for a, b_, c in mesh.faces.tolist())
        base += len(mesh.vertices)
    return ("\n".join(lines) + "\n").encode("ascii")


def _num(v: float) -> str:
    return str(int(v)) if float(v).is_integer() else repr(float(v))


def export_pieces(pieces: PieceMap, fmt: str) -> bytes:
    """The pieces where they stand as ``glb`` (named, coloured meshes), ``stl`` (binary, one
    solid for all) or ``obj`` (named objects with vertex colours). Same pieces, same bytes."""
    if fmt not in FORMATS:
        raise ValueError(f"unknown mesh format {fmt!r}; use one of {list(FORMATS)}")
    if not pieces:
        raise ValueError("nothing to export: no pieces")
    if fmt == "obj":
        return _obj_bytes(pieces)
    data: Any
    if fmt == "stl":
        meshes = [piece_mesh(pieces[name][0]) for name in sorted(pieces)]
        data = trimesh.exchange.stl.export_stl(trimesh.util.concatenate(meshes))
    else:
        data = trimesh.exchange.gltf.export_glb(scene_of(pieces))  # type: ignore[no-untyped-call]
    assert isinstance(data, bytes)
    return data


def export_level(level: Level, fmt: str) -> bytes:
    """A level's pieces at their solution positions: packed in the box (stacking) or assembled
    (puzzle)."""
    from chaingeo.pictures.scene import solution_pieces

    return export_pieces(solution_pieces(level), fmt)


def load_meshes(data: bytes, fmt: str) -> list[trimesh.Trimesh]:
    """Read exported bytes back with trimesh (tests and round-trip checks use this)."""
    options: dict[str, Any] = {"split_objects": True, "group_material": False}
    loaded = trimesh.load(
        io.BytesIO(data), file_type=fmt, process=fmt != "stl", **(options if fmt == "obj" else {})
    )
    geometry = (
        [loaded.geometry[name] for name in sorted(loaded.geometry)]
        if isinstance(loaded, trimesh.Scene)
        else [loaded]
    )
    return [g for g in geometry if isinstance(g, trimesh.Trimesh)]


def mesh_arrays(mesh: trimesh.Trimesh) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int32]]:
    """Vertices (float64) and triangles (int32) in the layout collision libraries take."""
    return (
        np.ascontiguousarray(mesh.vertices, dtype=np.float64),
        np.ascontiguousarray(mesh.faces, dtype=np.int32),
    )
