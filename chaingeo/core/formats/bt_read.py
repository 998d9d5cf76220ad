"""Reading BurrTools ``.xmpuzzle`` files (gzip-compressed XML, cube grid only).

Everything that changes what a problem means is read: colours (``<colors>``, and ``#N`` /
``+N`` after a voxel), variable voxels, hotspots and weights, each problem's parts
(``count``, or a ``min``/``max`` range, default 1; ``group=`` or nested ``<group group count>``
tags), result, colour rules (``<bitmap>`` pairs, 0-based colour numbers in the file), hole cap
(``maxHoles``) and stored solutions (placements; the separation trees kept as XML text).

Hostile input meets a typed error before it costs anything: the sizes in
:mod:`chaingeo.core.limits` bound the decompressed XML, the grids, the shapes, problems and
pieces; a DOCTYPE or entity declaration is refused in any encoding (looked for after decoding,
:mod:`chaingeo.core.formats.xml_guard`); every number is checked. Each error is a
:class:`BurrToolsError` naming the file, the element and the reason.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
import zlib

from chaingeo.core import limits
from chaingeo.core.files import UnreadableFile, read_bounded
from chaingeo.core.formats.bt_model import (
    MAX_COLORS,
    RGB,
    TRANSFORMS_BT,
    BTPart,
    BTPlacement,
    BTProblem,
    BTPuzzle,
    BTShape,
    BTSolution,
    BurrToolsError,
    Cell,
)
from chaingeo.core.formats.xml_read import XmlRefused, parse_bounded, to_text
from chaingeo.core.geometry import Shape


def _int(
    src: str, where: str, value: str | None, lo: int | None = None, hi: int | None = None
) -> int:
    if value is None:
        raise BurrToolsError(src, where, "missing number")
    text = value.strip()
    if len(text.lstrip("+-")) > limits.MAX_INT_DIGITS:
        raise BurrToolsError(src, where, f"{value[:24]!r}... is too long a number")
    try:
        out = int(text)
    except ValueError:
        raise BurrToolsError(src, where, f"{value!r} is not an integer") from None
    if lo is not None and out < lo:
        raise BurrToolsError(src, where, f"{out} is below {lo}")
    if hi is not None and out > hi:
        raise BurrToolsError(src, where, f"{out} is above {hi}")
    return out


def _gunzip(data: bytes, source: str) -> bytes:
    """Every member of a gzip stream (BurrTools writes one; ``cat a.gz b.gz`` makes two, and
    gzip reads them all), decompressed up to one byte past the XML limit."""
    budget = limits.MAX_XMPUZZLE_XML_BYTES + 1
    out: list[bytes] = []
    rest = data
    while rest[:2] == b"\x1f\x8b" and budget > 0:
        d = zlib.decompressobj(wbits=16 + zlib.MAX_WBITS)
        try:
            out.append(d.decompress(rest, budget))
        except zlib.error as e:
            raise BurrToolsError(source, "(file)", f"not a readable gzip stream: {e}") from None
        budget -= len(out[-1])
        if not d.eof:
            if budget > 0:
                raise BurrToolsError(source, "(file)", "not a readable gzip stream: truncated")
            break
        rest = d.unused_data
    if rest.strip(b"\0") and budget > 0:
        raise BurrToolsError(source, "(file)", "not a readable gzip stream: data after it")
    return b"".join(out)


def _decompress(data: bytes, source: str) -> bytes:
    raw = _gunzip(data, source) if data[:2] == b"\x1f\x8b" else data
    if len(raw) > limits.MAX_XMPUZZLE_XML_BYTES:
        raise BurrToolsError(
            source, "(file)", f"more than {limits.MAX_XMPUZZLE_XML_BYTES} bytes of XML"
        )
    return raw


def _parse_voxels(src: str, where: str, node: ET.Element, n_colors: int) -> BTShape:
    if node.get("type", "0") != "0":
        raise BurrToolsError(src, where, f"voxel type {node.get('type')} is not the cube grid")
    sx, sy, sz = (_int(src, f"{where}.{k}", node.get(k), 0, limits.MAX_COORD) for k in "xyz")
    if sx * sy * sz > limits.MAX_BT_GRID_CELLS:
        raise BurrToolsError(
            src, where, f"a {sx}x{sy}x{sz} grid; at most {limits.MAX_BT_GRID_CELLS} cells"
        )
    hotspot = tuple(
        _int(src, f"{where}.h{k}", node.get(f"h{k}", "0"), -limits.MAX_COORD, limits.MAX_COORD)
        for k in "xyz"
    )
    weight = _int(src, f"{where}.weight", node.get("weight", "1"), 0, 1 << 31)
    text = "".join((node.text or "").split())
    filled: list[Cell] = []
    variable: list[Cell] = []
    colors: list[tuple[Cell, int]] = []
    idx = 0
    i = 0
    while i < len(text):
        ch = text[i]
        if ch not in "#+_":
            what = "colour digits before the first voxel" if ch.isdigit() else repr(ch)
            raise BurrToolsError(src, where, f"unexpected {what} in the voxel string")
        j = i + 1
        while j < len(text) and text[j].isdigit():
            j += 1
        if idx >= sx * sy * sz:
            raise BurrToolsError(src, where, f"more than {sx * sy * sz} voxels for the grid")
        cell = (idx % sx, (idx // sx) % sy, idx // (sx * sy))
        if j > i + 1:
            color = _int(src, f"{where} voxel {cell}", text[i + 1 : j], 0, MAX_COLORS)
            if color > n_colors:
                raise BurrToolsError(
                    src, where, f"voxel {cell} has colour {color}; {n_colors} colours are defined"
                )
            if color and ch == "_":
                raise BurrToolsError(src, where, f"empty voxel {cell} carries colour {color}")
            if color:
                colors.append((cell, color))
        if ch == "#":
            filled.append(cell)
        elif ch == "+":
            variable.append(cell)
        idx += 1
        i = j
    if idx != sx * sy * sz:
        raise BurrToolsError(src, where, f"{idx} voxels given for a {sx}x{sy}x{sz} grid")
    if len(filled) + len(variable) > limits.MAX_LEVEL_VOXELS:
        raise BurrToolsError(
            src, where, f"{len(filled) + len(variable)} voxels; at most {limits.MAX_LEVEL_VOXELS}"
        )
    return BTShape(
        node.get("name"),
        (sx, sy, sz),
        Shape(filled),
        Shape(variable),
        tuple(sorted(colors)),
        (hotspot[0], hotspot[1], hotspot[2]),
        weight,
    )


def _parse_assembly(
    src: str, where: str, text: str, slots: tuple[int, ...], n_shapes: int
) -> tuple[BTPlacement | None, ...]:
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
        x, y, z, t = _four_ints(src, where, toks[i : i + 4])
        i += 4
        if t == 255:  # older files: an unused piece
            out.append(None)
            continue
        if not 0 <= t < len(TRANSFORMS_BT):
            raise BurrToolsError(src, where, f"transform {t} of piece {slot} is not a cube one")
        if not 0 <= shape < n_shapes:
            raise BurrToolsError(src, where, f"shape {shape} does not exist")
        out.append(BTPlacement(shape, (x, y, z), t))
    if i != len(toks):
        raise BurrToolsError(src, where, f"{len(toks) - i} tokens left over")
    return tuple(out)


def _four_ints(src: str, where: str, toks: list[str]) -> tuple[int, int, int, int]:
    """Four numbers of an assembly: plain ``int`` on short tokens (a stored solution has
    dozens; SolidSixPieceBurrs stores 314), :func:`_int` (its checks, its errors) otherwise."""
    if max(map(len, toks)) <= limits.MAX_INT_DIGITS:
        try:
            x, y, z, t = map(int, toks)
            return x, y, z, t
        except ValueError:
            pass
    x, y, z, t = (_int(src, where, v) for v in toks)
    return x, y, z, t


def _parse_part(src: str, where: str, node: ET.Element, n_shapes: int) -> BTPart:
    cap = limits.MAX_PIECES
    sid = _int(src, f"{where}.id", node.get("id"), 0)
    if sid >= n_shapes:
        raise BurrToolsError(src, f"{where}.id", f"shape {sid} does not exist")
    if node.get("count") is not None:
        lo = hi = _int(src, f"{where}.count", node.get("count"), 0, cap)
    elif node.get("min") is not None and node.get("max") is not None:
        lo = _int(src, f"{where}.min", node.get("min"), 0, cap)
        hi = _int(src, f"{where}.max", node.get("max"), 0, cap)
        if lo > hi:
            raise BurrToolsError(src, where, f"min {lo} is above max {hi}")
    else:
        lo = hi = 1  # BurrTools' default
    groups: list[tuple[int, int]] = []
    grp = _int(src, f"{where}.group", node.get("group", "0"), 0, 0xFFFF)
    if grp:
        groups.append((grp, hi))
    else:
        for k, g in enumerate(node.findall("group")):
            gid = _int(src, f"{where}.group[{k}].group", g.get("group"), 0, 0xFFFF)
            cnt = _int(src, f"{where}.group[{k}].count", g.get("count"), 0, cap)
            if gid and cnt:  # group 0 is "no group", as BurrTools saves it
                groups.append((gid, cnt))
    return BTPart(sid, lo, hi, tuple(groups))


def _parse_problem(
    src: str, where: str, prob: ET.Element, shapes: tuple[BTShape, ...], n_colors: int
) -> BTProblem:
    parts = tuple(
        _parse_part(src, f"{where}.shapes[{k}]", s, len(shapes))
        for k, s in enumerate(prob.findall("shapes/shape"))
    )
    n_pieces = sum(p.max for p in parts)
    if n_pieces > limits.MAX_PIECES:
        raise BurrToolsError(src, where, f"{n_pieces} pieces; at most {limits.MAX_PIECES}")
    res = prob.find("result")
    if res is None:
        raise BurrToolsError(src, where, "no <result> shape")
    result = _int(src, f"{where}.result", res.get("id"), 0)
    if result >= len(shapes):
        raise BurrToolsError(src, f"{where}.result", f"shape {result} does not exist")
    pairs: set[tuple[int, int]] = set()
    for k, pair in enumerate(prob.findall("bitmap/pair")):
        w = f"{where}.bitmap[{k}]"
        pc = _int(src, f"{w}.piece", pair.get("piece"), 0, MAX_COLORS - 1)
        rc = _int(src, f"{w}.result", pair.get("result"), 0, MAX_COLORS - 1)
        if max(pc, rc) >= n_colors:
            raise BurrToolsError(src, w, f"colour {max(pc, rc) + 1} of {n_colors} defined")
        pairs.add((pc + 1, rc + 1))  # the file numbers colours from 0, voxels from 1
    max_holes = None
    if prob.get("maxHoles") is not None:
        max_holes = _int(src, f"{where}.maxHoles", prob.get("maxHoles"), 0)
    slots = tuple(p.shape for p in parts for _ in range(p.max))
    sols = []
    for si, sol in enumerate(prob.findall("solutions/solution")):
        asm = sol.find("assembly")
        if asm is None or not (asm.text or "").strip():
            continue
        w = f"{where}.solutions[{si}]"
        placements = _parse_assembly(src, w, asm.text or "", slots, len(shapes))
        extra = tuple(_compact_xml(e) for e in sol if e.tag != "assembly")
        sols.append(BTSolution(placements, tuple(sorted(sol.attrib.items())), extra))
    state = _int(src, f"{where}.state", prob.get("state", "0"), 0, 2)
    recorded = {
        k: _int(src, f"{where}.{k}", prob.get(k), 0)
        for k in ("assemblies", "solutions", "time")
        if prob.get(k)
    }
    return BTProblem(
        prob.get("name"),
        parts,
        result,
        tuple(sols),
        recorded,
        tuple(sorted(pairs)),
        max_holes,
        state,
    )


def _compact_xml(node: ET.Element) -> str:
    """The element as XML text without layout whitespace (so re-indenting keeps it equal).
    The element's layout is dropped in place: the parsed tree is the reader's own and read
    once (a copy through text cost 0.01 s of SolidSixPieceBurrs' 314 stored solutions)."""
    for el in node.iter():
        if el.text is not None and not el.text.strip():
            el.text = None
        if el.tail is not None and not el.tail.strip():
            el.tail = None
    tail, node.tail = node.tail, None
    try:
        return to_text(node)  # no recursion: the depth is bounded, but so is the stack
    finally:
        node.tail = tail


def _parse_colors(src: str, root: ET.Element) -> tuple[RGB, ...]:
    out: list[RGB] = []
    for k, c in enumerate(root.findall("colors/color")):
        rgb = tuple(
            _int(src, f"colors[{k}].{a}", c.get(a, "0"), 0, 255) for a in ("red", "green", "blue")
        )
        out.append((rgb[0], rgb[1], rgb[2]))
    if len(out) > MAX_COLORS:
        raise BurrToolsError(src, "colors", f"{len(out)} colours; BurrTools allows {MAX_COLORS}")
    return tuple(out)


def _check_total_cells(source: str, voxels: list[ET.Element]) -> None:
    """The grid cells of all shapes together, before any voxel string is read (each costs its
    cells in Python work)."""
    total = 0
    for i, v in enumerate(voxels):
        sizes = [_int(source, f"shapes[{i}].{k}", v.get(k), 0, limits.MAX_COORD) for k in "xyz"]
        total += sizes[0] * sizes[1] * sizes[2]
        if total > limits.MAX_BT_TOTAL_GRID_CELLS:
            raise BurrToolsError(
                source, "shapes", f"more than {limits.MAX_BT_TOTAL_GRID_CELLS} grid cells in all"
            )


def parse_xmpuzzle(data: bytes, source: str = "<xmpuzzle>") -> BTPuzzle:
    """Decode the bytes of a ``.xmpuzzle`` file (gzip or plain XML)."""
    if len(data) > limits.MAX_FILE_BYTES:
        raise BurrToolsError(source, "(file)", f"more than {limits.MAX_FILE_BYTES} bytes")
    raw = _decompress(data, source)
    try:  # DOCTYPE refused, depth and element count bounded as the tree is built
        root = parse_bounded(raw, limits.MAX_BT_XML_DEPTH, limits.MAX_BT_XML_ELEMENTS)
    except XmlRefused as e:
        raise BurrToolsError(source, "(file)", e.reason) from None
    if root.tag != "puzzle":
        raise BurrToolsError(source, "(file)", f"root element is <{root.tag}>, not <puzzle>")
    grid = root.find("gridType")
    gtype = "0" if grid is None else grid.get("type", "0")
    if gtype != "0":
        raise BurrToolsError(
            source, "gridType", f"grid type {gtype} is not supported; only the cube grid (0)"
        )
    colors = _parse_colors(source, root)
    voxels = root.findall("shapes/voxel")
    if len(voxels) > limits.MAX_BT_SHAPES:
        raise BurrToolsError(
            source, "shapes", f"{len(voxels)} shapes; at most {limits.MAX_BT_SHAPES}"
        )
    _check_total_cells(source, voxels)
    shapes = tuple(
        _parse_voxels(source, f"shapes[{i}]", v, len(colors)) for i, v in enumerate(voxels)
    )
    probs = root.findall("problems/problem")
    if len(probs) > limits.MAX_BT_PROBLEMS:
        raise BurrToolsError(
            source, "problems", f"{len(probs)} problems; at most {limits.MAX_BT_PROBLEMS}"
        )
    problems = tuple(
        _parse_problem(source, f"problems[{pi}]", p, shapes, len(colors))
        for pi, p in enumerate(probs)
    )
    comment_node = root.find("comment")
    comment = "" if comment_node is None else (comment_node.text or "")
    popup = comment_node is not None and "popup" in comment_node.attrib
    return BTPuzzle(shapes, problems, comment, colors, popup)


def read_xmpuzzle(path: str | os.PathLike[str]) -> BTPuzzle:
    source = str(path)
    try:
        data = read_bounded(path, limits.MAX_FILE_BYTES)
    except UnreadableFile as e:
        raise BurrToolsError(source, "(file)", e.reason) from None
    return parse_xmpuzzle(data, source)
