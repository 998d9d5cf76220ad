"""Writing BurrTools ``.xmpuzzle`` files: everything :mod:`chaingeo.core.formats.bt_read`
reads, laid out as BurrTools saves it, so a file read and written back is the same puzzle.

Bytes are canonical (fixed gzip mtime, fixed attribute order): the same puzzle is the same file.
"""

from __future__ import annotations

import gzip
import os
import re
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from chaingeo.core.files import atomic_write
from chaingeo.core.formats import bt_model as bm
from chaingeo.core.geometry import Shape

_EMPTY_TAG = re.compile(rb'(<[A-Za-z]+(?:\s+[A-Za-z]+="[^"]*")*) />')


def voxel_string(shape: bm.BTShape) -> str:
    """``#``/``+``/``_`` per grid cell, x fastest, each coloured voxel followed by its colour."""
    sx, sy, sz = shape.size
    chars = ["_"] * (sx * sy * sz)
    for marks, ch in ((shape.filled, "#"), (shape.variable, "+")):
        for x, y, z in marks:
            chars[x + sx * (y + sy * z)] = ch
    for (x, y, z), color in shape.colors:
        chars[x + sx * (y + sy * z)] += str(color)
    return "".join(chars)


def _shape_node(parent: ET.Element, s: bm.BTShape) -> None:
    attrs = {"x": str(s.size[0]), "y": str(s.size[1]), "z": str(s.size[2])}
    for axis, h in zip("xyz", s.hotspot, strict=True):
        if h:
            attrs[f"h{axis}"] = str(h)
    if s.weight != 1:
        attrs["weight"] = str(s.weight)
    if s.name:
        attrs["name"] = s.name
    attrs["type"] = "0"
    ET.SubElement(parent, "voxel", attrs).text = voxel_string(s)


def _part_node(parent: ET.Element, p: bm.BTPart) -> None:
    attrs = {"id": str(p.shape)}
    if p.min == p.max:
        attrs["count"] = str(p.min)
    else:
        attrs.update(min=str(p.min), max=str(p.max))
    nested = False
    if len(p.groups) == 1 and p.groups[0][1] == p.max:
        attrs["group"] = str(p.groups[0][0])  # all pieces of the part in one group
    elif p.groups:
        nested = True
    node = ET.SubElement(parent, "shape", attrs)
    if nested:
        for gid, count in p.groups:
            ET.SubElement(node, "group", group=str(gid), count=str(count))


def _placement_text(pl: bm.BTPlacement | None) -> str:
    if pl is None:
        return "x"
    return f"{pl.position[0]} {pl.position[1]} {pl.position[2]} {pl.transform}"


def _problem_node(parent: ET.Element, p: bm.BTProblem) -> None:
    attrs: dict[str, str] = {}
    if p.name:
        attrs["name"] = p.name
    state = p.state or (2 if p.solutions else 0)
    attrs["state"] = str(state)
    attrs.update({k: str(v) for k, v in sorted(p.recorded.items())})
    if p.max_holes is not None:
        attrs["maxHoles"] = str(p.max_holes)
    pn = ET.SubElement(parent, "problem", attrs)
    ps = ET.SubElement(pn, "shapes")
    for part in p.parts:
        _part_node(ps, part)
    ET.SubElement(pn, "result", id=str(p.result))
    bitmap = ET.SubElement(pn, "bitmap")
    for pc, rc in p.color_pairs:  # 0-based in the file
        ET.SubElement(bitmap, "pair", piece=str(pc - 1), result=str(rc - 1))
    if p.solutions:
        sols = ET.SubElement(pn, "solutions")
        for sol in p.solutions:
            node = ET.SubElement(sols, "solution", dict(sol.attributes))
            text = " ".join(_placement_text(pl) for pl in sol.placements)
            ET.SubElement(node, "assembly").text = text
            for extra in sol.extra:
                node.append(ET.fromstring(extra))


def xmpuzzle_xml(puzzle: bm.BTPuzzle) -> bytes:
    """The XML document (uncompressed)."""
    root = ET.Element("puzzle", version="2")
    ET.SubElement(root, "gridType", type="0")
    colors = ET.SubElement(root, "colors")
    for r, g, b in puzzle.colors:
        ET.SubElement(colors, "color", red=str(r), green=str(g), blue=str(b))
    shapes = ET.SubElement(root, "shapes")
    for s in puzzle.shapes:
        _shape_node(shapes, s)
    problems = ET.SubElement(root, "problems")
    for p in puzzle.problems:
        _problem_node(problems, p)
    if puzzle.comment or puzzle.comment_popup:
        node = ET.SubElement(root, "comment", {"popup": ""} if puzzle.comment_popup else {})
        node.text = puzzle.comment or None
    ET.indent(root)
    body: bytes = ET.tostring(root, encoding="utf-8")
    body = _EMPTY_TAG.sub(rb"\1/>", body)  # <a x="1"/> as BurrTools writes it, not <a x="1" />
    return b'<?xml version="1.0"?>\n' + body


def xmpuzzle_bytes(puzzle: bm.BTPuzzle) -> bytes:
    """Canonical gzip bytes (fixed mtime, so the same puzzle is the same file)."""
    return gzip.compress(xmpuzzle_xml(puzzle), mtime=0)


def write_xmpuzzle(puzzle: bm.BTPuzzle, path: str | os.PathLike[str]) -> Path:
    return atomic_write(path, xmpuzzle_bytes(puzzle))


def assembled_puzzle(
    pieces: Mapping[str, Shape], *, name: str = "CHAIN-geo puzzle", comment: str = ""
) -> bm.BTPuzzle:
    """A one-problem puzzle: each piece its own shape (count 1), the union as the result, and
    the assembly itself stored as the one solution (so BurrTools shows it and can disassemble
    it)."""
    names = sorted(pieces)
    allv = np.concatenate([pieces[n].voxels for n in names])
    base = allv.min(axis=0)
    shapes: list[bm.BTShape] = []
    placements: list[bm.BTPlacement | None] = []
    for i, n in enumerate(names):
        s = pieces[n]
        norm = s.normalized()
        shapes.append(bm.BTShape(n, norm.extent, norm, Shape([])))
        pos = s.min_corner - base
        placements.append(bm.BTPlacement(i, (int(pos[0]), int(pos[1]), int(pos[2])), 0))
    union = Shape(allv - base)
    shapes.append(bm.BTShape("result", union.extent, union, Shape([])))
    problem = bm.BTProblem(
        name,
        tuple(bm.BTPart(i, 1, 1) for i in range(len(names))),
        len(names),
        (bm.BTSolution(tuple(placements)),),
        {"assemblies": 1},
    )
    return bm.BTPuzzle(tuple(shapes), (problem,), comment)
