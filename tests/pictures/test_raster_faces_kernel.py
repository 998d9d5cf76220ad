"""The kernels' visible faces are the reference's, array for array."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.pictures.raster import visible_faces
from chaingeo.pictures.raster_faces_kernel import visible_faces as fast_faces
from chaingeo.pictures.scene import BACK_CAMERA, CAMERAS
from tests.support.equivalence import assert_same

cell = st.tuples(st.integers(-3, 5), st.integers(-3, 5), st.integers(-3, 5))
CAMS = (*CAMERAS.values(), BACK_CAMERA)


@settings(max_examples=150, deadline=None)
@given(st.sets(cell, max_size=40), st.integers(0, 2**32 - 1))
def test_visible_faces_are_the_references(cells: set[tuple[int, int, int]], seed: int) -> None:
    arr = np.array(sorted(cells), dtype=np.int64).reshape(-1, 3)
    colors = np.random.default_rng(seed).integers(0, 256, (len(arr), 3)).astype(np.float64)
    for cam in CAMS:
        assert_same(visible_faces(arr, colors, cam), fast_faces(arr, colors, cam), "faces")


def test_the_check_catches_a_kernel_that_differs() -> None:
    """The shared check is not vacuous: one changed element, a widened dtype, a missing row."""
    arr = np.array([[0, 0, 0], [1, 0, 0]], dtype=np.int64)
    faces = visible_faces(arr, np.zeros((2, 3)), CAMERAS["iso"])
    bad = [
        dataclasses.replace(faces, cells=faces.cells + 1),
        dataclasses.replace(faces, fills=faces.fills.astype(np.float32)),
        dataclasses.replace(faces, normals=faces.normals[:-1]),
    ]
    for other in bad:
        with pytest.raises(AssertionError):
            assert_same(faces, other, "faces")
