"""Quarter turns: the centre convention, the turn move, and the exact sweep test.

**Centre convention.** A piece is a set of unit cubes; voxel ``(i, j, k)`` is the cube
``[i, i+1] x [j, j+1] x [k, k+1]`` (:mod:`chaingeo.pictures.mesh`). A quarter turn about a line
parallel to z through ``(px, py)`` maps a cube's centre ``(i+1/2, j+1/2)`` to
``(px - (j+1/2-py), py + (i+1/2-px))``, a cube centre again for every ``i, j`` exactly when
``px + py`` and ``px - py`` are whole numbers: ``px, py`` are both whole (the line runs along cube
edges, through the lattice points that are the cubes' corners) or both whole plus a half (the
line runs through cube centres). Any other line (say through the midpoint of an edge) takes
cubes off the lattice. Both kinds keep cells on cells, and they are different motions (a square
rod turns in place about its own centre; about one of its edges it swings to the next cell),
so both are moves.

Centres are written in *cell units*: position ``p`` is the centre of cell ``p`` (0-based in code,
1-based in agent text, :mod:`chaingeo.envs.actions.types`), so the two coordinates across the axis
are both whole numbers (the axis through cell centres) or both halves (the axis through cell
corners). Code keeps them exact as ``centre2``, twice the position: both even or both odd. The
coordinate along the axis does not matter (the axis is a line) and is stored as 0.

**The sweep test.** A turn of a group is legal when, turning continuously through the 90
degrees, it never overlaps another piece (touching is allowed). Cubes turning about a line
parallel to an axis stay in their slice across it, so the test is planar and pairwise: the
*swept region* of one moving unit square against one fixed unit square of the same slice.
:func:`square_hit` decides that exactly (rational arithmetic and square roots compared by
squaring); :func:`swept_cells` lists every cell a moving cell sweeps. See :func:`square_hit`
for the argument.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from functools import lru_cache
from typing import Any, Final

import numpy as np

from chaingeo.core.geometry import QUARTER_TURNS, Cell, IntArray, rotation_index

AXES: Final[tuple[str, ...]] = ("x", "y", "z")
ANGLES: Final[dict[int, str]] = {1: "+90", -1: "-90"}


def lateral(axis: int) -> tuple[int, int]:
    """The two axes across ``axis``, ordered so that a +90 degree turn takes the first to the
    second (right hand: x -> y about z, y -> z about x, z -> x about y)."""
    return (axis + 1) % 3, (axis + 2) % 3


def quarter_matrix(axis: int, quarter: int) -> IntArray:
    """The rotation of a +90 (``quarter`` 1) or -90 (-1) degree turn about axis ``axis``."""
    m = QUARTER_TURNS[AXES[axis]]
    return m if quarter == 1 else np.ascontiguousarray(m.T)


def quarter_index(axis: int, quarter: int) -> int:
    """Index into :data:`chaingeo.core.geometry.ROTATIONS` of that turn."""
    return rotation_index(quarter_matrix(axis, quarter))


def half_text(v2: int) -> str:
    """A doubled coordinate as a number: 7 -> ``3.5``, 6 -> ``3``."""
    return str(v2 // 2) if v2 % 2 == 0 else f"{v2 // 2}.5" if v2 > 0 else f"-{(-v2) // 2}.5"


def centre_problem(axis: int, centre2: Sequence[int]) -> str | None:
    """Why ``centre2`` (doubled cell units) is no turn centre about ``axis``, or None."""
    u, v = lateral(axis)
    if (centre2[u] - centre2[v]) % 2:
        return (
            f"the axis must pass through cell centres or cell corners: its two coordinates "
            f"across {AXES[axis]} must both be whole or both end in .5, got "
            f"{half_text(centre2[u])} and {half_text(centre2[v])}"
        )
    return None


@dataclass(frozen=True, order=True)
class TurnMove:
    """Turn ``pieces`` together by 90 degrees about a line parallel to ``axis``.

    ``quarter`` is +1 for +90 degrees (right hand about the positive axis) and -1 for -90;
    ``centre2`` is twice a point of the line in cell units (see the module docstring), its
    component along the axis 0. One move, like a translation."""

    pieces: tuple[str, ...]
    axis: str
    quarter: int
    centre2: Cell

    def __post_init__(self) -> None:
        if self.axis not in AXES:
            raise ValueError(f"unknown axis {self.axis!r}; use x, y or z")
        if self.quarter not in (1, -1):
            raise ValueError(f"a turn is +90 or -90 degrees, got quarter {self.quarter!r}")
        if not self.pieces:
            raise ValueError("a turn needs at least one piece")
        if len(set(self.pieces)) != len(self.pieces):
            raise ValueError(f"a piece is named twice in {list(self.pieces)}")
        c = [int(v) for v in self.centre2]
        if len(c) != 3:
            raise ValueError(f"a centre has three coordinates, got {self.centre2!r}")
        a = AXES.index(self.axis)
        c[a] = 0
        why = centre_problem(a, c)
        if why is not None:
            raise ValueError(why)
        object.__setattr__(self, "pieces", tuple(sorted(self.pieces)))
        object.__setattr__(self, "centre2", (c[0], c[1], c[2]))

    @classmethod
    def listed(cls, pieces: tuple[str, ...], axis: str, quarter: int, centre2: Cell) -> TurnMove:
        """A turn a kernel listed (pieces sorted and distinct, a valid centre with its axis
        component 0), built without checking again: a state lists thousands."""
        move = object.__new__(cls)
        move.__dict__.update(pieces=pieces, axis=axis, quarter=quarter, centre2=centre2)
        return move

    @property
    def axis_index(self) -> int:
        return AXES.index(self.axis)

    @property
    def distance(self) -> int:
        """Turns never take a group out of its part (for code written for translations)."""
        return 1

    def centre_text(self) -> str:
        """The centre in code coordinates (0-based cell units), e.g. ``(3.5,0,4.5)``."""
        return "(" + ",".join(half_text(v) for v in self.centre2) + ")"

    def describe(self) -> str:
        return (
            f"rotate {'+'.join(self.pieces)} {self.axis} {ANGLES[self.quarter]} "
            f"about {self.centre_text()}"
        )

    def to_json(self) -> dict[str, object]:
        about: list[object] = [v // 2 if v % 2 == 0 else v / 2 for v in self.centre2]
        return {
            "pieces": list(self.pieces),
            "axis": self.axis,
            "angle": 90 * self.quarter,
            "about": about,
        }

    def inverse(self) -> TurnMove:
        """The same group turning back about the same line (the same swept region)."""
        return TurnMove(self.pieces, self.axis, -self.quarter, self.centre2)

    def matrix(self) -> IntArray:
        return quarter_matrix(self.axis_index, self.quarter)


def turn_from_json(obj: Mapping[str, Any]) -> TurnMove:
    """The inverse of :meth:`TurnMove.to_json` (pieces checked by the caller); ValueError
    naming the field otherwise."""
    pieces = obj.get("pieces")
    if not isinstance(pieces, list) or not all(isinstance(n, str) for n in pieces):
        raise ValueError("pieces: expected a list of piece names")
    axis = obj.get("axis")
    if axis not in AXES:
        raise ValueError(f"axis: expected 'x', 'y' or 'z', got {axis!r}")
    angle = obj.get("angle")
    if isinstance(angle, bool) or angle not in (90, -90):
        raise ValueError(f"angle: expected 90 or -90, got {angle!r}")
    about = obj.get("about")
    if not isinstance(about, list) or len(about) != 3:
        raise ValueError("about: expected three numbers (whole or ending in .5)")
    centre2: list[int] = []
    for v in about:
        if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
            raise ValueError(f"about: expected numbers, got {v!r}")
        if abs(v) > 1e6 or 2 * v != int(2 * v):
            raise ValueError(f"about: {v!r} is not a whole number or a half")
        centre2.append(int(2 * v))
    return TurnMove(
        tuple(pieces), axis, 1 if angle == 90 else -1, (centre2[0], centre2[1], centre2[2])
    )


def turn_cells(
    cells: Iterable[Cell], axis: int, quarter: int, centre2: Sequence[int]
) -> list[Cell]:
    """Where the cells go: ``v -> Q (v - c) + c`` in cell units (exact, via doubled units)."""
    q = quarter_matrix(axis, quarter)
    c = np.asarray(centre2, dtype=np.int64)
    out: list[Cell] = []
    for cell in cells:
        w = (q @ (2 * np.asarray(cell, dtype=np.int64) - c) + c) // 2
        out.append((int(w[0]), int(w[1]), int(w[2])))
    return out


def turn_pose(rotation: IntArray, offset: Cell, move: TurnMove) -> tuple[IntArray, Cell]:
    """A piece at pose ``(rotation, offset)`` (cells ``R v + offset``) after ``move``."""
    q = move.matrix()
    c = np.asarray(move.centre2, dtype=np.int64)
    o = (q @ (2 * np.asarray(offset, dtype=np.int64) - c) + c) // 2
    return q @ rotation, (int(o[0]), int(o[1]), int(o[2]))


# ---------------------------------------------------------------------------------------------
# The exact planar test
# ---------------------------------------------------------------------------------------------
#
# Coordinates are *doubled* and relative to the axis O: a cell whose centre lies at (cu, cv)
# relative to O (cell units) has s = (2 cu, 2 cv), integers both even (axis through cell
# centres) or both odd (axis through corners), and is the square [s - 1, s + 1]^2.
#
# Inside the test, coordinates are doubled once more (quadrupled: square ``s`` is
# [2s - 2, 2s + 2]^2), so that every test radius below is an integer and all exact arithmetic
# is on Python integers. A number of the form c * sqrt(e) (integers, e >= 0) is a Term; a
# point is two Terms.

Term = tuple[int, int]
Point = tuple[Term, Term]
#: Float comparisons closer than this are redone exactly.
_MARGIN: Final = 1e-7
_TAU: Final = 2 * math.pi


def _sign(t: Term) -> int:
    c, e = t
    if c == 0 or e == 0:
        return 0
    return 1 if c > 0 else -1


def _sign_sum(a: Term, b: Term) -> int:
    """Sign of ``a + b`` for two Terms, exactly (compare squares when the signs differ)."""
    sa, sb = _sign(a), _sign(b)
    if sa == 0 or sa == sb:
        return sb if sa == 0 else sa
    if sb == 0:
        return sa
    ma, mb = a[0] * a[0] * a[1], b[0] * b[0] * b[1]
    return sa if ma > mb else sb if mb > ma else 0


def _mul(a: Term, b: Term) -> Term:
    return (a[0] * b[0], a[1] * b[1])


def _neg(a: Term) -> Term:
    return (-a[0], a[1])


def _cross(p: Point, q: Point) -> int:
    return _sign_sum(_mul(p[0], q[1]), _neg(_mul(p[1], q[0])))


def _dot(p: Point, q: Point) -> int:
    return _sign_sum(_mul(p[0], q[0]), _mul(p[1], q[1]))


def _compare(base: Point, p: Point, q: Point) -> int:
    """Order of the directions of ``p`` and ``q`` by counter-clockwise angle from ``base``,
    in [0, 360): -1, 0 or 1."""

    def half(w: Point) -> int:
        c = _cross(base, w)
        return 0 if c > 0 or (c == 0 and _dot(base, w) > 0) else 1

    hp, hq = half(p), half(q)
    if hp != hq:
        return -1 if hp < hq else 1
    return -_cross(p, q)


def _rmin2(s: Sequence[int]) -> int:
    dx = 0 if s[0] - 1 <= 0 <= s[0] + 1 else min(abs(s[0] - 1), abs(s[0] + 1))
    dy = 0 if s[1] - 1 <= 0 <= s[1] + 1 else min(abs(s[1] - 1), abs(s[1] + 1))
    return dx * dx + dy * dy


def _rmax2(s: Sequence[int]) -> int:
    return (abs(s[0]) + 1) ** 2 + (abs(s[1]) + 1) ** 2


def _critical(s: Sequence[int]) -> list[int]:
    """Squared radii where the circle meets a corner of the square or touches an edge line."""
    out = [(s[0] + dx) ** 2 + (s[1] + dy) ** 2 for dx in (-1, 1) for dy in (-1, 1)]
    if s[1] - 1 <= 0 <= s[1] + 1:  # the feet of O on the lines x = s0 -+ 1 lie on the edges
        out += [(s[0] - 1) ** 2, (s[0] + 1) ** 2]
    if s[0] - 1 <= 0 <= s[0] + 1:
        out += [(s[1] - 1) ** 2, (s[1] + 1) ** 2]
    return out


def edge_roots(m: int, k: int, lo: int, hi: int) -> int:
    """Where the circle of squared radius ``m`` about O crosses the line ``k`` (the other
    coordinate ``+-sqrt(h)``, ``h = m - k^2``) within ``[lo, hi]``: bit 0 set when ``+sqrt(h)``
    lies there, bit 1 when ``-sqrt(h)`` does. Integers only, so the sweep kernel
    (:mod:`chaingeo.solvers.motion.turns_sweep_kernel`) compiles this very function."""
    h = m - k * k
    if h < 0:
        return 0
    plus = (lo <= 0 or h >= lo * lo) and (hi >= 0 and h <= hi * hi)
    minus = (lo <= 0 and h <= lo * lo) and (hi >= 0 or h >= hi * hi)
    return (1 if plus else 0) | (2 if minus else 0)


def _on_circle(s: Sequence[int], m: int) -> list[Point]:
    """Points where the circle of squared radius ``m`` about O crosses the edges of square
    ``s`` (quadrupled units: the square is [2s - 2, 2s + 2]^2)."""
    pts: list[Point] = []
    for i in (0, 1):  # edges x = k (i = 0) and y = k (i = 1)
        lo, hi = 2 * s[1 - i] - 2, 2 * s[1 - i] + 2
        for k in (2 * s[i] - 2, 2 * s[i] + 2):
            roots, h = edge_roots(m, k, lo, hi), m - k * k
            for sign in [sg for sg, bit in ((1, 1), (-1, 2)) if roots & bit]:
                pts.append(((k, 1), (sign, h)) if i == 0 else ((sign, h), (k, 1)))
    return pts


def _extremes(pts: list[Point]) -> tuple[Point, Point]:
    """The clockwise-most and counter-clockwise-most points (they span at most 90 degrees)."""
    first = next(p for p in pts if all(_cross(p, q) >= 0 for q in pts))
    last = next(p for p in pts if all(_cross(q, p) >= 0 for q in pts))
    return first, last


def _value(t: Term) -> float:
    return t[0] * math.sqrt(t[1])


def _angle(p: Point) -> float:
    return math.atan2(_value(p[1]), _value(p[0]))


def _float_overlap(s: Sequence[int], f: Sequence[int], m: int) -> bool | None:
    """:func:`_arcs_overlap` in floating point, or None when some comparison is too close."""
    ang_s = [_angle(p) for p in _on_circle(s, m)]
    ang_f = [_angle(p) for p in _on_circle(f, m)]
    base = ang_s[0]
    rel_s = [(a - base) % _TAU for a in ang_s]
    # s spans at most 90 degrees: its points lie within 90 degrees on either side of ``base``
    rel_s = [r - _TAU if r > math.pi else r for r in rel_s]
    start, end = min(rel_s), max(rel_s) + math.pi / 2
    end -= start
    rel_f = [(a - base - start) % _TAU for a in ang_f]
    # f spans at most 90 degrees: its arc starts after the largest gap between its directions
    rel_f.sort()
    gaps = [(rel_f[(i + 1) % len(rel_f)] - rel_f[i]) % _TAU for i in range(len(rel_f))]
    i = max(range(len(rel_f)), key=lambda j: gaps[j])
    a_f, b_f = rel_f[(i + 1) % len(rel_f)], rel_f[i]
    for x in (a_f, b_f):
        if abs(x - end) < _MARGIN or min(x, _TAU - x) < _MARGIN:
            return None
    if a_f < end:
        return True
    return b_f < a_f  # wraps round past the start


def _arcs_overlap(s: Sequence[int], f: Sequence[int], m: int) -> bool:
    """At squared radius ``m`` (quadrupled units; not critical, inside both squares' radius
    ranges): does the arc swept by ``s`` (counter-clockwise, 90 degrees) overlap ``f``'s?"""
    quick = _float_overlap(s, f, m)
    if quick is not None:
        return quick
    a_s, b_s = _extremes(_on_circle(s, m))
    a_f, b_f = _extremes(_on_circle(f, m))
    end: Point = (_neg(b_s[1]), b_s[0])  # b_s turned by +90 degrees
    if _compare(a_s, a_f, end) < 0:  # f's arc starts inside the swept arc
        return True
    # otherwise only if f's arc wraps round past the swept arc's start
    return _compare(a_s, b_f, a_f) < 0 and _compare(a_s, a_s, b_f) < 0


