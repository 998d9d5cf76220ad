"""Integrations with training frameworks, as optional extras (``pip install 'chaingeo[train]'``).

They sit above the evaluation harness: they play our levels with our state machines and score
them with our metrics, in another framework's terms. :mod:`chaingeo.integrations.game` needs
nothing beyond the core install; :mod:`chaingeo.integrations.verifiers` needs ``verifiers``.
"""
