"""Reading a CHAIN model folder: every ``PART/urdf/*.urdf`` and the OBJ meshes it names.

Model folders come from other people, so every file is hostile input (issue #21, item 11):

* a mesh path is resolved (symlinks included) and must name a regular ``.obj`` file inside the
  model folder before anything is opened; a URDF likewise;
* sizes are checked with ``stat`` and a bounded read; vertex and triangle counts are counted in
  the text, and face corners checked against the vertices, before trimesh parses anything
  (the bounds are in :mod:`chaingeo.core.limits`);
* bytes are decoded here as UTF-8 and trimesh gets text with no resolver: left with bytes it
  guesses an encoding through ``charset_normalizer`` (not a dependency), and an ``mtllib`` line
  opens nothing;
* a URDF with a DOCTYPE is refused before ElementTree sees it (:mod:`.xml_guard`);
* every failure is one :class:`ModelImportError` naming the model, the part and the file.

The geometry itself (scale, ``origin rpy``, ``origin xyz``) is as in
:mod:`chaingeo.core.formats.mesh_lattice`, which takes it from here.
"""

from __future__ import annotations

import io
import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Final

import numpy as np
import trimesh

from chaingeo.core import limits
from chaingeo.core.arrays import F64
from chaingeo.core.formats.mesh_lattice import (
    IntArray,
    ModelImportError,
    PartMesh,
    rpy_matrix,
)
from chaingeo.core.formats.xml_read import XmlRefused, parse_bounded
from chaingeo.core.level_reader import short

_VERTEX_RE: Final = re.compile(r"^[ \t]*v[ \t]([^\n]*)", re.MULTILINE)
_FACE_RE: Final = re.compile(r"^[ \t]*f[ \t]([^\n]*)", re.MULTILINE)
_INDEX_RE: Final = re.compile(rf"-?[0-9]{{1,{limits.MAX_INT_DIGITS}}}")


def _natural_key(text: str) -> tuple[object, ...]:
    """``obj_2`` before ``obj_10``: the order a person numbering parts meant."""
    return tuple(int(t) if t.isdigit() else t for t in re.split(r"(\d+)", text))


def _shown(path: str) -> str:
    """A path as written, its middle cut when long: both ends tell where it leads."""
    return repr(path if len(path) <= 80 else f"{path[:30]}...{path[-45:]}")


@dataclass
class _Where:
    """The model and the element an error is about."""

    source: str
    field: str

    def fail(self, reason: str) -> ModelImportError:
        return ModelImportError(self.source, self.field, reason)


def _inside(root: Path, path: Path, what: str, at: _Where) -> Path:
    """``path`` with every symlink resolved, refused unless it is inside ``root`` (resolved)."""
    try:
        resolved = path.resolve()
    except (OSError, RuntimeError, ValueError) as e:  # a symlink loop, a NUL byte
        raise at.fail(f"{what}: cannot resolve the path ({e})") from None
    if not resolved.is_relative_to(root):
        raise at.fail(f"{what} leads outside the model folder")
    return resolved


def _read_bounded(path: Path, limit: int, what: str, at: _Where) -> bytes:
    """The bytes of a regular file of at most ``limit`` bytes (checked before reading)."""
    try:
        if not path.is_file():  # a folder, a FIFO or a device is never read
            raise at.fail(
                f"{what}: not a regular file" if path.exists() else f"{what}: no such file"
            )
        size = path.stat().st_size
        if size > limit:
            raise at.fail(f"{what}: {size} bytes; at most {limit}")
        with path.open("rb") as fh:
            data = fh.read(limit + 1)
    except OSError as e:
        raise at.fail(f"{what}: cannot read: {e.strerror or e}") from None
    if len(data) > limit:
        raise at.fail(f"{what}: more than {limit} bytes")
    return data


def _floats(text: str | None, count: int, default: float, what: str, at: _Where) -> list[float]:
    """``count`` finite numbers of magnitude at most :data:`limits.MAX_MODEL_NUMBER`."""
    if text is None:
        return [default] * count
    try:
        values = [float(v) for v in text.split()]
    except ValueError:
        values = []
    if len(values) != count:
        raise at.fail(f"{what}: expected {count} numbers, got {short(text)}")
    if not all(math.isfinite(v) and abs(v) <= limits.MAX_MODEL_NUMBER for v in values):
        raise at.fail(f"{what}: {short(text)} holds a number that is not finite or is beyond "
                      f"+-{limits.MAX_MODEL_NUMBER:g}")  # fmt: skip
    return values