def square_hit(s: tuple[int, int], f: tuple[int, int]) -> bool:
    """Does the unit square ``s``, turning counter-clockwise by 90 degrees about O, ever overlap
    the fixed unit square ``f`` (interiors; touching does not count)? Doubled coordinates
    relative to O, as above; ``s`` and ``f`` of the same parity class.

    Argument. (1) If O is inside ``s`` (``s = (0, 0)``) the square, symmetric under quarter
    turns, sweeps the open disc of radius sqrt(2) (doubled units): ``f`` is hit iff its nearest
    point is closer than that. If O is inside ``f``, the relative motion is ``f`` turning back
    about its own centre: the same test on ``s``. (2) Otherwise O is outside both squares'
    interiors, where a unit square of this lattice subtends at most 90 degrees. The points of
    the closed square at radius r have angles in [a(r), b(r)] (with at most one gap, narrower
    than 90 degrees), so the open swept region at radius r is the open arc (a_s(r), b_s(r) + 90)
    -- the turn closes the gap -- and, as that arc spans at least 90 degrees, ``f``'s own gap
    never hides an overlap: ``f`` is hit iff at some radius the open arcs (a_s, b_s + 90) and
    (a_f, b_f) overlap. (3) The extreme points a and b run along the squares' edges, switching
    edges only at corner radii and where the circle touches an edge line; two of those curves
    can meet only at a point common to the boundaries of two lattice squares (``f`` and ``s`` or
    ``f`` and ``s`` turned, itself a lattice square), i.e. at a lattice corner, or along a
    shared edge, where they stay equal. So whether the arcs overlap is constant between
    consecutive *critical* squared radii (corner radii and edge-line distances, integers), and
    one test radius per interval, with the angles compared exactly, decides it."""
    if s == f:
        return True
    if s == (0, 0):
        return _rmin2(f) < 2
    if f == (0, 0):
        return _rmin2(s) < 2
    lo = max(_rmin2(s), _rmin2(f))
    hi = min(_rmax2(s), _rmax2(f))
    if lo >= hi:
        return False
    cuts = sorted({lo, hi, *(c for c in (*_critical(s), *_critical(f)) if lo < c < hi)})
    # test radii between consecutive cuts, in quadrupled units (4 x doubled squares): integers
    return any(_arcs_overlap(s, f, 2 * (a + b)) for a, b in itertools.pairwise(cuts))


