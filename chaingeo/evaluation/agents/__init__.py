"""The agents: each module one kind (baselines, replay, external command, OpenAI-compatible
chat); :mod:`chaingeo.evaluation.agents.registry` maps names to factories."""
