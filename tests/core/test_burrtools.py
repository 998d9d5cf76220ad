"""BurrTools interop: the real example files (skipped when ../shared/burrtools is absent)."""

from __future__ import annotations

import gzip
import json
from pathlib import Path

import pytest

from chaingeo.cli.main import main
from chaingeo.core.formats.burrtools import (
    TRANSFORMS_BT,
    BurrToolsError,
    assembled_puzzle,
    parse_xmpuzzle,
    read_xmpuzzle,
    xmpuzzle_bytes,
)
from chaingeo.core.geometry import ROTATIONS, Shape
from chaingeo.core.piecesets.burrs import six_piece_family, solid_knot
from chaingeo.solvers.motion.disassemble import analyze_assembly
from tests.support.shared_files import BT, needs_files


def test_transform_table_is_the_cube_group() -> None:
    rotations = {r.tobytes() for r in ROTATIONS}
    assert len({t.tobytes() for t in TRANSFORMS_BT}) == 48
    assert all(t.tobytes() in rotations for t in TRANSFORMS_BT[:24])
    assert all(round(float(__import__("numpy").linalg.det(t))) == -1 for t in TRANSFORMS_BT[24:])


def test_other_grids_and_garbage_are_refused() -> None:
    other = b'<?xml version="1.0"?><puzzle version="2"><gridType type="1"/></puzzle>'
    with pytest.raises(BurrToolsError, match="only the cube grid"):
        parse_xmpuzzle(gzip.compress(other))
    with pytest.raises(BurrToolsError, match="invalid XML"):
        parse_xmpuzzle(b"<puzzle")
    bad = b'<puzzle><shapes><voxel x="2" y="1" z="1" type="0">#</voxel></shapes></puzzle>'
    with pytest.raises(BurrToolsError, match="1 voxels given"):
        parse_xmpuzzle(bad)


def test_export_round_trip(tmp_path: Path) -> None:
    pieces = {
        "red": Shape([(0, 0, 0), (1, 0, 0), (2, 0, 0)]),
        "blue": Shape([(0, 1, 0), (1, 1, 0), (2, 1, 0), (3, 1, 0), (3, 0, 0)]),
    }
    data = xmpuzzle_bytes(assembled_puzzle(pieces))
    assert data == xmpuzzle_bytes(assembled_puzzle(pieces))  # canonical bytes
    back = parse_xmpuzzle(data)
    (asm,) = back.assemblies(0)
    assert sorted(s.cells for s in asm.values()) == sorted(s.cells for s in pieces.values())
    assert (
        back.shapes[back.problems[0].result].filled.cells
        == Shape([c for s in pieces.values() for c in s]).cells
    )


@needs_files
def test_alpackino_stored_solution_and_level() -> None:
    assert BT is not None
    puzzle = read_xmpuzzle(BT / "AlPackino.xmpuzzle")
    prob = puzzle.problems[0]
    assert [(s, lo, hi) for s, lo, hi in prob.pieces] == [
        (0, 1, 1),
        (1, 4, 4),
        (2, 4, 4),
        (3, 4, 4),
    ]
    (asm,) = puzzle.assemblies(0)
    assert Shape([c for s in asm.values() for c in s]) == puzzle.shapes[prob.result].filled
    result = analyze_assembly({f"p{k:02d}": s for k, s in asm.items()}, optimal=False)
    assert result.first_level == 1  # BurrTools: the first piece comes free in 1 move
    # BurrTools' own stored separation tree has these moves per separation (12 separations).
    assert result.level == "1.1.1.1.1.2.1.3.1.2.1.2" and result.moves == 17


@needs_files
def test_solid_burr_file_matches_our_family_and_knot() -> None:
    assert BT is not None
    puzzle = read_xmpuzzle(BT / "SolidSixPieceBurrs.xmpuzzle")
    assert puzzle.shapes[25].filled == solid_knot()
    family = {s.canonical() for s in six_piece_family().values()}
    assert len(family) == 837
    assert all(puzzle.shapes[i].filled.canonical() in family for i in range(25))
    stored = puzzle.assemblies(0)
    assert len(stored) == 314 == puzzle.problems[0].recorded["solutions"]
    assert all(
        analyze_assembly({f"p{k}": s for k, s in a.items()}, optimal=False).disassemblable
        for a in stored
    )


@needs_files
def test_chain_analyze_prints_one_json_object(capsys: pytest.CaptureFixture[str]) -> None:
    assert BT is not None
    assert main(["analyze", str(BT / "SolidSixPieceBurrs.xmpuzzle"), "--no-assemble"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["level"] == "1" and out["moves"] == 5 and out["optimal_steps"] == 5
    assert set(out) >= {"assemblies", "solutions", "level", "moves", "optimal_steps", "seconds"}
