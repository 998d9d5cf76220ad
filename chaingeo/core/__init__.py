"""The core layer: lattice geometry, the 24 rotations, piece sets, colours, rules, the reference
kinematics, the ``chain-level/1`` format and other file formats.

It imports nothing from :mod:`solvers`, :mod:`generator` or the layers above it in
:mod:`chaingeo` (import-linter checks this in CI).
"""
