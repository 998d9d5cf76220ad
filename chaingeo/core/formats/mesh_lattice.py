"""Triangle meshes of a URDF model on the cubic lattice: loading, the lattice fit, voxelising.

This is the geometric half of the model importer (:mod:`chaingeo.core.formats.models` is the other):

* **Loading** (:mod:`chaingeo.core.formats.model_files`, which reads the files as hostile
  input): every URDF of a puzzle folder is one part; its ``visual`` meshes (OBJ) are scaled,
  turned by the ``origin rpy`` (fixed axes: ``Rz(yaw) Ry(pitch) Rx(roll)``)
  and shifted by ``origin xyz`` into the assembled arrangement. Angles in the files are rounded
  to five decimals (``1.57080``), so a rotation within 1e-4 of a signed permutation is taken to be
  that permutation: otherwise no face would be exactly axis-aligned.
* **Lattice fit**: only faces whose normal is an axis carry lattice information. Per part and axis
  their planes (positions weighted by area) are fitted by one unit ``u`` for the whole model and
  an origin per part and axis (a circular mean of the phases ``2 pi p / u``), so that parts built
  with clearance, each slightly off the common grid, still fit. The unit is the largest candidate
  (plane gaps divided by small integers, refined by least squares) whose area-weighted RMS
  deviation stays small: any divisor of the unit fits too, and a finer grid than needed would
  only multiply cells.
* **Voxelising**: a cell is decided by sub-samples and the generalised winding number (robust to
  the non-manifold edges some of these meshes have; trimesh's ``contains`` needs rtree and
  manifold3d refuses such meshes). Sample points go through a per-axis piecewise-linear map that
  passes through the part's own planes, so a notch widened by a clearance still covers whole
  cells. A cell that is neither clearly full nor clearly empty is *ambiguous*, and a model with
  ambiguous cells is refused rather than guessed.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Final

import numba
import numpy as np
import numpy.typing as npt

from chaingeo.core import limits
from chaingeo.core.arrays import F64
from chaingeo.core.geometry import Cell, Shape
from chaingeo.core.level import LevelError

IntArray = npt.NDArray[np.int64]

#: A face is axis-aligned when its normal is within this angle (radians) of an axis.
ALIGNED_ANGLE: Final = 1e-3
#: The least share of surface area facing along an axis for a model to be taken as a lattice model.
MIN_ALIGNED_SHARE: Final = 0.6
#: The largest area-weighted RMS deviation of planes from the lattice, in units, that still fits.
MAX_FIT_RMS: Final = 0.08
#: How far (units) the grids of two assembled parts may sit apart: clearance, not design.
MAX_SPREAD: Final = 0.4
#: Planes lighter than this share of their part's axis-aligned area (engravings, bevel lips) do
#: not vote in the fit or anchor the sample map.
MIN_PLANE_WEIGHT: Final = 0.01
#: Sub-sample offsets inside a cell, per axis (27 samples per cell).
SAMPLE_OFFSETS: Final = (0.25, 0.5, 0.75)
#: Share of inside samples below which a cell is empty and above which it is full.
EMPTY_BELOW: Final = 0.25
FULL_ABOVE: Final = 0.75
#: The most cells a part may span along one axis (a guard against absurdly fine units).
MAX_SPAN: Final = 64


class ModelImportError(LevelError):
    """A model that cannot be imported as lattice pieces: which model, what, and why.

    A :class:`~chaingeo.core.level.LevelError` so that every caller that reports level problems
    (the ``chain`` command among them) reports this one the same way.
    """


@dataclass(frozen=True)
class PartMesh:
    """One part in the assembled arrangement: world-space triangles and its material colour."""

    name: str
    vertices: F64
    faces: IntArray
    rgba: tuple[float, float, float, float] | None
    material: str | None
    files: tuple[str, ...]  # the visual meshes, relative to the model folder

    @cached_property
    def triangles(self) -> F64:
        return np.ascontiguousarray(self.vertices[self.faces], dtype=np.float64)

    @cached_property
    def bounds(self) -> tuple[F64, F64]:
        return self.vertices.min(axis=0), self.vertices.max(axis=0)

    @cached_property
    def volume(self) -> float:
        """Enclosed volume (divergence theorem; orientation-agnostic)."""
        t = self.triangles
        return abs(float(np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum()) / 6)


# ---------------------------------------------------------------------------------------------
# Loading
# ---------------------------------------------------------------------------------------------


def rpy_matrix(roll: float, pitch: float, yaw: float) -> F64:
    """URDF's fixed-axis roll-pitch-yaw rotation ``Rz(yaw) @ Ry(pitch) @ Rx(roll)``, with a
    rotation within 1e-4 of a signed permutation snapped to it (the files round angles)."""
    cr, sr, cp, sp = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    m = np.asarray(rz @ ry @ rx, dtype=np.float64)
    snapped = np.round(m)
    if np.abs(m - snapped).max() < 1e-4 and np.all(np.abs(snapped).sum(axis=0) == 1):
        return np.asarray(snapped, dtype=np.float64)
    return m


# ---------------------------------------------------------------------------------------------
# Axis-aligned faces and the lattice fit
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Planes:
    """A part's axis-aligned face planes: per axis, positions and areas (clustered)."""

    positions: tuple[F64, F64, F64]
    weights: tuple[F64, F64, F64]
    aligned_area: float
    total_area: float

    @property
    def aligned_share(self) -> float:
        return self.aligned_area / self.total_area if self.total_area > 0 else 0.0

    def significant(self, axis: int) -> tuple[F64, F64]:
        keep = self.weights[axis] >= MIN_PLANE_WEIGHT * self.aligned_area
        return self.positions[axis][keep], self.weights[axis][keep]


