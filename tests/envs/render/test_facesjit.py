"""The kernels' visible faces are the reference's, array for array."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.envs.render.facesjit import visible_faces as fast_faces
from chaingeo.envs.render.raster import visible_faces
from chaingeo.envs.render.scene import BACK_CAMERA, CAMERAS

cell = st.tuples(st.integers(-3, 5), st.integers(-3, 5), st.integers(-3, 5))
CAMS = (*CAMERAS.values(), BACK_CAMERA)


@settings(max_examples=150, deadline=None)
@given(st.sets(cell, max_size=40), st.integers(0, 2**32 - 1))
def test_visible_faces_are_the_references(cells: set[tuple[int, int, int]], seed: int) -> None:
    arr = np.array(sorted(cells), dtype=np.int64).reshape(-1, 3)
    colors = np.random.default_rng(seed).integers(0, 256, (len(arr), 3)).astype(np.float64)
    for cam in CAMS:
        want, got = visible_faces(arr, colors, cam), fast_faces(arr, colors, cam)
        for name in ("corners", "fills", "cells", "normals"):
            a, b = getattr(want, name), getattr(got, name)
            assert a.dtype == b.dtype and a.shape == b.shape and np.array_equal(a, b), name