def _rgba(text: str, at: _Where) -> tuple[float, float, float, float]:
    r, g, b, a = _floats(text, 4, 0.0, "rgba", at)
    if not all(0.0 <= v <= 1.0 for v in (r, g, b, a)):
        raise at.fail(f"rgba: {short(text)} is not four numbers from 0 to 1")
    return r, g, b, a


def _materials(root: ET.Element, at: _Where) -> dict[str, tuple[float, float, float, float]]:
    out: dict[str, tuple[float, float, float, float]] = {}
    for mat in root.findall("material"):
        color = mat.find("color")
        if mat.get("name") and color is not None and color.get("rgba"):
            out[str(mat.get("name"))] = _rgba(str(color.get("rgba")), at)
    return out


@dataclass
class _ReadBudget:
    """Vertices and triangles a part may still have (all its meshes together)."""

    vertices: int = limits.MAX_PART_VERTICES
    triangles: int = limits.MAX_PART_TRIANGLES


def _check_obj_text(text: str, what: str, budget: _ReadBudget, at: _Where) -> None:
    """Count vertices and triangles, check the vertices are finite numbers of magnitude at most
    :data:`limits.MAX_MODEL_NUMBER` and that every face corner names one, before trimesh parses
    anything (it would drop a non-finite vertex, and the faces on it, without a word)."""
    vertex_lines = _VERTEX_RE.findall(text)
    vertices = len(vertex_lines)
    faces = _FACE_RE.findall(text)
    triangles = sum(max(len(f.split()) - 2, 0) for f in faces)
    if vertices > budget.vertices or triangles > budget.triangles:
        raise at.fail(
            f"{what}: {vertices} vertices and {triangles} triangles; a part has at most "
            f"{limits.MAX_PART_VERTICES} and {limits.MAX_PART_TRIANGLES}"
        )
    budget.vertices -= vertices
    budget.triangles -= triangles
    try:
        coords = np.array(" ".join(vertex_lines).split(), dtype=np.float64)
    except ValueError:
        raise at.fail(f"{what}: a vertex holds something that is not a number") from None
    if not np.all(np.abs(coords) <= limits.MAX_MODEL_NUMBER):  # NaN fails too
        raise at.fail(
            f"{what}: a vertex coordinate is not a finite number within "
            f"+-{limits.MAX_MODEL_NUMBER:g}"
        )
    for n, face in enumerate(faces):
        for corner in face.split():
            index = corner.split("/", 1)[0]
            ok = _INDEX_RE.fullmatch(index) is not None  # ASCII digits: "²".isdigit() is True
            if not ok or not (1 <= abs(int(index)) <= vertices):
                raise at.fail(
                    f"{what}: face {n + 1} has corner {short(corner)}; the file has "
                    f"{vertices} vertices (numbered from 1)"
                )


def _load_obj(path: Path, what: str, budget: _ReadBudget, at: _Where) -> trimesh.Trimesh:
    """One OBJ file, bounded and checked (see the module doc), as a processed trimesh mesh."""
    data = _read_bounded(path, limits.MAX_MESH_BYTES, what, at)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise at.fail(f"{what}: not UTF-8 text (byte {e.start})") from None
    text = text.replace("\r\n", "\n").replace("\r", "\n")
    _check_obj_text(text, what, budget, at)
    try:
        mesh = trimesh.load(io.StringIO(text), file_type="obj", force="mesh", process=True)
    except Exception as e:  # a third-party parser on hostile text: any failure is the file's
        why = f"{type(e).__name__}: {short(str(e))}"
        raise at.fail(f"{what}: not a readable OBJ mesh ({why})") from None
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise at.fail(f"{what} holds no triangles")
    return mesh


