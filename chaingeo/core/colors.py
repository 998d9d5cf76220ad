"""Named piece colours: one lowercase word a model can type, and an RGB hex for rendering.

The order is fixed and is the assignment order, chosen so that the first pieces of a level get
the most distinct hues (after Kelly's and Trubetskoy's lists of maximally distinct colours).

Any two colours of the palette differ by at least :data:`MIN_DELTA_E00` in CIEDE2000, so every
level, whichever of them it uses, passes the same check (``tests/pictures/test_colors.py``
holds it for the palette and for every shipped level). The first 13 colours are Trubetskoy's;
the later ones were moved (each by at most 11 ΔE00 from its named shade, so the name still fits,
and so that the materials of CHAIN's models still import as the same names) until the whole
palette cleared the bound: before, gold/mustard were 5.3 apart, cyan/sky 6.5, blue/cobalt 11.4.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Final

import numpy as np
import numpy.typing as npt

from chaingeo.core.arrays import F64

#: Least CIEDE2000 difference between any two piece colours of one level (and of the palette).
#: Blue and cobalt, which people confused on screen, were 11.4 apart.
MIN_DELTA_E00: Final = 12.0


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
        ("apricot", "#eac9ba"),
        ("navy", "#000075"),
        ("grey", "#a9a9a9"),
        ("white", "#f5f5f5"),
        ("gold", "#af8c46"),
        ("coral", "#c86e4b"),
        ("indigo", "#5a0555"),
        ("crimson", "#b40f5a"),
        ("turquoise", "#00d7c3"),
        ("salmon", "#ff968c"),
        ("khaki", "#c3b091"),
        ("plum", "#875a78"),
        ("sky", "#a0c8ff"),
        ("chocolate", "#5c3317"),
        ("forest", "#0b5d1e"),
        ("rose", "#ff66a3"),
        ("slate", "#737378"),
        ("mustard", "#f5a500"),
        ("cobalt", "#4b4b82"),
        ("peach", "#ffb982"),
        ("jade", "#328755"),
        ("violet", "#0a00ff"),
        ("rust", "#b7410e"),
        ("steel", "#0096be"),
        ("charcoal", "#36454f"),
        ("wine", "#722f37"),
        ("lilac", "#967db9"),
        ("moss", "#8a9a5b"),
        ("scarlet", "#ff2400"),
        ("amber", "#cdaf28"),
        ("azure", "#7391cd"),
    )
)

BY_NAME: Final[dict[str, NamedColor]] = {c.name: c for c in PALETTE}


def assign_colors(count: int) -> list[NamedColor]:
    """The first ``count`` palette colours, in palette order (deterministic)."""
    if count > len(PALETTE):
        raise ValueError(f"only {len(PALETTE)} named colours exist, {count} pieces asked for")
    return list(PALETTE[:count])


# ---------------------------------------------------------------------------------------------
# Colour difference: sRGB -> CIELAB (D65) -> CIEDE2000
# ---------------------------------------------------------------------------------------------

_SRGB_TO_XYZ: Final = np.array(
    [
        [0.4124564, 0.3575761, 0.1804375],
        [0.2126729, 0.7151522, 0.0721750],
        [0.0193339, 0.1191920, 0.9503041],
    ]
)
_D65: Final = np.array([0.95047, 1.0, 1.08883])
_EPSILON: Final = 216 / 24389  # CIE's exact constants, not the rounded 0.008856 / 7.787
_KAPPA: Final = 24389 / 27


def srgb_to_lab(rgb: npt.ArrayLike) -> F64:
    """CIELAB (D65 white) of 8-bit sRGB triples, shape (..., 3) -> (..., 3)."""
    c = np.asarray(rgb, dtype=np.float64) / 255.0
    linear = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    xyz = (linear @ _SRGB_TO_XYZ.T) / _D65
    f = np.where(xyz > _EPSILON, np.cbrt(xyz), (_KAPPA * xyz + 16) / 116)
    return np.stack(
        [116 * f[..., 1] - 16, 500 * (f[..., 0] - f[..., 1]), 200 * (f[..., 1] - f[..., 2])],
        axis=-1,
    )


def ciede2000(lab1: npt.ArrayLike, lab2: npt.ArrayLike) -> F64:
    """CIEDE2000 colour difference (k_L = k_C = k_H = 1) of CIELAB colours, broadcasting over
    leading axes; as published by CIE 142-2001, with the hue conventions of Sharma, Wu and
    Dalal (2005) where a chroma is zero."""
    l1, a1, b1 = np.moveaxis(np.asarray(lab1, dtype=np.float64), -1, 0)
    l2, a2, b2 = np.moveaxis(np.asarray(lab2, dtype=np.float64), -1, 0)
    c_bar = (np.hypot(a1, b1) + np.hypot(a2, b2)) / 2
    g = 0.5 * (1 - np.sqrt(c_bar**7 / (c_bar**7 + 25.0**7)))
    a1p, a2p = (1 + g) * a1, (1 + g) * a2
    c1p, c2p = np.hypot(a1p, b1), np.hypot(a2p, b2)
    achromatic = c1p * c2p == 0
    h1p = np.where(c1p == 0, 0.0, np.degrees(np.arctan2(b1, a1p)) % 360)
    h2p = np.where(c2p == 0, 0.0, np.degrees(np.arctan2(b2, a2p)) % 360)
    dh = h2p - h1p
    dh = np.where(dh > 180, dh - 360, np.where(dh < -180, dh + 360, dh))
    dh = np.where(achromatic, 0.0, dh)
    d_l, d_c = l2 - l1, c2p - c1p
    d_h = 2 * np.sqrt(c1p * c2p) * np.sin(np.radians(dh / 2))
    l_bar, cp_bar = (l1 + l2) / 2, (c1p + c2p) / 2
    h_sum = h1p + h2p
    h_bar = np.where(
        np.abs(h1p - h2p) <= 180,
        h_sum / 2,
        np.where(h_sum < 360, (h_sum + 360) / 2, (h_sum - 360) / 2),
    )
    h_bar = np.where(achromatic, h_sum, h_bar)
    t = (
        1
        - 0.17 * np.cos(np.radians(h_bar - 30))
        + 0.24 * np.cos(np.radians(2 * h_bar))
        + 0.32 * np.cos(np.radians(3 * h_bar + 6))
        - 0.20 * np.cos(np.radians(4 * h_bar - 63))
    )
    d_theta = 30 * np.exp(-(((h_bar - 275) / 25) ** 2))
    r_c = 2 * np.sqrt(cp_bar**7 / (cp_bar**7 + 25.0**7))
    s_l = 1 + 0.015 * (l_bar - 50) ** 2 / np.sqrt(20 + (l_bar - 50) ** 2)
    s_c = 1 + 0.045 * cp_bar
    s_h = 1 + 0.015 * cp_bar * t
    r_t = -np.sin(np.radians(2 * d_theta)) * r_c
    x, y, z = d_l / s_l, d_c / s_c, d_h / s_h
    out: F64 = np.sqrt(x * x + y * y + z * z + r_t * y * z)
    return out


def min_delta_e00(colors: Sequence[tuple[int, int, int]]) -> tuple[float, int, int]:
    """(least CIEDE2000 difference, i, j) over all pairs of ``colors``; (inf, -1, -1) for
    fewer than two."""
    if len(colors) < 2:
        return float("inf"), -1, -1
    lab = srgb_to_lab(np.array(colors))
    d = ciede2000(lab[:, None, :], lab[None, :, :])
    d[np.tril_indices(len(colors))] = np.inf
    i, j = np.unravel_index(int(np.argmin(d)), d.shape)
    return float(d[i, j]), int(i), int(j)