def face_planes(part: PartMesh, tolerance: float) -> Planes:
    """Cluster the axis-aligned faces of a part into planes (positions within ``tolerance``)."""
    tri = part.triangles
    cross = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    norm = np.linalg.norm(cross, axis=1)
    area = norm / 2
    ok = norm > 0
    unit = np.zeros_like(cross)
    unit[ok] = cross[ok] / norm[ok, None]
    centre = tri.mean(axis=1)
    cos_min = math.cos(ALIGNED_ANGLE)
    positions: list[F64] = []
    weights: list[F64] = []
    aligned = 0.0
    for axis in range(3):
        sel = ok & (np.abs(unit[:, axis]) >= cos_min)
        pos, w = centre[sel, axis], area[sel]
        aligned += float(w.sum())
        order = np.argsort(pos, kind="stable")
        pos, w = pos[order], w[order]
        cuts = np.flatnonzero(np.diff(pos) > tolerance) + 1
        groups = np.split(np.arange(len(pos)), cuts) if len(pos) else []
        positions.append(np.array([np.average(pos[g], weights=w[g] + 1e-300) for g in groups]))
        weights.append(np.array([w[g].sum() for g in groups]))
    return Planes(
        (positions[0], positions[1], positions[2]),
        (weights[0], weights[1], weights[2]),
        aligned,
        float(area.sum()),
    )


def _wrap(x: F64) -> F64:
    return np.asarray(x - np.round(x), dtype=np.float64)


def circular_origin(pos: F64, w: F64, unit: float) -> float:
    """The origin (mod ``unit``) that best aligns weighted positions: the phases' circular mean."""
    angle = 2 * np.pi * pos / unit
    return float(
        math.atan2(float(w @ np.sin(angle)), float(w @ np.cos(angle))) / (2 * np.pi) * unit
    )


@dataclass(frozen=True)
class LatticeFit:
    """One cubic lattice for a model: ``unit``, a global ``origin`` and how well planes fit.

    ``phase[p][a]``: how far part ``p``'s own grid sits from the global one along axis ``a``,
    in units within [-0.5, 0.5); ``rms`` and ``worst``: area-weighted RMS and largest deviation
    of the significant planes from their part's grid, in units.
    """

    unit: float
    origin: tuple[float, float, float]
    rms: float
    worst: float
    phase: dict[str, tuple[float, float, float]]


