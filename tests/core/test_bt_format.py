"""The ``.xmpuzzle`` format: BurrTools' problem semantics read and written back unchanged, and
malformed or hostile files refused with a typed error."""

from __future__ import annotations

import gzip

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.core import limits
from chaingeo.core.formats.burrtools import (
    BTPart,
    BTPlacement,
    BTProblem,
    BTPuzzle,
    BTShape,
    BTSolution,
    BurrToolsError,
    parse_xmpuzzle,
    read_xmpuzzle,
    voxel_string,
    xmpuzzle_bytes,
    xmpuzzle_xml,
)
from chaingeo.core.geometry import Shape
from chaingeo.generator.bt_examples import EXAMPLES
from tests.support.paths import DATA
from tests.support.shared_files import BT, needs_files

DATA = DATA / "burrtools"


def _xml(body: str, colors: str = "") -> bytes:
    head = '<?xml version="1.0"?><puzzle version="2">'
    return f"{head}<colors>{colors}</colors>{body}</puzzle>".encode()


@pytest.mark.parametrize("name", sorted(EXAMPLES))
def test_example_files_are_the_builders_output(name: str) -> None:
    """tests/data/burrtools holds each example exactly as the builder writes it (regenerate
    with ``python -m chaingeo.generator.bt_examples tests/data/burrtools``)."""
    data = xmpuzzle_bytes(EXAMPLES[name]())
    assert (DATA / f"{name}.xmpuzzle").read_bytes() == data
    assert xmpuzzle_bytes(parse_xmpuzzle(data)) == data


@needs_files
@pytest.mark.parametrize("name", ["AlPackino", "SolidSixPieceBurrs"])
def test_burrtools_files_are_written_back_as_read(name: str) -> None:
    """Read and written again, BurrTools' own files give the same XML, line for line
    (stored separation trees included), apart from attribute order."""
    assert BT is not None
    path = BT / f"{name}.xmpuzzle"
    puzzle = read_xmpuzzle(path)
    assert parse_xmpuzzle(xmpuzzle_bytes(puzzle)) == puzzle
    theirs = gzip.decompress(path.read_bytes()).decode().splitlines()
    ours = xmpuzzle_xml(puzzle).decode().splitlines()
    assert len(theirs) == len(ours)
    for a, b in zip(theirs, ours, strict=True):
        assert sorted(a.replace("/>", " />").split()) == sorted(b.replace("/>", " />").split())


def test_colours_groups_ranges_and_bitmap_as_burrtools_writes_them() -> None:
    data = _xml(
        '<gridType type="0"/><shapes>'
        '<voxel x="2" y="1" z="1" type="0">#1#</voxel>'
        '<voxel x="3" y="1" z="1" hx="1" weight="3" type="0">#2+12_</voxel></shapes>'
        '<problems><problem maxHoles="1"><shapes><shape id="0" min="0" max="4">'
        '<group group="2" count="1"/><group group="0" count="1"/><group group="5" count="3"/>'
        '</shape><shape id="0" group="7"/></shapes><result id="1"/>'
        '<bitmap><pair piece="0" result="1"/><pair piece="11" result="0"/></bitmap>'
        "</problem></problems>",
        "".join('<color red="1" green="2" blue="3"/>' for _ in range(12)),
    )
    puzzle = parse_xmpuzzle(data)
    piece, result = puzzle.shapes
    assert piece.colors == (((0, 0, 0), 1),) and piece.color((1, 0, 0)) == 0
    assert result.colors == (((0, 0, 0), 2), ((1, 0, 0), 12))
    assert result.variable.cells == ((1, 0, 0),) and result.hotspot == (1, 0, 0)
    assert result.weight == 3
    prob = puzzle.problems[0]
    # nested groups (group 0 is "no group"), the group attribute (all pieces), count default 1
    assert prob.parts == (BTPart(0, 0, 4, ((2, 1), (5, 3))), BTPart(0, 1, 1, ((7, 1),)))
    assert prob.color_pairs == ((1, 2), (12, 1))  # the file counts colours from 0
    assert prob.max_holes == 1
    assert prob.placement_allowed(1, 2, 12) and not prob.placement_allowed(2, 1, 12)
    assert prob.placement_allowed(3, 0, 12) and prob.placement_allowed(3, 4, 0)
    assert voxel_string(result) == "#2+12_"
    again = parse_xmpuzzle(xmpuzzle_bytes(puzzle))
    assert again == puzzle


