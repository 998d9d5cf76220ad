"""CHAIN-geo as a verifiers environment (``pip install 'chaingeo[train]'``), for evaluation with
``vf-eval`` and training with prime-rl.

``load_environment(family=..., difficulty=..., split=..., images=True, protocol=..., reward=...)``
returns the environment; it needs nothing but this package (the id ``chaingeo-env`` resolves in
this process, :func:`~chaingeo.integrations.verifiers.plugin_module.install_alias`).
verifiers' command line finds a taskset by the top-level module its id names: the plugin
``chaingeo_env`` (a one-file distribution shipped inside this package, so chaingeo's wheel stays
one top-level package) is installed by ``python -m chaingeo.integrations.verifiers install``,
then ``vf-eval chaingeo-env --env.taskset.family puzzle`` works.
Rewards, summing to 1 for an optimal, well-formed episode: ``success`` (0.5), ``efficiency``
(0.4; ``1 - NormDist`` when solved) and ``format`` (0.1; the share of readable actions).
"""

from __future__ import annotations

try:
    import verifiers.v1  # noqa: F401
except ImportError as e:  # pragma: no cover - exercised only without the extra
    raise ImportError(
        "chaingeo.integrations.verifiers needs verifiers: pip install 'chaingeo[train]'"
    ) from e

from chaingeo.integrations.verifiers.environment import (
    ChainGeoEnv,
    ChainGeoEnvConfig,
    load_environment,
)
from chaingeo.integrations.verifiers.harness import ChainGeoHarness, ChainGeoHarnessConfig
from chaingeo.integrations.verifiers.plugin_module import install_alias
from chaingeo.integrations.verifiers.taskset import (
    TASKSET_ID,
    ChainGeoConfig,
    ChainGeoData,
    ChainGeoTask,
    ChainGeoTaskset,
)

install_alias()

__all__ = [
    "TASKSET_ID",
    "ChainGeoConfig",
    "ChainGeoData",
    "ChainGeoEnv",
    "ChainGeoEnvConfig",
    "ChainGeoHarness",
    "ChainGeoHarnessConfig",
    "ChainGeoTask",
    "ChainGeoTaskset",
    "load_environment",
]
