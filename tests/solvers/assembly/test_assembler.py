"""The assembler (exact-cover engine) plus the disassembler: BurrTools' 'assemblies' and
'solutions', checked against the figures of BurrTools' own example file."""

from __future__ import annotations

import json

import pytest

from chaingeo.cli.main import main
from chaingeo.core.geometry import Shape
from chaingeo.solvers.assembly.assemble import count_assemblies, iter_assemblies
from chaingeo.solvers.cover.problem import PieceSpec
from tests.support.shared_files import BT, needs_files


def test_small_assemblies_and_solutions() -> None:
    # Two L-trominoes and a domino fill a 2x2x2 cube in many ways; all of them come apart.
    ell = Shape([(0, 0, 0), (1, 0, 0), (0, 1, 0)])
    pieces = [PieceSpec(ell, "ell", 2, 2), PieceSpec(Shape([(0, 0, 0), (1, 0, 0)]), "bar")]
    target = Shape([(x, y, z) for x in range(2) for y in range(2) for z in range(2)])
    asms = list(iter_assemblies(pieces, target))
    assert asms and all(sorted(a) == ["bar", "ell", "ell_2"] for a in asms)
    for a in asms:
        cells = [c for s in a.values() for c in s.cells]
        assert sorted(cells) == sorted(target.cells)
    report = count_assemblies(pieces, target)
    assert report.assemblies == len(asms) and report.solutions == len(asms)


@needs_files
def test_solid_six_piece_burrs_1063_assemblies_314_solutions(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Cutler's 314 solid six-piece burrs: BurrTools reports 1063 assemblies, 314 solutions."""
    assert BT is not None
    assert (
        main(
            [
                "analyze",
                str(BT / "SolidSixPieceBurrs.xmpuzzle"),
                "--no-optimal",
                "--mirrors",
                "keep",
            ]
        )
        == 0
    )
    out = json.loads(capsys.readouterr().out)
    assert out["assemblies"] == 1063 and out["solutions"] == 314
    assert out["level"] == "1"
