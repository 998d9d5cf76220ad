"""The environments: action types and the text parser, the two state machines (stacking and
puzzles), observations, rendering, meshes and the Gymnasium wrappers.

Built on :mod:`chaingeo.core` and :mod:`solvers`; the evaluation harness sits above.
"""
