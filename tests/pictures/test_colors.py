"""CIEDE2000 against the published test data, and the palette check for every shipped level."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from chaingeo.core.colors import (
    BY_NAME,
    MIN_DELTA_E00,
    PALETTE,
    ciede2000,
    min_delta_e00,
    srgb_to_lab,
)
from chaingeo.pictures.raster import parse_color
from tests.support.paths import LEVELS

#: Sharma, Wu & Dalal (2005), "The CIEDE2000 color-difference formula: implementation notes,
#: supplementary test data, and mathematical observations", Color Res. Appl. 30(1), Table 1:
#: L1 a1 b1, L2 a2 b2, ΔE00 (all 34 pairs; they exercise the hue wrap-arounds, the mean-hue
#: branches, achromatic colours and the blue rotation term).
SHARMA = np.array(
    [
        (50.0000, 2.6772, -79.7751, 50.0000, 0.0000, -82.7485, 2.0425),
        (50.0000, 3.1571, -77.2803, 50.0000, 0.0000, -82.7485, 2.8615),
        (50.0000, 2.8361, -74.0200, 50.0000, 0.0000, -82.7485, 3.4412),
        (50.0000, -1.3802, -84.2814, 50.0000, 0.0000, -82.7485, 1.0000),
        (50.0000, -1.1848, -84.8006, 50.0000, 0.0000, -82.7485, 1.0000),
        (50.0000, -0.9009, -85.5211, 50.0000, 0.0000, -82.7485, 1.0000),
        (50.0000, 0.0000, 0.0000, 50.0000, -1.0000, 2.0000, 2.3669),
        (50.0000, -1.0000, 2.0000, 50.0000, 0.0000, 0.0000, 2.3669),
        (50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0009, 7.1792),
        (50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0010, 7.1792),
        (50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0011, 7.2195),
        (50.0000, 2.4900, -0.0010, 50.0000, -2.4900, 0.0012, 7.2195),
        (50.0000, -0.0010, 2.4900, 50.0000, 0.0009, -2.4900, 4.8045),
        (50.0000, -0.0010, 2.4900, 50.0000, 0.0010, -2.4900, 4.8045),
        (50.0000, -0.0010, 2.4900, 50.0000, 0.0011, -2.4900, 4.7461),
        (50.0000, 2.5000, 0.0000, 50.0000, 0.0000, -2.5000, 4.3065),
        (50.0000, 2.5000, 0.0000, 73.0000, 25.0000, -18.0000, 27.1492),
        (50.0000, 2.5000, 0.0000, 61.0000, -5.0000, 29.0000, 22.8977),
        (50.0000, 2.5000, 0.0000, 56.0000, -27.0000, -3.0000, 31.9030),
        (50.0000, 2.5000, 0.0000, 58.0000, 24.0000, 15.0000, 19.4535),
        (50.0000, 2.5000, 0.0000, 50.0000, 3.1736, 0.5854, 1.0000),
        (50.0000, 2.5000, 0.0000, 50.0000, 3.2972, 0.0000, 1.0000),
        (50.0000, 2.5000, 0.0000, 50.0000, 1.8634, 0.5757, 1.0000),
        (50.0000, 2.5000, 0.0000, 50.0000, 3.2592, 0.3350, 1.0000),
        (60.2574, -34.0099, 36.2677, 60.4626, -34.1751, 39.4387, 1.2644),
        (63.0109, -31.0961, -5.8663, 62.8187, -29.7946, -4.0864, 1.2630),
        (61.2901, 3.7196, -5.3901, 61.4292, 2.2480, -4.9620, 1.8731),
        (35.0831, -44.1164, 3.7933, 35.0232, -40.0716, 1.5901, 1.8645),
        (22.7233, 20.0904, -46.6940, 23.0331, 14.9730, -42.5619, 2.0373),
        (36.4612, 47.8580, 18.3852, 36.2715, 50.5065, 21.2231, 1.4146),
        (90.8027, -2.0831, 1.4410, 91.1528, -1.6435, 0.0447, 1.4441),
        (90.9257, -0.5406, -0.9208, 88.6381, -0.8985, -0.7239, 1.5381),
        (6.7747, -0.2908, -2.4247, 5.8714, -0.0985, -2.2286, 0.6377),
        (2.0776, 0.0795, -1.1350, 0.9033, -0.0636, -0.5514, 0.9082),
    ]
)


def test_ciede2000_matches_sharma_wu_dalal_table_1_both_ways() -> None:
    got = ciede2000(SHARMA[:, 0:3], SHARMA[:, 3:6])
    back = ciede2000(SHARMA[:, 3:6], SHARMA[:, 0:3])
    assert np.abs(got - SHARMA[:, 6]).max() < 5e-5
    assert np.abs(back - SHARMA[:, 6]).max() < 5e-5


def test_srgb_to_lab_known_points() -> None:
    # White is L=100 a=b=0 under D65; sRGB red is (53.24, 80.09, 67.20) (Lindbloom's figures).
    lab = srgb_to_lab([(255, 255, 255), (0, 0, 0), (255, 0, 0)])
    assert np.allclose(lab[0], (100, 0, 0), atol=1e-3)
    assert np.allclose(lab[1], (0, 0, 0), atol=1e-9)
    assert np.allclose(lab[2], (53.24, 80.09, 67.20), atol=0.02)


def test_min_delta_e00_names_the_closest_pair() -> None:
    d, i, j = min_delta_e00([(255, 0, 0), (0, 0, 255), (250, 0, 0)])
    assert (i, j) == (0, 2) and 0 < d < 3
    assert min_delta_e00([(1, 2, 3)]) == (float("inf"), -1, -1)


def test_whole_palette_clears_the_bound() -> None:
    d, i, j = min_delta_e00([c.rgb for c in PALETTE])
    assert d >= MIN_DELTA_E00, (PALETTE[i].name, PALETTE[j].name, d)
    assert len({c.hex for c in PALETTE}) == len({c.name for c in PALETTE}) == len(PALETTE)


SHIPPED = sorted(LEVELS.glob("**/*.json"))


def test_there_are_shipped_levels() -> None:
    assert len(SHIPPED) >= 100


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: p.stem)
def test_shipped_level_colours_are_far_apart_and_named_by_the_palette(path: Path) -> None:
    pieces = json.loads(path.read_text(encoding="utf-8"))["pieces"]
    assert [p["rgb"] for p in pieces] == [BY_NAME[p["name"]].hex for p in pieces]
    rgbs = [parse_color(p["rgb"]) for p in pieces]
    d, i, j = min_delta_e00(rgbs)
    assert d >= MIN_DELTA_E00, (pieces[i]["name"], pieces[j]["name"], round(d, 2))
