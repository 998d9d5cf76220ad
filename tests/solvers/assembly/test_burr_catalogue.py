"""The six-piece burr catalogue: Cutler's 59 notchable pieces, the 25 of solid burrs, and the
314 solid six-piece burrs that come apart (1063 assemblies, BurrTools' figures)."""

from __future__ import annotations

import pytest

from chaingeo.core.piecesets.burrs import (
    SOLID_BURR_CODES,
    notchable_family,
    six_piece_family,
    solid_burr_pieces,
    solid_knot,
)
from chaingeo.solvers.assembly.assemble import count_assemblies, solid_burr_codes
from chaingeo.solvers.cover.problem import PieceSpec
from tests.support.shared_files import BT, needs_files


def test_family_sizes() -> None:
    assert len(six_piece_family()) == 837  # every connected notched stick, up to rotation
    assert len(notchable_family()) == 59
    assert set(SOLID_BURR_CODES) <= set(notchable_family())
    assert len(solid_knot()) == 104


def test_314_solid_six_piece_burrs() -> None:
    pieces = [PieceSpec(s, n, 0, 6) for n, s in solid_burr_pieces().items()]
    report = count_assemblies(pieces, solid_knot())
    assert (report.assemblies, report.solutions) == (1063, 314)


@needs_files
def test_catalogue_is_burrtools_list() -> None:
    from chaingeo.core.formats.burrtools import read_xmpuzzle

    assert BT is not None
    puzzle = read_xmpuzzle(BT / "SolidSixPieceBurrs.xmpuzzle")
    ours = {s.canonical() for s in solid_burr_pieces().values()}
    assert ours == {puzzle.shapes[i].filled.canonical() for i in range(25)}


@pytest.mark.slow
def test_catalogue_recomputed_from_the_notchable_family() -> None:
    assert solid_burr_codes() == SOLID_BURR_CODES