def _cone(s: tuple[int, int], ref: tuple[int, int]) -> tuple[float, float]:
    """The directions of square ``s``'s corners, as angles relative to the direction of
    ``ref`` in (-pi, pi]: (smallest, largest)."""
    base = math.atan2(ref[1], ref[0])
    rel = [
        (math.atan2(s[1] + dy, s[0] + dx) - base + math.pi) % _TAU - math.pi
        for dx in (-1, 1)
        for dy in (-1, 1)
    ]
    return min(rel), max(rel)


def _may_meet(swept: tuple[float, float], f: tuple[int, int], s: tuple[int, int]) -> bool:
    """False only when square ``f`` lies outside the swept cone (with a margin): the swept
    region lies in the cone of directions from ``s``'s first to its last corner plus 90
    degrees (angles relative to ``s``'s own direction, see :func:`_swept_ccw`)."""
    lo, hi = _cone(f, s)
    if hi - lo > math.pi:  # f straddles the direction opposite to s: keep it
        return True
    return not (hi < swept[0] - _MARGIN or lo > swept[1] + _MARGIN)


@lru_cache(maxsize=1 << 16)
def _swept_ccw(s: tuple[int, int]) -> tuple[tuple[int, int], ...]:
    """Every square (same parity class) that ``s`` hits turning +90 degrees, sorted."""
    r2 = _rmax2(s)
    rmin2 = _rmin2(s)
    bound = math.isqrt(r2) + 2
    out: list[tuple[int, int]] = []
    par = s[0] % 2
    cone = _cone(s, s)
    cone = (cone[0], cone[1] + math.pi / 2)
    for fx in range(-bound - par, bound + 1):
        if fx % 2 != par:
            continue
        for fy in range(-bound - par, bound + 1):
            if fy % 2 != par:
                continue
            f = (fx, fy)
            if _rmin2(f) >= r2 or _rmax2(f) <= rmin2:
                continue  # no common open range of radii
            if f != (0, 0) and s != (0, 0) and not _may_meet(cone, f, s):
                continue
            if square_hit(s, f):
                out.append(f)
    return tuple(sorted(out))


