"""Named things (agents, judges, generator shapes and configs, benchmarks) in one kind of table.

Why: a plug-in registered under a name already taken used to replace the built-in silently; a
:class:`Registry` refuses it with a typed error naming the name, and an unknown name gets one
error listing the known ones, worded the same everywhere.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import Generic, TypeVar, overload

from chaingeo.core.errors import ChainGeoError

T = TypeVar("T")


class _Unset:
    """No item given to :meth:`Registry.register` (None may be an item)."""


_UNSET = _Unset()


class RegistryError(ChainGeoError, ValueError):
    """A name refused or not found; a ``ValueError`` as the old dictionary lookups raised."""

    def __init__(self, message: str, kind: str, name: str) -> None:
        super().__init__(message)
        self.kind = kind
        self.name = name


class DuplicateNameError(RegistryError):
    """A second item registered under a name already taken."""


class UnknownNameError(RegistryError):
    """A name nothing is registered under; the message lists the known names."""


class Registry(Generic[T]):
    """Name -> item, in registration order. ``kind`` names the items in messages ("agent");
    ``missing`` words an unknown name (``{kind}``, ``{name!r}`` are filled in)."""

    def __init__(self, kind: str, *, missing: str = "unknown {kind} {name!r}") -> None:
        self.kind = kind
        self._missing = missing
        self._items: dict[str, T] = {}

    @overload
    def register(self, name: str) -> Callable[[T], T]: ...
    @overload
    def register(self, name: str, item: T) -> T: ...
    def register(self, name: str, item: T | _Unset = _UNSET) -> T | Callable[[T], T]:
        """Add ``item`` under ``name`` (returned), or, given no item, a decorator that does."""
        if isinstance(item, _Unset):
            return lambda it: self._add(name, it)
        return self._add(name, item)

    def _add(self, name: str, item: T) -> T:
        if name in self._items:
            message = f"{self.kind} {name!r} is already registered"
            raise DuplicateNameError(message, self.kind, name)
        self._items[name] = item
        return item

    def unregister(self, name: str) -> T:
        """Remove ``name`` (a plug-in's or a test's own entry), returning its item."""
        item = self.get(name)
        del self._items[name]
        return item

    @contextmanager
    def registered(self, name: str, item: T) -> Iterator[T]:
        """``item`` under ``name`` for the ``with`` block only."""
        self.register(name, item)
        try:
            yield item
        finally:
            del self._items[name]

    def get(self, name: str) -> T:
        """The item named ``name``; an :class:`UnknownNameError` listing the known names if none."""
        try:
            return self._items[name]
        except KeyError:
            said = self._missing.format(kind=self.kind, name=name)
            known = ", ".join(sorted(self._items)) or "none"
            raise UnknownNameError(f"{said}; known: {known}", self.kind, name) from None

    def names(self) -> tuple[str, ...]:
        """Every name, in registration order."""
        return tuple(self._items)

    def items(self) -> tuple[tuple[str, T], ...]:
        """Every (name, item), in registration order."""
        return tuple(self._items.items())

    def __iter__(self) -> Iterator[str]:
        return iter(self.names())

    def __len__(self) -> int:
        return len(self._items)

    def __contains__(self, name: object) -> bool:
        return name in self._items

    def __repr__(self) -> str:
        return f"Registry({self.kind!r}, {list(self._items)!r})"
