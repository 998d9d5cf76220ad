"""Named piece colours: one lowercase word a model can type, and an RGB hex for rendering.

The order is fixed and is the assignment order, chosen so that the first pieces of a level get
the most distinct hues (after Kelly's and Trubetskoy's lists of maximally distinct colours).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final


@dataclass(frozen=True, order=True)
class NamedColor:
    name: str
    hex: str

    @property
    def rgb(self) -> tuple[int, int, int]:
        h = self.hex.lstrip("#")
        return int(h[0:2], 16), int(h[2:4], 16), int(h[4:6], 16)


PALETTE: Final[tuple[NamedColor, ...]] = tuple(
    NamedColor(n, h)
    for n, h in (
        ("red", "#e6194b"),
        ("green", "#3cb44b"),
        ("yellow", "#ffe119"),
        ("blue", "#4363d8"),
        ("orange", "#f58231"),
        ("purple", "#911eb4"),
        ("cyan", "#42d4f4"),
        ("magenta", "#f032e6"),
        ("lime", "#bfef45"),
        ("pink", "#fabed4"),
        ("teal", "#469990"),
        ("lavender", "#dcbeff"),
        ("brown", "#9a6324"),
        ("beige", "#fffac8"),
        ("maroon", "#800000"),
        ("mint", "#aaffc3"),
        ("olive", "#808000"),
        ("apricot", "#ffd8b1"),
        ("navy", "#000075"),
        ("grey", "#a9a9a9"),
        ("white", "#f5f5f5"),
        ("gold", "#c9a227"),
        ("coral", "#ff7f50"),
        ("indigo", "#4b0082"),
        ("crimson", "#9e0031"),
        ("turquoise", "#1abc9c"),
        ("salmon", "#fa8072"),
        ("khaki", "#c3b091"),
        ("plum", "#8e4585"),
        ("sky", "#87ceeb"),
        ("chocolate", "#5c3317"),
        ("forest", "#0b5d1e"),
        ("rose", "#ff66a3"),
        ("slate", "#5a6e7f"),
        ("mustard", "#e1ad01"),
        ("cobalt", "#0047ab"),
        ("peach", "#ffb07c"),
        ("jade", "#00a86b"),
        ("violet", "#7f00ff"),
        ("rust", "#b7410e"),
        ("steel", "#4682b4"),
        ("charcoal", "#36454f"),
        ("wine", "#722f37"),
        ("lilac", "#b666d2"),
        ("moss", "#8a9a5b"),
        ("scarlet", "#ff2400"),
        ("amber", "#ffbf00"),
        ("azure", "#007fff"),
    )
)

BY_NAME: Final[dict[str, NamedColor]] = {c.name: c for c in PALETTE}


def assign_colors(count: int) -> list[NamedColor]:
    """The first ``count`` palette colours, in palette order (deterministic)."""
    if count > len(PALETTE):
        raise ValueError(f"only {len(PALETTE)} named colours exist, {count} pieces asked for")
    return list(PALETTE[:count])
