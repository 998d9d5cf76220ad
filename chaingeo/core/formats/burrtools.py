"""BurrTools ``.xmpuzzle`` files (gzip-compressed XML), cube grid only: read and write.

What is read: the shapes (``#`` filled, ``+`` variable, ``_`` empty; x fastest), the problems
(which shapes with a count or a ``min``/``max`` range, the result shape) and the stored
solutions (an ``<assembly>`` of ``x y z transform`` per piece, ``x`` for an unused one).
A transform ``t < 24`` is the rotation ``ROTATIONS_BT[t]`` (applied as ``M @ v``, then shifted
by ``(x, y, z)``); ``t >= 24`` is the mirror through ``x = 0`` followed by rotation ``t - 24``.
Anything else (another grid, a malformed voxel string, a transform out of range) raises
:class:`BurrToolsError` naming the file and the element.
"""

from __future__ import annotations

import gzip
import os
import xml.etree.ElementTree as ET
import zlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Final

import numpy as np

from chaingeo.core.files import atomic_write
from chaingeo.core.geometry import QUARTER_TURNS, Shape


# BurrTools' numbering of the 24 proper rotations of the cube grid (applied as v' = M v):
# rotation 4 k + r is base k followed by r quarter turns about x, i.e. B_k @ Rx^r, with the
# bases I, Ry^3, Ry^2, Ry, Rz, Rz^3 (right-handed quarter turns).
def _bt_rotations() -> tuple[np.ndarray, ...]:
    rx, ry, rz = (QUARTER_TURNS[a] for a in "xyz")
    eye = np.eye(3, dtype=np.int64)
    bases = (eye, ry.T, ry @ ry, ry, rz, rz.T)
    out = []
    for b in bases:
        m = b
        for _ in range(4):
            frozen = np.ascontiguousarray(m)
            frozen.setflags(write=False)
            out.append(frozen)
            m = m @ rx
    return tuple(out)


ROTATIONS_BT: Final[tuple[np.ndarray, ...]] = _bt_rotations()
_MIRROR_X: Final = np.diag([-1, 1, 1]).astype(np.int64)
#: All 48 transforms in BurrTools' order: 24 rotations, then the same after a mirror in x.
TRANSFORMS_BT: Final[tuple[np.ndarray, ...]] = ROTATIONS_BT + tuple(
    m @ _MIRROR_X for m in ROTATIONS_BT
)


class BurrToolsError(ValueError):
    """A file that is not a readable cube-grid BurrTools puzzle: where, and why."""

    def __init__(self, source: str, where: str, reason: str) -> None:
        super().__init__(f"{source}: {where}: {reason}")
        self.source = source
        self.where = where
        self.reason = reason


@dataclass(frozen=True)
class BTShape:
    name: str | None
    size: tuple[int, int, int]
    filled: Shape  # '#' voxels, in the shape's own grid
    variable: Shape  # '+' voxels (may stay empty in a result)

    @property
    def cells(self) -> Shape:
        """Every voxel that may be filled (``#`` and ``+``)."""
        return Shape(list(self.filled.cells) + list(self.variable.cells))


@dataclass(frozen=True)
class BTPlacement:
    shape: int
    position: tuple[int, int, int]
    transform: int

    def place(self, shape: BTShape) -> Shape:
        m = TRANSFORMS_BT[self.transform]
        return shape.filled.rotate(m).translate(self.position)


@dataclass(frozen=True)
class BTSolution:
    """One stored solution: a placement per piece of the problem (None: piece unused)."""

    placements: tuple[BTPlacement | None, ...]


@dataclass(frozen=True)
class BTProblem:
    name: str | None
    pieces: tuple[tuple[int, int, int], ...]  # (shape index, min count, max count)
    result: int
    solutions: tuple[BTSolution, ...]
    recorded: Mapping[str, int]  # the file's own figures: assemblies, solutions, time


@dataclass(frozen=True)
class BTPuzzle:
    shapes: tuple[BTShape, ...]
    problems: tuple[BTProblem, ...]
    comment: str = ""

    def problem(self, index: int) -> BTProblem:
        if not 0 <= index < len(self.problems):
            raise IndexError(f"problem {index} does not exist; the file has {len(self.problems)}")
        return self.problems[index]

    def assemblies(self, index: int) -> list[dict[int, Shape]]:
        """The stored assemblies of problem ``index``: piece slot -> placed voxels."""
        prob = self.problem(index)
        out = []
        for sol in prob.solutions:
            out.append(
                {
                    slot: p.place(self.shapes[p.shape])
                    for slot, p in enumerate(sol.placements)
                    if p is not None
                }
            )
        return out


# -------------------------------------------------------------------------------------------
# Reading
# -------------------------------------------------------------------------------------------


def _int(src: str, where: str, value: str | None) -> int:
    if value is None:
        raise BurrToolsError(src, where, "missing number")
    try:
        return int(value)
    except ValueError:
        raise BurrToolsError(src, where, f"{value!r} is not an integer") from None