def _turn2(p: tuple[int, int], k: int) -> tuple[int, int]:
    """``p`` turned by ``k`` quarter turns counter-clockwise."""
    x, y = p
    for _ in range(k % 4):
        x, y = -y, x
    return x, y


@lru_cache(maxsize=1 << 16)
def swept_squares(s: tuple[int, int], quarter: int) -> tuple[tuple[int, int], ...]:
    """The squares hit by square ``s`` turning by ``quarter`` (+1: +90, -1: -90) about O
    (doubled coordinates relative to O), sorted. Quarter-turn symmetry reduces every square to
    one with ``x > 0, y >= 0``; a -90 turn is the mirror image (y -> -y) of a +90 one. Cached:
    a search asks for the same few squares (a piece's cells about nearby centres) again and
    again."""
    if quarter == -1:
        return tuple(sorted((x, -y) for x, y in swept_squares((s[0], -s[1]), 1)))
    if s == (0, 0):
        return _swept_ccw(s)
    k = next(k for k in range(4) if (lambda t: t[0] > 0 and t[1] >= 0)(_turn2(s, -k)))
    return tuple(sorted(_turn2(f, k) for f in _swept_ccw(_turn2(s, -k))))


def swept_by(cells: Iterable[Cell], axis: int, quarter: int, centre2: Sequence[int]) -> set[Cell]:
    """Every cell whose interior the cells sweep through (their own and their final cells
    included) turning by ``quarter`` about the line through ``centre2`` parallel to ``axis``."""
    u, v = lateral(axis)
    out: set[Cell] = set()
    for cell in cells:
        s = (2 * cell[u] - centre2[u], 2 * cell[v] - centre2[v])
        for fu, fv in swept_squares(s, quarter):
            c = [0, 0, 0]
            c[axis] = cell[axis]
            c[u] = (fu + centre2[u]) // 2
            c[v] = (fv + centre2[v]) // 2
            out.add((c[0], c[1], c[2]))
    return out