@pytest.mark.parametrize(
    ("body", "colors", "match"),
    [
        ('<shapes><voxel x="2" y="1" z="1" type="0">#3#</voxel></shapes>', 2, "colour 3"),
        ('<shapes><voxel x="2" y="1" z="1" type="0">1##</voxel></shapes>', 2, "before the first"),
        ('<shapes><voxel x="2" y="1" z="1" type="0">#_1</voxel></shapes>', 2, "empty voxel"),
        ('<shapes><voxel x="2" y="1" z="1" type="0">#x</voxel></shapes>', 0, "'x'"),
        ('<shapes><voxel x="2" y="1" z="1" type="0">###</voxel></shapes>', 0, "more than 2"),
        ('<shapes><voxel x="2000" y="1" z="1" type="0">#</voxel></shapes>', 0, "above 1024"),
        ('<shapes><voxel x="1000" y="1000" z="2" type="0">#</voxel></shapes>', 0, "grid"),
        ('<shapes><voxel x="a" y="1" z="1" type="0">#</voxel></shapes>', 0, "not an integer"),
        (
            '<shapes><voxel x="1" y="1" z="1" type="0">#</voxel></shapes><problems><problem>'
            '<shapes><shape id="0" min="3" max="2"/></shapes><result id="0"/></problem></problems>',
            0,
            "min 3 is above max 2",
        ),
        (
            '<shapes><voxel x="1" y="1" z="1" type="0">#</voxel></shapes><problems><problem>'
            '<shapes><shape id="0" count="300"/></shapes><result id="0"/></problem></problems>',
            0,
            "above 256",
        ),
        (
            '<shapes><voxel x="1" y="1" z="1" type="0">#</voxel></shapes><problems><problem>'
            '<shapes><shape id="1"/></shapes><result id="0"/></problem></problems>',
            0,
            "shape 1 does not exist",
        ),
        (
            '<shapes><voxel x="1" y="1" z="1" type="0">#</voxel></shapes><problems><problem>'
            '<shapes><shape id="0"/></shapes><result id="0"/><bitmap><pair piece="0" result="1"/>'
            "</bitmap></problem></problems>",
            1,
            "colour 2 of 1",
        ),
        (
            '<shapes><voxel x="1" y="1" z="1" type="0">#</voxel></shapes><problems><problem>'
            '<shapes><shape id="0"/></shapes><result id="0"/><solutions><solution><assembly>'
            "0 0 0 48</assembly></solution></solutions></problem></problems>",
            0,
            "transform 48",
        ),
    ],
)
def test_malformed_files_are_refused_with_where_and_why(body: str, colors: int, match: str) -> None:
    color = '<color red="1" green="1" blue="1"/>'
    with pytest.raises(BurrToolsError, match=match) as err:
        parse_xmpuzzle(_xml(body, color * colors), "f.xmpuzzle")
    assert err.value.source == "f.xmpuzzle" and err.value.where


def test_hostile_files_are_refused_before_the_work() -> None:
    bomb = gzip.compress(b"<puzzle>" + b" " * (limits.MAX_XMPUZZLE_XML_BYTES + 10) + b"</puzzle>")
    assert len(bomb) < limits.MAX_FILE_BYTES
    with pytest.raises(BurrToolsError, match="bytes of XML"):
        parse_xmpuzzle(bomb)
    laughs = b'<?xml version="1.0"?><!DOCTYPE p [<!ENTITY a "aaaa">]><puzzle>&a;</puzzle>'
    with pytest.raises(BurrToolsError, match="DOCTYPE"):
        parse_xmpuzzle(laughs)
    with pytest.raises(BurrToolsError, match="gzip"):
        parse_xmpuzzle(gzip.compress(_xml(""))[:-12])
    with pytest.raises(BurrToolsError, match="too long a number"):
        parse_xmpuzzle(_xml('<shapes><voxel x="1' + "0" * 40 + '" y="1" z="1">#</voxel></shapes>'))


# -- round trip of arbitrary puzzles ------------------------------------------------------------

_cells = st.tuples(st.integers(0, 2), st.integers(0, 2), st.integers(0, 1))


@st.composite
def _shapes(draw: st.DrawFn, n_colors: int) -> BTShape:
    marks = draw(st.dictionaries(_cells, st.sampled_from("#+"), min_size=1, max_size=8))
    colors = (
        draw(st.dictionaries(st.sampled_from(sorted(marks)), st.integers(1, n_colors)))
        if n_colors
        else {}
    )
    return BTShape(
        draw(st.none() | st.text("abc XYZ<&\"'", min_size=1, max_size=6)),
        (3, 3, 2),
        Shape([c for c, m in marks.items() if m == "#"]),
        Shape([c for c, m in marks.items() if m == "+"]),
        tuple(sorted(colors.items())),
        draw(st.tuples(st.integers(-2, 2), st.integers(-2, 2), st.integers(-2, 2))),
        draw(st.integers(0, 5)),
    )