def _groups(parts: Sequence[PartMesh], planes: Sequence[Planes]) -> list[tuple[int, int]]:
    return [(i, a) for i in range(len(parts)) for a in range(3) if len(planes[i].significant(a)[0])]


def _fit_cost(planes: Sequence[Planes], groups: list[tuple[int, int]], unit: float) -> float:
    num = den = 0.0
    for i, a in groups:
        pos, w = planes[i].significant(a)
        o = circular_origin(pos, w, unit)
        dev = _wrap((pos - o) / unit)
        num += float(w @ dev**2)
        den += float(w.sum())
    return math.sqrt(num / den) if den > 0 else math.inf


def _refine(planes: Sequence[Planes], groups: list[tuple[int, int]], unit: float) -> float:
    """Least-squares unit for the plane indices that ``unit`` assigns (origins free per group)."""
    num = den = 0.0
    for i, a in groups:
        pos, w = planes[i].significant(a)
        o = circular_origin(pos, w, unit)
        k = np.round((pos - o) / unit)
        kb, pb = np.average(k, weights=w), np.average(pos, weights=w)
        num += float(w @ ((k - kb) * (pos - pb)))
        den += float(w @ (k - kb) ** 2)
    return num / den if den > 0 else unit


def _grid(
    parts: Sequence[PartMesh], planes: Sequence[Planes], unit: float
) -> tuple[tuple[float, float, float], dict[str, tuple[float, float, float]], float]:
    """The global origin (all parts' planes), each part's phase against it and the largest
    deviation of a significant plane from its own part's grid, all for one unit."""
    origin: list[float] = []
    phase: dict[str, list[float]] = {p.name: [0.0, 0.0, 0.0] for p in parts}
    worst = 0.0
    for a in range(3):
        pos_all = [planes[i].significant(a) for i in range(len(parts))]
        allp = np.concatenate([p for p, _ in pos_all])
        allw = np.concatenate([w for _, w in pos_all])
        o_glob = circular_origin(allp, allw, unit) if len(allp) else 0.0
        origin.append(o_glob)
        for i, (pos, w) in enumerate(pos_all):
            if len(pos) == 0:
                continue
            o = circular_origin(pos, w, unit)
            phase[parts[i].name][a] = float(_wrap(np.array([(o - o_glob) / unit]))[0])
            worst = max(worst, float(np.abs(_wrap((pos - o) / unit)).max()))
    return (
        (origin[0], origin[1], origin[2]),
        {k: (v[0], v[1], v[2]) for k, v in phase.items()},
        worst,
    )


def fit_lattice(
    parts: Sequence[PartMesh], planes: Sequence[Planes], source: str, *, common: bool = True
) -> LatticeFit:
    """The largest cubic unit whose grid (one origin per part and axis) the planes fit.

    ``common``: the parts are assembled, so their own grids may differ from each other by a
    clearance only (at most :data:`MAX_SPREAD` of a unit along any axis); otherwise a coarse
    unit could fit every part alone with parts half a unit apart. Pieces laid out apart pass
    ``False``.
    """
    groups = _groups(parts, planes)
    lo = np.min([p.bounds[0] for p in parts], axis=0)
    hi = np.max([p.bounds[1] for p in parts], axis=0)
    tiny = 1e-3 * float((hi - lo).max())
    raw: set[float] = set()
    for i, a in groups:
        pos, _ = planes[i].significant(a)
        for gap in np.diff(np.sort(pos)):
            if gap > tiny:
                raw.update(float(f"{gap / k:.4g}") for k in range(1, 7))
    tried: list[tuple[float, float]] = []
    off_grid: tuple[float, float] | None = None
    passing: list[tuple[float, float]] = []  # (unit, cost), largest unit first
    for cand in sorted(raw, reverse=True):
        # the candidate itself or its least-squares refinements, whichever fits best: clearance
        # planes can pull the refinement off a round design unit
        once = _refine(planes, groups, cand)
        options = [u for u in (cand, once, _refine(planes, groups, once)) if u > 0]
        cost, unit = min((_fit_cost(planes, groups, u), u) for u in options)
        spans = [(float(p.bounds[1][a] - p.bounds[0][a]) / unit) for p in parts for a in range(3)]
        if passing and unit < 0.9 * passing[0][0]:
            break
        if max(spans) > MAX_SPAN:
            continue
        tried.append((cost, unit))
        if cost > MAX_FIT_RMS:
            continue
        _, phase, _ = _grid(parts, planes, unit)
        spread = max(
            max(ph[a] for ph in phase.values()) - min(ph[a] for ph in phase.values())
            for a in range(3)
        )
        if common and spread > MAX_SPREAD:
            off_grid = off_grid or (spread, unit)
            continue
        passing.append((unit, cost))
    if passing:
        # the largest unit that fits, or a unit within 10 % of it that fits better (the same
        # cells, a rounder figure)
        unit, cost = min(passing, key=lambda uc: (uc[1], -uc[0]))
        origin, phase, worst = _grid(parts, planes, unit)
        return LatticeFit(unit, origin, cost, worst, phase)
    if off_grid is not None:
        raise ModelImportError(
            source,
            "lattice",
            f"the parts do not share one grid: at unit {off_grid[1]:.5g} two parts sit "
            f"{off_grid[0]:.2f} units apart (at most {MAX_SPREAD} is clearance), "
            "and no finer unit fits",
        )
    near = min(tried) if tried else (math.inf, math.nan)
    raise ModelImportError(
        source,
        "lattice",
        "no cubic lattice fits the axis-aligned faces: the best unit tried "
        f"({near[1]:.5g}) leaves an RMS deviation of {near[0]:.2f} units "
        f"(at most {MAX_FIT_RMS} fits)",
    )


