"""FCL on the piece meshes agrees with the voxel kinematics on every move of random scenes."""

from __future__ import annotations

import fcl
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import DIRECTIONS, Assembly, Move, MoveError
from chaingeo.envs.render.collision_check import move_is_legal, swept_collision
from chaingeo.envs.render.mesh import mesh_arrays, piece_mesh

DISTANCES = (1, 2, 3, None)


@st.composite
def scenes(draw: st.DrawFn) -> dict[str, Shape]:
    """A small box shared out among 2-4 pieces, some cells left empty so that moves vary
    (pieces need not be connected: the kinematics takes any voxel sets)."""
    dims = draw(
        st.tuples(*(st.integers(1, 3) for _ in range(3))).filter(lambda d: d[0] * d[1] * d[2] >= 2)
    )
    cells = [(x, y, z) for x in range(dims[0]) for y in range(dims[1]) for z in range(dims[2])]
    n = draw(st.integers(2, 4))
    owner = draw(st.lists(st.integers(-1, n - 1), min_size=len(cells), max_size=len(cells)))
    pieces = {
        f"p{k}": Shape([c for c, o in zip(cells, owner, strict=True) if o == k]) for k in range(n)
    }
    pieces = {name: s for name, s in pieces.items() if len(s)}
    if len(pieces) < 2:  # force two pieces: the first two cells
        pieces = {"p0": Shape([cells[0]]), "p1": Shape([cells[1]])}
    return pieces


def _voxel_legal(pieces: dict[str, Shape], group: tuple[str, ...], d: str, k: int | None) -> bool:
    try:
        Assembly.assembled(pieces).check(Move(group, d, k))
    except MoveError:
        return False
    return True


@settings(max_examples=60)
@given(scenes(), st.data())
def test_fcl_swept_motion_agrees_with_voxel_legality(
    pieces: dict[str, Shape], data: st.DataObject
) -> None:
    names = sorted(pieces)
    size = data.draw(st.integers(1, len(names) - 1))
    group = tuple(sorted(data.draw(st.permutations(names))[:size]))
    for d, step in DIRECTIONS.items():
        for k in DISTANCES:
            voxel = _voxel_legal(pieces, group, d, k)
            assert move_is_legal(pieces, group, step, k) == voxel, (group, d, k)


def test_face_contact_is_not_collision_but_overlap_is() -> None:
    a, b = [Shape([(0, 0, 0)])], [Shape([(0, 1, 0)]), Shape([(2, 0, 0)])]
    assert not swept_collision(a, b, (1, 0, 0), 1.0)  # slides along b[0], stops short of b[1]
    assert swept_collision(a, b, (1, 0, 0), 2.0)
    assert swept_collision(a, b, (1, 0, 0), 7.0)  # passes through: caught on the way
    assert not swept_collision(a, b, (-1, 0, 0), 7.0)


def test_fcl_alone_calls_face_contact_a_collision() -> None:
    """Why the meshes are eroded: unshrunk, two cubes that merely touch count as colliding."""

    def obj(shape: Shape) -> fcl.CollisionObject:
        v, f = mesh_arrays(piece_mesh(shape))
        model = fcl.BVHModel()
        model.beginModel(len(v), len(f))
        model.addSubModel(v, f)
        model.endModel()
        return fcl.CollisionObject(model, fcl.Transform())

    result = fcl.CollisionResult()
    touching = fcl.collide(
        obj(Shape([(0, 0, 0)])), obj(Shape([(1, 0, 0)])), fcl.CollisionRequest(), result
    )
    assert touching > 0 and result.is_collision
    assert np.isclose(piece_mesh(Shape([(0, 0, 0)])).volume, 1.0)
