"""An independent check of the voxel kinematics with FCL (python-fcl) on the piece meshes.

A test oracle that ships with the package on purpose: the property tests compare every move the
voxel engine allows with this verdict, and anyone who imports levels or adds a kind of move
(turns, other lattices) can run the same comparison on their own data without our test tree.
Turns (:func:`turn_is_legal`) are checked the same way, the motion being FCL's screw motion
about the turn's axis line, sampled every :data:`TURN_SAMPLES`-th of the quarter turn.

:mod:`chaingeo.core.kinematics` decides a move by testing every unit step on voxel sets. Here the
same question is put to a different engine on different data: the pieces are watertight
manifold3d meshes, the group's motion is FCL's continuous collision query along the straight
path, and the verdict is whether the moving meshes ever meet the others.

Two details make the verdicts comparable:

* Face contact. In the voxel model two pieces touching face to face do not collide, but FCL
  reports touching surfaces as contact. So every mesh is shrunk first (an exact L-infinity
  erosion, :func:`chaingeo.pictures.mesh.eroded_mesh`): the moving pieces by ``GROUP_EPS`` and
  the others by ``REST_EPS``. Touching faces are then ``GROUP_EPS + REST_EPS`` apart, while any
  real overlap of unit cubes remains an overlap of depth close to one unit. The two epsilons
  differ so that no face of the group is ever coplanar with a face of the rest.
* The solver. FCL's conservative advancement gives wrong answers for mesh (BVH) models
  (flexible-collision-library/fcl issues #120 and #555); its naive solver, which runs exact
  mesh-mesh intersection tests at evenly spaced times along the motion, is the one that works
  for meshes. We sample every quarter unit. That is exact here: a moving lattice cube overlaps
  a fixed one exactly while its offset along the axis lies in an open interval of width nearly
  two units around a whole number, so every overlap is caught at a quarter point off the whole
  number, where the two surfaces cross properly (at whole-number offsets a shrunk cube can lie
  entirely inside the other one, which a surface test cannot see).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from functools import lru_cache
from typing import Final

import fcl
import numpy as np
import numpy.typing as npt

from chaingeo.core.arrays import F64
from chaingeo.core.geometry import Cell, Shape
from chaingeo.pictures.mesh import eroded_mesh, mesh_arrays

GROUP_EPS: Final = 1e-3
REST_EPS: Final = 2e-3
SAMPLES_PER_UNIT: Final = 4
IntArray = npt.NDArray[np.int32]


@lru_cache(maxsize=512)
def _eroded_at_origin(shape: Shape, eps: float) -> tuple[F64, IntArray]:
    """Eroded mesh arrays of a normalised shape (the Minkowski difference is the slow part, and
    it commutes with translation, so it is computed once per shape)."""
    return mesh_arrays(eroded_mesh(shape, eps))


def _bvh(shapes: Sequence[Shape], eps: float) -> fcl.BVHModel:
    """One FCL mesh model holding the eroded meshes of several pieces."""
    vertices: list[F64] = []
    triangles: list[IntArray] = []
    base = 0
    for shape in shapes:
        v, f = _eroded_at_origin(shape.normalized(), eps)
        vertices.append(v + shape.min_corner)
        triangles.append(f + base)
        base += len(v)
    model = fcl.BVHModel()
    all_v = np.concatenate(vertices)
    all_f = np.concatenate(triangles).astype(np.int32)
    model.beginModel(len(all_v), len(all_f))
    model.addSubModel(all_v, all_f)
    model.endModel()
    return model


def swept_collision(
    group: Sequence[Shape], rest: Sequence[Shape], direction: Cell, distance: float
) -> bool:
    """Does ``group``, translated continuously by ``0 .. distance`` along ``direction``, ever
    meet ``rest``? (Meshes eroded as explained above; touching faces do not count.)"""
    if not rest:
        return False
    moving = fcl.CollisionObject(_bvh(group, GROUP_EPS), fcl.Transform())
    fixed = fcl.CollisionObject(_bvh(rest, REST_EPS), fcl.Transform())
    samples = math.ceil(distance * SAMPLES_PER_UNIT) + 1
    request = fcl.ContinuousCollisionRequest(
        num_max_iterations=samples,
        toc_err=1.0 / (4 * samples),
        ccd_motion_type=fcl.CCDMotionType.CCDM_TRANS,
        ccd_solver_type=fcl.CCDSolverType.CCDC_NAIVE,
    )
    result = fcl.ContinuousCollisionResult()
    end = fcl.Transform(np.asarray(direction, dtype=np.float64) * distance)
    fcl.continuousCollide(moving, end, fixed, fcl.Transform(), request, result)
    return bool(result.is_collide)


#: Samples of a quarter turn (every 0.1 degree): a turning unit square that overlaps a fixed one
#: does so over an interval of angles, and on this lattice (small scenes) that interval is far
#: wider than a tenth of a degree.
TURN_SAMPLES: Final = 900


def turning_collision(
    group: Sequence[Shape], rest: Sequence[Shape], axis: int, quarter: int, centre2: Cell
) -> bool:
    """Does ``group``, turned continuously by 90 degrees (``quarter`` +1 or -1, right hand
    about the positive ``axis``) about the line through ``centre2`` (doubled cell units, cell
    centres at whole numbers: :mod:`chaingeo.core.turns`), ever meet ``rest``?"""
    if not rest:
        return False
    moving = fcl.CollisionObject(_bvh(group, GROUP_EPS), fcl.Transform())
    fixed = fcl.CollisionObject(_bvh(rest, REST_EPS), fcl.Transform())
    # mesh coordinates put cell (i, j, k) at [i, i+1] x ..., its centre at i + 1/2
    point = np.asarray(centre2, dtype=np.float64) / 2 + 0.5
    angle = quarter * math.pi / 2
    c, s = math.cos(angle), math.sin(angle)
    u, v = (axis + 1) % 3, (axis + 2) % 3
    rot = np.eye(3)
    rot[u, u], rot[u, v], rot[v, u], rot[v, v] = c, -s, s, c
    end = fcl.Transform(rot, point - rot @ point)
    request = fcl.ContinuousCollisionRequest(
        num_max_iterations=TURN_SAMPLES,
        toc_err=1.0 / (4 * TURN_SAMPLES),
        ccd_motion_type=fcl.CCDMotionType.CCDM_SCREW,
        ccd_solver_type=fcl.CCDSolverType.CCDC_NAIVE,
    )
    result = fcl.ContinuousCollisionResult()
    fcl.continuousCollide(moving, end, fixed, fcl.Transform(), request, result)
    return bool(result.is_collide)


def sweep_to_clear(group: Sequence[Shape], rest: Sequence[Shape], direction: Cell) -> float:
    """A travel after which the group lies wholly past the rest along the axis (from bounding
    boxes of the cells, not from the kinematics), plus one unit of margin."""
    axis = next(i for i in range(3) if direction[i])
    g = np.concatenate([s.voxels[:, axis] for s in group])
    r = np.concatenate([s.voxels[:, axis] for s in rest])
    gap = r.max() - g.min() + 1 if direction[axis] > 0 else g.max() - r.min() + 1
    return float(max(gap, 0) + 1)


def move_is_legal(
    pieces: Mapping[str, Shape], group: Sequence[str], direction: Cell, distance: int | None
) -> bool:
    """FCL's verdict on moving ``group`` (pieces where they stand) along ``direction`` by
    ``distance`` units, or, for ``None``, far enough to leave the others behind for good."""
    unknown = sorted(set(group) - set(pieces))
    if unknown:
        raise ValueError(f"unknown piece(s) {unknown}")
    moving = [pieces[n] for n in sorted(set(group))]
    rest = [pieces[n] for n in sorted(set(pieces) - set(group))]
    if not rest:
        return True
    travel = sweep_to_clear(moving, rest, direction) if distance is None else float(distance)
    return not swept_collision(moving, rest, direction, travel)


def turn_is_legal(
    pieces: Mapping[str, Shape], group: Sequence[str], axis: int, quarter: int, centre2: Cell
) -> bool:
    """FCL's verdict on turning ``group`` (pieces where they stand) by ``quarter`` about the
    line parallel to ``axis`` through ``centre2`` (see :func:`turning_collision`)."""
    unknown = sorted(set(group) - set(pieces))
    if unknown:
        raise ValueError(f"unknown piece(s) {unknown}")
    moving = [pieces[n] for n in sorted(set(group))]
    rest = [pieces[n] for n in sorted(set(pieces) - set(group))]
    return not turning_collision(moving, rest, axis, quarter, centre2)
