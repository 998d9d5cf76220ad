"""The environments, in rooms: actions and the text parser (:mod:`.actions`), the two state
machines (:mod:`.machines`), pictures and meshes (:mod:`.render`), video models
(:mod:`.worldmodel`); observations, the Gymnasium wrappers and the dataset export beside them.

Built on :mod:`chaingeo.core` and :mod:`chaingeo.solvers`; the evaluation harness sits above.
"""
