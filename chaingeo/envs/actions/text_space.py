"""The ``Text`` space of text observations, made to work in ``AsyncVectorEnv``'s shared memory.

Gymnasium 1.4 stores a ``Text`` observation in shared memory (one ``int32`` character index per
position, padded with ``len(charset)``) but reads it back only once, when the vector
environment is built: every later step returns the text of that first read (for an unwritten
buffer, a string of tabs). :class:`ObservationText` is a plain ``Text`` space for everything
else (sampling, ``contains``, the checker, equality); for it the shared-memory functions are
registered here (Gymnasium's own extension point, ``singledispatch``) with the same layout,
written and read with numpy lookup tables instead of a Python loop over up to
:data:`~chaingeo.core.limits.MAX_OBSERVATION_CHARS` characters, and read when asked:
``AsyncVectorEnv`` deep-copies its observations on return (``copy=True``, the default), which
decodes the buffer as it is then; with ``copy=False`` each item decodes on access.
"""

from __future__ import annotations

import multiprocessing as mp
from collections.abc import Sequence
from types import ModuleType
from typing import Any, overload

import numpy as np
import numpy.typing as npt
from gymnasium.spaces import Text
from gymnasium.vector.utils import (
    create_shared_memory,
    read_from_shared_memory,
    write_to_shared_memory,
)


class ObservationText(Text):
    """A ``Text`` space of ASCII characters whose batches survive ``AsyncVectorEnv``."""

    def __init__(self, max_length: int, charset: frozenset[str]) -> None:
        super().__init__(max_length, min_length=0, charset=charset)
        if any(ord(c) > 127 for c in self.character_list):
            raise ValueError("ObservationText holds ASCII characters only")
        pad = len(self.character_list)
        self.encode_table = np.full(128, -1, dtype=np.int32)
        for i, c in enumerate(self.character_list):
            self.encode_table[ord(c)] = i
        self.decode_table = np.array([ord(c) for c in self.character_list] + [0], dtype=np.uint8)
        self.pad = pad

    def encode(self, text: str) -> npt.NDArray[np.int32]:
        """``text`` as character indices, padded to ``max_length`` (Gymnasium's ``flatten``)."""
        if len(text) > self.max_length:
            raise ValueError(f"text of {len(text)} characters; the space holds {self.max_length}")
        codes = np.frombuffer(text.encode("ascii"), dtype=np.uint8)
        out = np.full(self.max_length, self.pad, dtype=np.int32)
        out[: len(codes)] = self.encode_table[codes]
        if (out[: len(codes)] < 0).any():
            raise ValueError("text outside the space's characters")
        return out

    def decode(self, indices: npt.NDArray[np.int32]) -> str:
        """The text of one row of character indices (padding dropped)."""
        valid = indices[indices < self.pad]
        return self.decode_table[valid].tobytes().decode("ascii")


class SharedTexts(Sequence[str]):
    """The texts of a batch, decoded from shared memory when read (see the module docstring)."""

    def __init__(self, space: ObservationText, buffer: npt.NDArray[np.int32], n: int) -> None:
        self._space = space
        self._rows = buffer.reshape((n, space.max_length))

    def __len__(self) -> int:
        return len(self._rows)

    @overload
    def __getitem__(self, i: int) -> str: ...
    @overload
    def __getitem__(self, i: slice) -> tuple[str, ...]: ...
    def __getitem__(self, i: int | slice) -> str | tuple[str, ...]:
        if isinstance(i, slice):
            return tuple(self._space.decode(row) for row in self._rows[i])
        return self._space.decode(self._rows[i])

    def __deepcopy__(self, memo: dict[int, Any]) -> tuple[str, ...]:
        return tuple(self)


def _buffer(shared: Any) -> npt.NDArray[np.int32]:
    return np.frombuffer(shared.get_obj(), dtype=np.int32)


@create_shared_memory.register(ObservationText)
def _create(space: ObservationText, n: int = 1, ctx: ModuleType = mp) -> Any:
    shared = ctx.Array(np.dtype(np.int32).char, n * space.max_length)
    _buffer(shared)[:] = space.pad  # a row never written reads as "", not as tabs
    return shared


@read_from_shared_memory.register(ObservationText)
def _read(space: ObservationText, shared: Any, n: int = 1) -> SharedTexts:
    return SharedTexts(space, _buffer(shared), n)


@write_to_shared_memory.register(ObservationText)
def _write(space: ObservationText, index: int, value: str, shared: Any) -> None:
    size = space.max_length
    _buffer(shared)[index * size : (index + 1) * size] = space.encode(value)
