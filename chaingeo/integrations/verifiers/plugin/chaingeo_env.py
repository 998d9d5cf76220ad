"""The verifiers plugin module of CHAIN-geo (taskset id ``chaingeo-env``).

verifiers finds a taskset, its environment and its default harness by importing the module its
id names and taking the one subclass of each that ``__all__`` exports; a dotted id does not
resolve, hence this top-level module. The code is :mod:`chaingeo.integrations.verifiers`.
"""

from chaingeo.integrations.verifiers import ChainGeoEnv, ChainGeoHarness, ChainGeoTaskset

__all__ = ["ChainGeoEnv", "ChainGeoHarness", "ChainGeoTaskset"]