def load_urdf_part(urdf: Path, model_dir: Path) -> PartMesh:
    """The visual geometry of every link of one URDF, placed as the file says, as one mesh."""
    root_dir = Path(model_dir).resolve()
    part = urdf.parent.parent.name if urdf.parent.name == "urdf" else urdf.stem
    urdf_field = f"{part}/urdf/{urdf.name}"  # names the part and the file
    at = _Where(str(model_dir), urdf_field)
    path = _inside(root_dir, urdf, "the URDF", at)
    data = _read_bounded(path, limits.MAX_URDF_BYTES, "the URDF", at)
    try:  # the one bounded XML reader: no DOCTYPE, depth and elements bounded as it is built
        root = parse_bounded(data, limits.MAX_BT_XML_DEPTH, limits.MAX_BT_XML_ELEMENTS)
    except XmlRefused as e:
        raise at.fail(e.reason) from None
    named = _materials(root, at)
    visuals = list(root.iter("visual"))
    if len(visuals) > limits.MAX_PART_MESHES:
        raise at.fail(f"{len(visuals)} visuals; at most {limits.MAX_PART_MESHES}")
    verts: list[F64] = []
    faces: list[IntArray] = []
    files: list[str] = []
    rgba: tuple[float, float, float, float] | None = None
    material: str | None = None
    offset = 0
    budget = _ReadBudget()
    for i, vis in enumerate(visuals):
        at = _Where(str(model_dir), f"{urdf_field} visual[{i}]")
        origin = vis.find("origin")
        xyz = _floats(None if origin is None else origin.get("xyz"), 3, 0.0, "origin xyz", at)
        rpy = _floats(None if origin is None else origin.get("rpy"), 3, 0.0, "origin rpy", at)
        mesh_el = vis.find("geometry/mesh")
        if mesh_el is None or not mesh_el.get("filename"):
            raise at.fail("only mesh geometry is supported")
        scale = _floats(mesh_el.get("scale"), 3, 1.0, "mesh scale", at)
        filename = str(mesh_el.get("filename"))
        what = f"mesh {_shown(filename)}"
        if Path(filename).is_absolute():
            raise at.fail(f"{what}: an absolute path; a mesh is named relative to its URDF")
        mesh_path = _inside(root_dir, urdf.parent / filename, what, at)
        if mesh_path.suffix.lower() != ".obj":
            raise at.fail(f"{what}: only OBJ meshes are read")
        mesh = _load_obj(mesh_path, what, budget, at)
        v = np.asarray(mesh.vertices, dtype=np.float64) * np.asarray(scale)
        v = v @ rpy_matrix(*rpy).T + np.asarray(xyz)
        verts.append(v)
        faces.append(np.asarray(mesh.faces, dtype=np.int64) + offset)
        offset += len(v)
        files.append(str(mesh_path.relative_to(root_dir)))
        mat = vis.find("material")
        if mat is not None and rgba is None:
            inline = mat.find("color")
            material = mat.get("name")
            if inline is not None and inline.get("rgba"):
                rgba = _rgba(str(inline.get("rgba")), at)
            elif material in named:
                rgba = named[material]
    if not verts:
        raise ModelImportError(str(model_dir), urdf_field, "no visual geometry")
    return PartMesh(
        part, np.concatenate(verts), np.concatenate(faces), rgba, material, tuple(files)
    )


def load_model_parts(model_dir: str | Path) -> list[PartMesh]:
    """Every part of a puzzle folder (``PART/urdf/*.urdf``), in natural order of part names."""
    folder = Path(model_dir)
    if not folder.is_dir():
        raise ModelImportError(str(folder), "(folder)", "no such model folder")
    urdfs = sorted(folder.glob("*/urdf/*.urdf"), key=lambda p: _natural_key(str(p)))
    if not urdfs:
        raise ModelImportError(str(folder), "(folder)", "no PART/urdf/*.urdf files")
    if len(urdfs) > limits.MAX_MODEL_PARTS:
        raise ModelImportError(
            str(folder), "(folder)", f"{len(urdfs)} parts; at most {limits.MAX_MODEL_PARTS}"
        )
    parts = [load_urdf_part(u, folder) for u in urdfs]
    names = [p.name for p in parts]
    if len(set(names)) != len(names):
        raise ModelImportError(str(folder), "(folder)", f"part names repeat: {names}")
    return parts