@st.composite
def _problems(draw: st.DrawFn, n_shapes: int, n_colors: int) -> BTProblem:
    parts = []
    for _ in range(draw(st.integers(0, 3))):
        lo = draw(st.integers(0, 3))
        hi = draw(st.integers(lo, 4))
        groups = draw(
            st.lists(
                st.tuples(st.integers(1, 9), st.integers(1, 4)),
                max_size=2,
                unique_by=lambda g: g[0],
            )
        )
        parts.append(BTPart(draw(st.integers(0, n_shapes - 1)), lo, hi, tuple(groups)))
    slots = [p.shape for p in parts for _ in range(p.max)]
    solutions = []
    for _ in range(draw(st.integers(0, 2)) if slots else 0):  # an assembly places some piece
        placements = tuple(
            draw(
                st.none()
                | st.builds(
                    BTPlacement,
                    st.just(s),
                    st.tuples(st.integers(-3, 9), st.integers(-3, 9), st.integers(-3, 9)),
                    st.integers(0, 47),
                )
            )
            for s in slots
        )
        solutions.append(BTSolution(placements, (("asmNum", "3"),) if draw(st.booleans()) else ()))
    colors = range(1, n_colors + 1)
    pairs = (
        draw(st.sets(st.tuples(st.sampled_from(colors), st.sampled_from(colors))))
        if n_colors
        else set()
    )
    return BTProblem(
        draw(st.none() | st.text("pq r", min_size=1, max_size=5)),
        tuple(parts),
        draw(st.integers(0, n_shapes - 1)),
        tuple(solutions),
        {"assemblies": 4} if draw(st.booleans()) else {},
        tuple(sorted(pairs)),
        draw(st.none() | st.integers(0, 5)),
        draw(st.integers(0, 2)),
    )


@st.composite
def _puzzles(draw: st.DrawFn) -> BTPuzzle:
    n_colors = draw(st.integers(0, 3))
    shapes = draw(st.lists(_shapes(n_colors), min_size=1, max_size=4))
    problems = draw(st.lists(_problems(len(shapes), n_colors), max_size=3))
    return BTPuzzle(
        tuple(shapes),
        tuple(problems),
        draw(st.text("hello <world> & \u00e9", max_size=12)).strip(),
        tuple((k * 10, 255 - k, k) for k in range(n_colors)),
        draw(st.booleans()),
    )


@settings(max_examples=60, deadline=None)
@given(_puzzles())
def test_any_puzzle_read_back_is_the_same_puzzle(puzzle: BTPuzzle) -> None:
    data = xmpuzzle_bytes(puzzle)
    back = parse_xmpuzzle(data)
    normal = BTPuzzle(
        puzzle.shapes,
        tuple(
            BTProblem(
                p.name,
                p.parts,
                p.result,
                p.solutions,
                p.recorded,
                p.color_pairs,
                p.max_holes,
                p.state or (2 if p.solutions else 0),
            )
            for p in puzzle.problems
        ),
        puzzle.comment,
        puzzle.colors,
        puzzle.comment_popup,
    )
    assert back == normal
    assert xmpuzzle_bytes(back) == data


@settings(max_examples=150, deadline=None)
@given(st.data())
def test_damaged_files_raise_only_burrtools_errors(data: st.DataObject) -> None:
    """Bytes cut, dropped or replaced anywhere in a real file: read, or BurrToolsError."""
    xml = bytearray(xmpuzzle_xml(EXAMPLES[data.draw(st.sampled_from(sorted(EXAMPLES)))]()))
    for _ in range(data.draw(st.integers(1, 4))):
        i = data.draw(st.integers(0, len(xml) - 1))
        op = data.draw(st.sampled_from(["cut", "drop", "put"]))
        if op == "cut":
            del xml[i:]
        elif op == "drop":
            del xml[i : i + data.draw(st.integers(1, 20))]
        else:
            xml[i : i + 1] = data.draw(st.sampled_from([b"9", b"-", b"#7", b"+", b"x", b"<", b'"']))
        if not xml:
            break
    try:
        puzzle = parse_xmpuzzle(bytes(xml))
    except BurrToolsError:
        return
    assert parse_xmpuzzle(xmpuzzle_bytes(puzzle)) is not None


@settings(max_examples=40, deadline=None)
@given(_puzzles())
def test_any_readable_problem_is_analysed_or_refused_with_a_value_error(puzzle: BTPuzzle) -> None:
    """Whatever a readable file's problems say (empty pieces, variable voxels in a piece, no
    parts, colours), the analysis answers or raises a ValueError saying why."""
    from chaingeo.core.kinematics import SearchLimitError
    from chaingeo.solvers.analysis import RowOptions, problem_analysis_row
    from chaingeo.solvers.limits import SearchLimits

    back = parse_xmpuzzle(xmpuzzle_bytes(puzzle))
    for i in range(len(back.problems)):
        try:
            out = problem_analysis_row(
                back, i, RowOptions(SearchLimits(max_states=2000, seconds=5))
            )
        except (ValueError, SearchLimitError):
            continue
        assert out["assemblies"] is not None and out["assemblies"] >= out["solutions"] >= 0
