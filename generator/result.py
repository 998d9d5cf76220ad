"""What one generation item gives back when it gives no level: the family-neutral rejection.

Every family's ``make(config, seed, index)`` returns a :class:`~chaingeo.core.level.Level` or a
:class:`GenerationRejection`; the batch runner needs nothing else to count outcomes.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Final

#: Key of ``Level.stats`` holding why earlier attempts of the same item failed (reason -> count).
ATTEMPTS_KEY: Final = "rejected_attempts"


@dataclass(frozen=True)
class GenerationRejection:
    """No level for this (config, seed, index): the last reason, and every attempt's reason."""

    reason: str
    seed: int
    index: int
    attempts: Mapping[str, int] = field(default_factory=dict)
