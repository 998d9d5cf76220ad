"""Typed faces of the verifiers decorators we use (verifiers ships no type information)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, TypeVar, cast

import verifiers.v1 as vf

F = TypeVar("F", bound=Callable[..., Any])


def reward(weight: float) -> Callable[[F], F]:
    """``@vf.reward(weight=...)``: a task method scoring a finished trace, weighted."""
    return cast(Callable[[F], F], vf.reward(weight=weight))


def metric(fn: F) -> F:
    """``@vf.metric``: a task method recorded on the trace, not summed into the reward."""
    return cast(F, vf.metric(fn))
