"""``.xmpuzzle`` files through the one bounded XML reader (issue #37, items 4 and 12): deep
nesting in a stored solution is a typed error naming the file (it was ``RecursionError``),
millions of elements and grids of millions of cells are refused before they cost memory or
time, every member of a multi-member gzip stream is read, and the non-recursive writer of kept
elements is byte-equal to ElementTree's."""

from __future__ import annotations

import gzip
import time
import tracemalloc
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.cli.main import main
from chaingeo.core.formats.bt_write import assembled_puzzle, xmpuzzle_xml
from chaingeo.core.formats.burrtools import BurrToolsError, parse_xmpuzzle, read_xmpuzzle
from chaingeo.core.formats.xml_read import to_text
from chaingeo.core.suite import load_level
from tests.support.paths import DATA

SOMA = DATA / "burrtools" / "soma_problems.xmpuzzle"
SOLID = DATA / "burrtools" / "solid_burrs.xmpuzzle"


def _xml(path: Path) -> bytes:
    data = path.read_bytes()
    return gzip.decompress(data) if data[:2] == b"\x1f\x8b" else data


def _with_solution_extra(extra: bytes) -> bytes:
    """A shipped burr as a BurrTools puzzle (its assembly stored as the one solution), with
    ``extra`` inside that solution."""
    xml = xmpuzzle_xml(assembled_puzzle(load_level("puzzle-easy-04-burr6").shapes))
    at = xml.index(b"</solution>")
    return xml[:at] + extra + xml[at:]


@pytest.mark.parametrize("depth", [300, 5_000, 200_000])
def test_deep_nesting_in_a_stored_solution_is_a_typed_error(tmp_path: Path, depth: int) -> None:
    path = tmp_path / "deep.xmpuzzle"
    path.write_bytes(gzip.compress(_with_solution_extra(b"<s>" * depth + b"</s>" * depth)))
    with pytest.raises(BurrToolsError, match="nested") as e:
        read_xmpuzzle(path)
    assert str(path) in str(e.value)


def test_chain_analyze_names_the_file_of_a_deep_solution(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "deep.xmpuzzle"
    path.write_bytes(gzip.compress(_with_solution_extra(b"<s>" * 5000 + b"</s>" * 5000)))
    assert main(["analyze", str(path)]) == 2
    err = capsys.readouterr().err
    assert str(path) in err and "nested" in err and "recursion" not in err


def test_a_nesting_within_the_bound_is_kept_and_written_back() -> None:
    extra = b"<s>" * 200 + b"x" + b"</s>" * 200
    puzzle = parse_xmpuzzle(_with_solution_extra(extra))
    assert extra.decode() in puzzle.problems[0].solutions[0].extra


def test_millions_of_elements_are_refused_in_bounded_time_and_memory() -> None:
    data = gzip.compress(_with_solution_extra(b"<a/>" * 4_000_000))
    assert len(data) < 60_000
    tracemalloc.start()
    t0 = time.perf_counter()
    with pytest.raises(BurrToolsError, match="elements"):
        parse_xmpuzzle(data)
    seconds = time.perf_counter() - t0
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 400 * 1024 * 1024 and seconds < 20


def test_grids_of_millions_of_cells_in_all_are_refused_before_reading() -> None:
    grid = b'<voxel x="100" y="100" z="100" type="0">' + b"_" * 1_000_000 + b"</voxel>"
    xml = _xml(SOMA)
    at = xml.index(b"</shapes>")
    data = gzip.compress(xml[:at] + grid * 3 + xml[at:])
    t0 = time.perf_counter()
    with pytest.raises(BurrToolsError, match="grid cells in all"):
        parse_xmpuzzle(data)
    assert time.perf_counter() - t0 < 5


@pytest.mark.parametrize("cut", [0.1, 0.5, 0.9])
def test_a_multi_member_gzip_file_is_read_whole(tmp_path: Path, cut: float) -> None:
    xml = _xml(SOLID)
    k = int(len(xml) * cut)
    path = tmp_path / "two.xmpuzzle"
    path.write_bytes(gzip.compress(xml[:k]) + gzip.compress(xml[k:]))
    assert read_xmpuzzle(path) == parse_xmpuzzle(gzip.compress(xml))


def test_data_after_the_gzip_stream_is_refused() -> None:
    with pytest.raises(BurrToolsError, match="data after it"):
        parse_xmpuzzle(gzip.compress(_xml(SOMA)) + b"garbage")


_NAMES = st.sampled_from(["a", "b", "separation", "state", "x-y"])
_TEXT = st.one_of(st.none(), st.text(st.sampled_from("ab &<>\"\r\n\t'é"), max_size=6))


@st.composite
def _trees(draw: st.DrawFn, depth: int = 0) -> ET.Element:
    el = ET.Element(draw(_NAMES))
    for k in draw(st.lists(_NAMES, max_size=3, unique=True)):
        el.set(k, draw(st.text(st.sampled_from("ab &<>\"\r\n\t'é"), max_size=5)))
    el.text, el.tail = draw(_TEXT), draw(_TEXT)
    if depth < 4:
        el.extend(draw(st.lists(_trees(depth + 1), max_size=3)))
    return el


@settings(max_examples=200, deadline=None)
@given(_trees())
def test_to_text_is_elementtrees_tostring(tree: ET.Element) -> None:
    assert to_text(tree) == ET.tostring(tree, encoding="unicode")