def _parse_voxels(src: str, where: str, node: ET.Element) -> BTShape:
    if node.get("type", "0") != "0":
        raise BurrToolsError(src, where, f"voxel type {node.get('type')} is not the cube grid")
    sx, sy, sz = (_int(src, where, node.get(k)) for k in "xyz")
    if min(sx, sy, sz) < 0:
        raise BurrToolsError(src, where, "negative size")
    text = (node.text or "").strip()
    filled: list[tuple[int, int, int]] = []
    variable: list[tuple[int, int, int]] = []
    idx = 0
    i = 0
    while i < len(text):
        ch = text[i]
        i += 1
        if ch not in "#+_":
            raise BurrToolsError(src, where, f"unexpected character {ch!r} in the voxel string")
        while i < len(text) and text[i].isdigit():  # colour index after a voxel
            i += 1
        cell = (idx % sx, (idx // sx) % sy, idx // (sx * sy)) if sx and sy else (0, 0, 0)
        if ch == "#":
            filled.append(cell)
        elif ch == "+":
            variable.append(cell)
        idx += 1
    if idx != sx * sy * sz:
        raise BurrToolsError(src, where, f"{idx} voxels given for a {sx}x{sy}x{sz} grid")
    return BTShape(node.get("name"), (sx, sy, sz), Shape(filled), Shape(variable))


def _parse_assembly(
    src: str, where: str, text: str, slots: Sequence[int], n_shapes: int
) -> BTSolution:
    toks = text.split()
    out: list[BTPlacement | None] = []
    i = 0
    for slot, shape in enumerate(slots):
        if i >= len(toks):
            raise BurrToolsError(src, where, f"ends before piece {slot}")
        if toks[i] == "x":
            out.append(None)
            i += 1
            continue
        if i + 4 > len(toks):
            raise BurrToolsError(src, where, f"piece {slot} needs x y z transform")
        x, y, z, t = (_int(src, where, v) for v in toks[i : i + 4])
        if not 0 <= t < len(TRANSFORMS_BT):
            raise BurrToolsError(src, where, f"transform {t} of piece {slot} is not a cube one")
        if not 0 <= shape < n_shapes:
            raise BurrToolsError(src, where, f"shape {shape} does not exist")
        out.append(BTPlacement(shape, (x, y, z), t))
        i += 4
    if i != len(toks):
        raise BurrToolsError(src, where, f"{len(toks) - i} tokens left over")
    return BTSolution(tuple(out))


def parse_xmpuzzle(data: bytes, source: str = "<xmpuzzle>") -> BTPuzzle:
    """Decode the bytes of a ``.xmpuzzle`` file (gzip or plain XML)."""
    try:
        raw = gzip.decompress(data) if data[:2] == b"\x1f\x8b" else data
    except (OSError, EOFError, zlib.error) as e:
        raise BurrToolsError(source, "(file)", f"not a readable gzip stream: {e}") from None
    try:
        root = ET.fromstring(raw)
    except ET.ParseError as e:
        raise BurrToolsError(source, "(file)", f"invalid XML: {e}") from None
    if root.tag != "puzzle":
        raise BurrToolsError(source, "(file)", f"root element is <{root.tag}>, not <puzzle>")
    grid = root.find("gridType")
    gtype = "0" if grid is None else grid.get("type", "0")
    if gtype != "0":
        raise BurrToolsError(
            source, "gridType", f"grid type {gtype} is not supported; only the cube grid (0)"
        )
    shapes_node = root.find("shapes")
    shapes = tuple(
        _parse_voxels(source, f"shapes[{i}]", v)
        for i, v in enumerate(shapes_node if shapes_node is not None else [])
    )
    problems: list[BTProblem] = []
    for pi, prob in enumerate(root.findall("problems/problem")):
        where = f"problems[{pi}]"
        pieces: list[tuple[int, int, int]] = []
        for s in prob.findall("shapes/shape"):
            sid = _int(source, f"{where}.shape", s.get("id"))
            if not 0 <= sid < len(shapes):
                raise BurrToolsError(source, f"{where}.shape", f"shape {sid} does not exist")
            if s.get("count") is not None:
                lo = hi = _int(source, f"{where}.shape", s.get("count"))
            else:
                lo = _int(source, f"{where}.shape", s.get("min", "0"))
                hi = _int(source, f"{where}.shape", s.get("max"))
            if not 0 <= lo <= hi:
                raise BurrToolsError(source, f"{where}.shape", f"bad count range {lo}..{hi}")
            pieces.append((sid, lo, hi))
        res = prob.find("result")
        if res is None:
            raise BurrToolsError(source, where, "no <result> shape")
        result = _int(source, f"{where}.result", res.get("id"))
        if not 0 <= result < len(shapes):
            raise BurrToolsError(source, f"{where}.result", f"shape {result} does not exist")
        slots = [s for s, _, hi in pieces for _ in range(hi)]
        sols = []
        for si, sol in enumerate(prob.findall("solutions/solution")):
            asm = sol.find("assembly")
            if asm is None or not (asm.text or "").strip():
                continue
            sols.append(
                _parse_assembly(
                    source, f"{where}.solutions[{si}]", asm.text or "", slots, len(shapes)
                )
            )
        recorded = {
            k: int(prob.get(k) or 0) for k in ("assemblies", "solutions", "time") if prob.get(k)
        }
        problems.append(BTProblem(prob.get("name"), tuple(pieces), result, tuple(sols), recorded))
    comment = root.findtext("comment") or ""
    return BTPuzzle(shapes, tuple(problems), comment)


def read_xmpuzzle(path: str | os.PathLike[str]) -> BTPuzzle:
    source = str(path)
    try:
        data = Path(path).read_bytes()
    except OSError as e:
        raise BurrToolsError(source, "(file)", f"cannot read: {e.strerror or e}") from None
    return parse_xmpuzzle(data, source)


# -------------------------------------------------------------------------------------------
# Writing
# -------------------------------------------------------------------------------------------


def _voxel_string(cells: Shape, size: tuple[int, int, int]) -> str:
    sx, sy, sz = size
    chars = ["_"] * (sx * sy * sz)
    for x, y, z in cells:
        chars[x + sx * (y + sy * z)] = "#"
    return "".join(chars)


def assembled_puzzle(
    pieces: Mapping[str, Shape], *, name: str = "CHAIN-geo puzzle", comment: str = ""
) -> BTPuzzle:
    """A one-problem puzzle: each piece its own shape (count 1), the union as the result, and
    the assembly itself stored as the one solution (so BurrTools shows it and can disassemble
    it)."""
    names = sorted(pieces)
    allv = np.concatenate([pieces[n].voxels for n in names])
    base = allv.min(axis=0)
    shapes: list[BTShape] = []
    placements: list[BTPlacement | None] = []
    for i, n in enumerate(names):
        s = pieces[n]
        norm = s.normalized()
        shapes.append(BTShape(n, norm.extent, norm, Shape([])))
        pos = s.min_corner - base
        placements.append(BTPlacement(i, (int(pos[0]), int(pos[1]), int(pos[2])), 0))
    union = Shape(allv - base)
    shapes.append(BTShape("result", union.extent, union, Shape([])))
    problem = BTProblem(
        name,
        tuple((i, 1, 1) for i in range(len(names))),
        len(names),
        (BTSolution(tuple(placements)),),
        {"assemblies": 1},
    )
    return BTPuzzle(tuple(shapes), (problem,), comment)


def xmpuzzle_bytes(puzzle: BTPuzzle) -> bytes:
    """Canonical gzip bytes (fixed mtime, so the same puzzle is the same file)."""
    root = ET.Element("puzzle", version="2")
    ET.SubElement(root, "gridType", type="0")
    ET.SubElement(root, "colors")
    shapes = ET.SubElement(root, "shapes")
    for s in puzzle.shapes:
        attrs = {"x": str(s.size[0]), "y": str(s.size[1]), "z": str(s.size[2]), "type": "0"}
        if s.name:
            attrs["name"] = s.name
        node = ET.SubElement(shapes, "voxel", attrs)
        text = list(_voxel_string(s.filled, s.size))
        sx, sy, _ = s.size
        for x, y, z in s.variable:
            text[x + sx * (y + sy * z)] = "+"
        node.text = "".join(text)
    problems = ET.SubElement(root, "problems")
    for p in puzzle.problems:
        attrs = {"state": "2" if p.solutions else "0"}
        if p.name:
            attrs["name"] = p.name
        attrs.update({k: str(v) for k, v in sorted(p.recorded.items())})
        pn = ET.SubElement(problems, "problem", attrs)
        ps = ET.SubElement(pn, "shapes")
        for sid, lo, hi in p.pieces:
            if lo == hi:
                ET.SubElement(ps, "shape", id=str(sid), count=str(lo))
            else:
                ET.SubElement(ps, "shape", id=str(sid), min=str(lo), max=str(hi))
        ET.SubElement(pn, "result", id=str(p.result))
        ET.SubElement(pn, "bitmap")
        sols = ET.SubElement(pn, "solutions")
        for sol in p.solutions:
            toks = [
                "x"
                if pl is None
                else f"{pl.position[0]} {pl.position[1]} {pl.position[2]} {pl.transform}"
                for pl in sol.placements
            ]
            ET.SubElement(ET.SubElement(sols, "solution"), "assembly").text = " ".join(toks)
    if puzzle.comment:
        ET.SubElement(root, "comment").text = puzzle.comment
    ET.indent(root)
    xml = b'<?xml version="1.0"?>\n' + ET.tostring(root, encoding="utf-8")
    return gzip.compress(xml, mtime=0)


def write_xmpuzzle(puzzle: BTPuzzle, path: str | os.PathLike[str]) -> Path:
    return atomic_write(path, xmpuzzle_bytes(puzzle))