def spinning_rods(
    rods: Mapping[Cell, int],
    rotation: IntArray,
    offset: Sequence[int],
    axis: int,
    centre2: Sequence[int],
) -> set[Cell]:
    """The cells (where they stand) of a piece's round rods (cell of the piece's own frame ->
    the rod's axis) that lie along ``axis`` on the line through ``centre2``, the piece at pose
    ``(rotation, offset)``: turning about that line they spin in place, sweeping only their own
    cell. (A rod is a cylinder of diameter 1 filling its cell; in every other test it counts as
    a full cube, which never allows a move the rod could not make.)"""
    u, v = lateral(axis)
    out: set[Cell] = set()
    for cell, a in rods.items():
        if rotation[axis, a] == 0:
            continue  # this rod now lies across the axis
        w = rotation @ np.asarray(cell, dtype=np.int64) + np.asarray(offset, dtype=np.int64)
        if 2 * w[u] == centre2[u] and 2 * w[v] == centre2[v]:
            out.add((int(w[0]), int(w[1]), int(w[2])))
    return out


def centres_within(cells: Iterable[Cell], axis: int) -> list[Cell]:
    """Every turn centre (doubled, axis component 0) across ``axis`` inside the cells' bounding
    box (closed: corners on its boundary count), in lexicographic order: the centres a group
    may turn about."""
    u, v = lateral(axis)
    pts = list(cells)
    lo_u, hi_u = 2 * min(c[u] for c in pts) - 1, 2 * max(c[u] for c in pts) + 1
    lo_v, hi_v = 2 * min(c[v] for c in pts) - 1, 2 * max(c[v] for c in pts) + 1
    out: list[Cell] = []
    for a in range(lo_u, hi_u + 1):
        for b in range(lo_v, hi_v + 1):
            if (a - b) % 2 == 0:
                c = [0, 0, 0]
                c[u], c[v] = a, b
                out.append((c[0], c[1], c[2]))
    return sorted(out)


def centre_inside(cells: Iterable[Cell], axis: int, centre2: Sequence[int]) -> bool:
    """Is the centre within the cells' bounding box across ``axis`` (boundary included)?"""
    u, v = lateral(axis)
    pts = list(cells)
    return all(
        2 * min(c[a] for c in pts) - 1 <= centre2[a] <= 2 * max(c[a] for c in pts) + 1
        for a in (u, v)
    )
