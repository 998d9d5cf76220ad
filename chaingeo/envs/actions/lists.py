"""A read-only list of actions whose members are built only when asked for.

Assembly states can offer hundreds of thousands of insertions; building an action object for
each costs about a second per turn, although an agent looks at a few of them. An
:class:`ActionList` joins sequences (plain lists, or lazy blocks that know their length and
build their ``i``-th member on demand) end to end and behaves like the list it stands for:
``len``, indexing, slicing, iteration, ``in`` and ``==`` with a list.
"""

from __future__ import annotations

from bisect import bisect_right
from collections.abc import Iterator, Sequence
from itertools import accumulate, chain
from typing import overload

from chaingeo.envs.actions.types import Action


class ActionList(Sequence[Action]):
    """The concatenation of ``chunks`` (each a sequence of actions), in order."""

    __slots__ = ("_chunks", "_ends")

    def __init__(self, chunks: Sequence[Sequence[Action]]) -> None:
        self._chunks = tuple(c for c in chunks if len(c))
        self._ends = tuple(accumulate(len(c) for c in self._chunks))

    def __len__(self) -> int:
        return self._ends[-1] if self._ends else 0

    @overload
    def __getitem__(self, index: int) -> Action: ...
    @overload
    def __getitem__(self, index: slice) -> list[Action]: ...
    def __getitem__(self, index: int | slice) -> Action | list[Action]:
        if isinstance(index, slice):
            return [self[i] for i in range(*index.indices(len(self)))]
        n = len(self)
        i = index + n if index < 0 else index
        if not 0 <= i < n:
            raise IndexError(f"action index {index} out of range for {n} actions")
        c = bisect_right(self._ends, i)
        start = self._ends[c - 1] if c else 0
        return self._chunks[c][i - start]

    def __iter__(self) -> Iterator[Action]:
        return chain.from_iterable(self._chunks)

    def __contains__(self, value: object) -> bool:
        return any(value in c for c in self._chunks)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Sequence) or isinstance(other, str):
            return NotImplemented
        return len(self) == len(other) and all(a == b for a, b in zip(self, other, strict=True))

    __hash__ = None  # type: ignore[assignment]  # like a list: compared by value, unhashable

    def __repr__(self) -> str:
        return f"ActionList({len(self)} actions)"