# ---------------------------------------------------------------------------------------------
# Inside test and voxelising
# ---------------------------------------------------------------------------------------------


@numba.njit(cache=True, parallel=True)
def _winding_kernel(points: F64, tri: F64, out: F64) -> None:
    """Generalised winding number (Jacobson et al. 2013): the solid angles of all triangles
    seen from each point over 4 pi; about 1 inside a closed surface, 0 outside. Points run in
    parallel; each point's sum is in triangle order, so results do not depend on threads."""
    for i in numba.prange(points.shape[0]):
        px, py, pz = points[i, 0], points[i, 1], points[i, 2]
        total = 0.0
        for t in range(tri.shape[0]):
            ax, ay, az = tri[t, 0, 0] - px, tri[t, 0, 1] - py, tri[t, 0, 2] - pz
            bx, by, bz = tri[t, 1, 0] - px, tri[t, 1, 1] - py, tri[t, 1, 2] - pz
            cx, cy, cz = tri[t, 2, 0] - px, tri[t, 2, 1] - py, tri[t, 2, 2] - pz
            la = math.sqrt(ax * ax + ay * ay + az * az)
            lb = math.sqrt(bx * bx + by * by + bz * bz)
            lc = math.sqrt(cx * cx + cy * cy + cz * cz)
            det = ax * (by * cz - bz * cy) - ay * (bx * cz - bz * cx) + az * (bx * cy - by * cx)
            dot = la * lb * lc + (ax * bx + ay * by + az * bz) * lc
            dot += (bx * cx + by * cy + bz * cz) * la + (cx * ax + cy * ay + cz * az) * lb
            total += 2.0 * math.atan2(det, dot)
        out[i] = total / (4.0 * math.pi)


def winding_numbers(part: PartMesh, points: F64) -> F64:
    """The winding number of ``part``'s surface at each point (deterministic, no acceleration
    structure: parts here have at most tens of thousands of triangles)."""
    out = np.zeros(len(points), dtype=np.float64)
    if len(points):
        _winding_kernel(np.ascontiguousarray(points, dtype=np.float64), part.triangles, out)
    return out


@dataclass(frozen=True)
class AxisMap:
    """Lattice coordinate -> world coordinate along one axis for one part: piecewise linear
    through the part's planes (index, position), slope ``unit`` outside them."""

    indices: F64
    positions: F64
    unit: float
    base: float  # world position of index 0 when there is no plane

    def __call__(self, t: F64) -> F64:
        if len(self.indices) == 0:
            return np.asarray(self.base + t * self.unit, dtype=np.float64)
        k0, k1 = self.indices[0], self.indices[-1]
        p0, p1 = self.positions[0], self.positions[-1]
        inner = np.interp(t, self.indices, self.positions)
        out = np.where(t < k0, p0 + (t - k0) * self.unit, inner)
        return np.asarray(np.where(t > k1, p1 + (t - k1) * self.unit, out), dtype=np.float64)


