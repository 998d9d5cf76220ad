"""Seeding a batch of environments the project's way: sub-environment ``i`` from
``SeedSequence([seed, i])``.

Gymnasium's vector environments seed sub-environment ``i`` with ``seed + i``, so the batch
seeded 0 and the batch seeded 1 share all but one stream (environment 1 of the first is
environment 0 of the second). The project's rule (DESIGN.md, determinism) derives every stream
from ``SeedSequence([seed, index])`` instead, which keeps batches with different seeds apart.
:class:`SeedSequenceSeeds` wraps any vector environment (``gymnasium.make_vec(...,
vectorization_mode="sync" | "async")``) and turns ``reset(seed=s)`` into those seeds; the same
seed gives the same batch, whichever mode runs it.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium.vector import VectorEnv, VectorWrapper


def vector_seeds(seed: int, num_envs: int) -> list[int]:
    """One 63-bit seed per sub-environment: the first word of ``SeedSequence([seed, i])``."""
    if seed < 0:
        raise ValueError(f"a seed must be a non-negative integer, got {seed}")
    return [
        int(np.random.SeedSequence([seed, i]).generate_state(1, np.uint64)[0] >> np.uint64(1))
        for i in range(num_envs)
    ]


class SeedSequenceSeeds(VectorWrapper):
    """A vector environment whose ``reset(seed=s)`` seeds sub-environment ``i`` with
    ``vector_seeds(s, num_envs)[i]``; a list of seeds (or None) passes through unchanged."""

    def __init__(self, env: VectorEnv) -> None:
        super().__init__(env)

    def reset(
        self,
        *,
        seed: int | list[int | None] | None = None,
        options: dict[str, Any] | None = None,
    ) -> tuple[Any, dict[str, Any]]:
        seeds = vector_seeds(seed, self.num_envs) if isinstance(seed, int) else seed
        # VectorEnv.reset is annotated int | None; Sync/AsyncVectorEnv take a list per env
        return self.env.reset(seed=seeds, options=options)  # type: ignore[arg-type]
