"""Names a package exports but imports on first use (PEP 562), so that importing the package
stays cheap: ``import chaingeo`` loads neither numpy nor numba.

A package lists ``{public name: "module:attribute"}`` and binds what :func:`lazy_exports`
returns to its ``__getattr__`` and ``__dir__`` outside ``TYPE_CHECKING`` (its real imports sit
inside, for mypy and editors; ``tests/conformance/test_api.py`` checks that both agree).
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable, Mapping
from typing import Any

__all__ = ["lazy_exports"]


def lazy_exports(
    package: str, table: Mapping[str, str]
) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """``__getattr__`` and ``__dir__`` for ``package``: a name of ``table`` is imported from its
    module and kept in the package (the next look-up is a plain attribute); any other name is an
    ``AttributeError``."""

    def __getattr__(name: str) -> Any:
        target = table.get(name)
        if target is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        module, _, attr = target.partition(":")
        value = getattr(importlib.import_module(module), attr)
        setattr(sys.modules[package], name, value)
        return value

    def __dir__() -> list[str]:
        return sorted({*vars(sys.modules[package]), *table})

    return __getattr__, __dir__