def axis_map(pos: F64, w: F64, unit: float, start: float) -> AxisMap:
    """Snap each plane to the nearest index of the grid starting at ``start`` (world position of
    index 0) and anchor that index at the planes' weighted mean position."""
    if len(pos) == 0:
        return AxisMap(np.zeros(0), np.zeros(0), unit, start)
    k = np.round((pos - start) / unit)
    keys = np.unique(k)
    anchors = np.array([np.average(pos[k == key], weights=w[k == key]) for key in keys])
    return AxisMap(keys.astype(np.float64), anchors, unit, start)


@dataclass(frozen=True)
class PartVoxels:
    """A part's cells in global lattice indices, and the cells no sample count could decide."""

    name: str
    cells: Shape
    ambiguous: tuple[tuple[Cell, float], ...]  # (cell, share of inside samples)


def voxelize(
    part: PartMesh, planes: Planes, fit: LatticeFit, source: str = "<model>"
) -> PartVoxels:
    """Decide every cell the part's bounding box touches by 27 sub-samples, in two stages:
    the centre and the eight corner samples everywhere, the other 18 where those disagree
    (uniform cells, most of them, are taken to agree; this cuts the cost about threefold).
    The work (samples times triangles) is bounded by :data:`limits.MAX_WINDING_PAIRS` before
    any is done; ``source`` names the model in that error."""
    maps = []
    ranges = []
    lo, hi = part.bounds
    for a in range(3):
        start = fit.origin[a] + fit.phase[part.name][a] * fit.unit
        pos, w = planes.significant(a)
        amap = axis_map(pos, w, fit.unit, start)
        maps.append(amap)
        # cells with a sample (offsets 0.25..0.75) within the bounding box, and a little more
        low = math.ceil((lo[a] - start) / fit.unit - 0.8)
        high = math.floor((hi[a] - start) / fit.unit - 0.2)
        ranges.append(np.arange(low, high + 1, dtype=np.int64))
    pairs = math.prod(len(r) for r in ranges) * len(SAMPLE_OFFSETS) ** 3 * len(part.faces)
    if pairs > limits.MAX_WINDING_PAIRS:
        raise ModelImportError(
            source,
            f"parts.{part.name}",
            f"{pairs:.2g} sample-triangle pairs to decide its cells; at most "
            f"{limits.MAX_WINDING_PAIRS:.2g} (too many cells or triangles)",
        )
    gx, gy, gz = np.meshgrid(*ranges, indexing="ij")
    cells = np.stack([gx.ravel(), gy.ravel(), gz.ravel()], axis=1)
    offs = np.asarray(SAMPLE_OFFSETS)
    sub = np.stack(np.meshgrid(offs, offs, offs, indexing="ij"), axis=-1).reshape(-1, 3)
    # first the centre and the eight corner samples; the other 18 only where those disagree
    first = np.array([i for i, o in enumerate(sub) if (o != 0.5).all() or (o == 0.5).all()])
    rest = np.array([i for i in range(len(sub)) if i not in set(first.tolist())])

    def inside(cell_idx: IntArray, sample_idx: IntArray) -> npt.NDArray[np.bool_]:
        t = cells[cell_idx][:, None, :].astype(np.float64) + sub[sample_idx][None, :, :]
        world = np.stack([maps[a](t[..., a]) for a in range(3)], axis=-1).reshape(-1, 3)
        w = winding_numbers(part, world).reshape(len(cell_idx), len(sample_idx))
        return np.asarray(np.abs(w) > 0.5)

    hits = np.zeros((len(cells), len(sub)), dtype=bool)
    everyone = np.arange(len(cells))
    hits[:, first] = inside(everyone, first)
    mixed = np.flatnonzero(hits[:, first].any(axis=1) & ~hits[:, first].all(axis=1))
    uniform = np.setdiff1d(everyone, mixed)
    hits[np.ix_(uniform, rest)] = hits[uniform][:, first[:1]]  # agree with the first nine
    if len(mixed):
        hits[np.ix_(mixed, rest)] = inside(mixed, rest)
    share = hits.mean(axis=1)
    full = share > FULL_ABOVE
    unsure = (share >= EMPTY_BELOW) & (share <= FULL_ABOVE)
    amb = tuple(
        ((int(c[0]), int(c[1]), int(c[2])), round(float(s), 3))
        for c, s in zip(cells[unsure], share[unsure], strict=True)
    )
    return PartVoxels(part.name, Shape(cells[full]), amb)


