"""FCL on the piece meshes agrees with the voxel kinematics on every move of random scenes."""

from __future__ import annotations

import fcl
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from chaingeo.core.geometry import Shape
from chaingeo.core.kinematics import DIRECTIONS, Assembly, Move, MoveError
from chaingeo.pictures.collision_check import move_is_legal, swept_collision
from chaingeo.pictures.mesh import mesh_arrays, piece_mesh
from tests.support.puzzle_strategies import scenes

DISTANCES = (1, 2, 3, None)


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
