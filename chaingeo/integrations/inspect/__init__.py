"""CHAIN as an inspect_ai task: ``inspect eval chaingeo/chain --model <provider>/<model>``.

After ``pip install 'chaingeo[inspect]'`` inspect_ai finds the task through the entry point
``chaingeo`` (``[project.entry-points.inspect_ai]`` names :mod:`._registry`), so every model
provider inspect_ai speaks (OpenAI, Anthropic, Google, Bedrock, vLLM, Ollama, ...), its epochs,
retries, caching, ``eval-set`` and the ``inspect view`` transcripts work on our levels.

The task is a thin door over the one episode (:class:`~chaingeo.evaluation.episode.Episode`):
one sample per level whose input is the instruction and the first observation (the views as
image content); the solver (:mod:`.solver`) turns each observation into a chat message, asks
the model, reads its reply in the dialect (``text`` or ``tools``: native tool calls) and plays
it until the episode is done; the scorer (:mod:`.scoring`) reads the episode's
:class:`~chaingeo.evaluation.episode.Outcome`. ``agent=oracle`` plays each level's stored plan
through the same reading and playing path, so the task checks itself end to end.

inspect_ai is imported only by this package's modules (the ``inspect`` extra).
"""
