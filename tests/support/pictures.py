"""Scenes the picture tests draw, importable by a fresh interpreter too (the hash-seed test
renders them in a subprocess and compares bytes)."""

from __future__ import annotations

from chaingeo.core.colors import PALETTE
from chaingeo.core.piecesets import BEDLAM_SOLUTION
from chaingeo.pictures.scene import PieceMap


def bedlam_half() -> tuple[PieceMap, PieceMap]:
    """Bedlam's solution split in two: six pieces in place, the other seven laid in the tray."""
    names = sorted(BEDLAM_SOLUTION)
    boxed = {PALETTE[i].name: (BEDLAM_SOLUTION[n], PALETTE[i].hex) for i, n in enumerate(names[:6])}
    tray = {
        PALETTE[i].name: (BEDLAM_SOLUTION[n].normalized(), PALETTE[i].hex)
        for i, n in enumerate(names)
        if i >= 6
    }
    return boxed, tray