# ---------------------------------------------------------------------------------------------
# Containers (stacking models)
# ---------------------------------------------------------------------------------------------


def _apart(a: PartMesh, b: PartMesh) -> bool:
    (alo, ahi), (blo, bhi) = a.bounds, b.bounds
    return bool(np.any(ahi <= blo) or np.any(bhi <= alo))


def _is_open_box(part: PartMesh) -> bool:
    """Empty at the centre of its bounding box, material beside it on four sides and below it
    (a 5 x 5 fan of rays per side: walls may have windows), none above it."""
    lo, hi = part.bounds
    centre = (lo + hi) / 2
    if winding_numbers(part, centre[None])[0] > 0.5:
        return False
    grid = np.linspace(0.1, 0.9, 5)
    steps = np.linspace(0, 1, 33)[1:]  # a step of 1/32 of the half-size: thin walls are hit
    for axis, sign in ((0, 1), (0, -1), (1, 1), (1, -1), (2, -1), (2, 1)):
        u, v = (a for a in range(3) if a != axis)
        far = hi[axis] if sign > 0 else lo[axis]
        pts = np.zeros((len(grid), len(grid), len(steps), 3))
        pts[..., u] = (lo[u] + grid * (hi[u] - lo[u]))[:, None, None]
        pts[..., v] = (lo[v] + grid * (hi[v] - lo[v]))[None, :, None]
        pts[..., axis] = centre[axis] + steps * (far - centre[axis])
        hit = bool((winding_numbers(part, pts.reshape(-1, 3)) > 0.5).any())
        if hit != ((axis, sign) != (2, 1)):  # material on every side but the top
            return False
    return True


def find_container(parts: Sequence[PartMesh]) -> int | None:
    """The index of the part that is an open-top box standing apart from every other part,
    with room in its bounding box for all of them (a stacking model's container), or None."""
    for i, part in enumerate(parts):
        others = [p for j, p in enumerate(parts) if j != i]
        lo, hi = part.bounds
        room = float(np.prod(hi - lo)) - part.volume
        if (
            others
            and all(_apart(part, p) for p in others)
            and room >= sum(p.volume for p in others)
            and _is_open_box(part)
        ):
            return i
    return None


def container_cavity(
    part: PartMesh, planes: Planes, unit: float, source: str
) -> tuple[tuple[int, int, int], float]:
    """The container's inner box in cells: from the centre, the nearest wall plane on each side
    (the floor below; the rim on top), and how far its size is from whole cells."""
    lo, hi = part.bounds
    centre = (lo + hi) / 2
    dims: list[int] = []
    worst = 0.0
    for axis in range(3):
        pos, _ = planes.significant(axis)
        below = pos[pos < centre[axis]]
        above = pos[pos > centre[axis]] if axis < 2 else np.array([hi[axis]])
        if not len(below) or not len(above):
            raise ModelImportError(source, f"parts.{part.name}", "container has no inner walls")
        size = (float(above.min()) - float(below.max())) / unit
        dims.append(round(size))
        worst = max(worst, abs(size - round(size)))
    if worst > 0.25 or min(dims) < 1:
        raise ModelImportError(
            source,
            f"parts.{part.name}",
            f"the cavity is not a whole number of cells ({worst=:.2f})",
        )
    return (dims[0], dims[1], dims[2]), worst
