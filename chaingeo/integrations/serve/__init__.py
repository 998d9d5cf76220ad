"""``chain serve``: the environment as a service (openenv-core's server, so OpenEnv's clients
connect unchanged), a 3D player in the browser, and a human-baseline study (extra ``serve``)."""
