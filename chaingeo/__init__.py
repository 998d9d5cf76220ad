"""CHAIN-geo core: lattice geometry, levels, rules, state machines, observations, agents."""

__version__ = "0.1.0"
