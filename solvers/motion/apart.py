"""Groups of a part's pieces that lie apart, and why one stuck group settles the whole part.

Under a cap on the pieces a move carries (``max_group``), pieces that lie apart stay in one part:
nothing larger than the cap may leave, so the part's configurations multiply over the groups,
and an interlocked pair can walk off by alternating single moves (no end of states: the search
can only stop at its cap). Yet a part comes apart only if each group of it does alone. Dropping
pieces never forbids a translation: any disassembly of the part, restricted to a subset of its
pieces (every move carries the subset's pieces of its group by the same vector), is a
disassembly of the subset alone, a removal stays a removal and no move carries more pieces.
So a group proven stuck alone proves the part stuck, exactly (translations only: a turn's
centre must lie in its group's box, which a smaller group may not contain).
"""

from __future__ import annotations

import numpy as np

from chaingeo.core.arrays import I64


def apart_groups(lo: I64, hi: I64, members: tuple[int, ...], offsets: I64) -> list[list[int]]:
    """The part's pieces (positions in ``members``) in groups whose boxes, grown by one cell,
    meet no other group's (pieces of different groups cannot touch), smallest first; one
    group when nothing lies apart. ``lo``/``hi``: every piece's box at its start (table rows),
    ``offsets``: the part's pieces' offsets."""
    idx = np.asarray(members, dtype=np.int64)
    off = np.asarray(offsets, dtype=np.int64).reshape(len(members), 3)
    a_lo, a_hi = lo[idx] + off, hi[idx] + off
    near = np.all(
        (a_lo[:, None, :] <= a_hi[None, :, :] + 1) & (a_lo[None, :, :] <= a_hi[:, None, :] + 1),
        axis=2,
    )
    group = np.full(len(members), -1, dtype=np.int64)
    groups: list[list[int]] = []
    for seed in range(len(members)):
        if group[seed] >= 0:
            continue
        group[seed] = len(groups)
        todo, found = [seed], [seed]
        while todo:
            p = todo.pop()
            for q in np.flatnonzero(near[p] & (group < 0)).tolist():
                group[q] = len(groups)
                todo.append(q)
                found.append(q)
        groups.append(sorted(found))
    return sorted(groups, key=lambda g: (len(g), g))
