"""``chain serve``'s application: OpenEnv's server for our environment, the player, the guard.

:func:`build_app` makes OpenEnv's FastAPI app (``create_fastapi_app``: the HTTP routes and the
``/ws`` sessions OpenEnv's clients speak) for :class:`ChainEnvironment`, adds the player's pages
and turns our refusals into 4xx answers; :class:`~chaingeo.integrations.serve.guard.Guard`
wraps it all. :func:`serve` runs it under uvicorn until SIGINT/SIGTERM, then closes every
session (a study writes the episodes that were open) before it exits.
"""

from __future__ import annotations

import functools
import json
from dataclasses import dataclass
from typing import Any

from fastapi import FastAPI, Request
from fastapi.responses import HTMLResponse, JSONResponse, Response
from openenv.core.env_server.http_server import create_fastapi_app
from openenv.core.env_server.types import ConcurrencyConfig

from chaingeo.core import limits
from chaingeo.core.errors import ChainGeoError
from chaingeo.integrations.serve.environment import Catalog, ChainEnvironment
from chaingeo.integrations.serve.errors import RequestError, ServeError
from chaingeo.integrations.serve.guard import Guard, error_body
from chaingeo.integrations.serve.models import ChainAction, ChainObservation
from chaingeo.integrations.serve.pages import index_page, player_page, static_file


@dataclass(frozen=True)
class ServeOptions:
    host: str = "127.0.0.1"
    port: int = 8000
    token: str | None = None
    max_sessions: int = limits.MAX_SESSIONS
    idle_seconds: float = limits.SESSION_IDLE_SECONDS


def _refused(request: Request, exc: Exception) -> Response:
    """Our refusals, and any typed error a client's input caused, as 4xx JSON."""
    error = exc if isinstance(exc, ServeError) else RequestError(str(exc))
    return Response(error_body(error), status_code=error.status, media_type="application/json")


def build_app(catalog: Catalog, options: ServeOptions = ServeOptions()) -> Guard:
    """The whole server as one ASGI app."""
    app: FastAPI = create_fastapi_app(
        functools.partial(ChainEnvironment, catalog),
        ChainAction,
        ChainObservation,
        # Idle sessions are closed by the guard (OpenEnv's reaper frees the slot but leaves the
        # socket playing on the closed environment).
        concurrency_config=ConcurrencyConfig(max_concurrent_envs=options.max_sessions),
    )
    app.add_exception_handler(ChainGeoError, _refused)
    _player_routes(app, catalog)
    return Guard(app, options.token, options.idle_seconds)


def _player_routes(app: FastAPI, catalog: Catalog) -> None:
    study = catalog.study is not None

    @app.get("/", response_class=HTMLResponse, include_in_schema=False)
    async def index() -> HTMLResponse:
        return HTMLResponse(index_page(catalog))

    @app.get("/levels", tags=["Environment Info"], summary="The levels this server plays")
    async def levels() -> JSONResponse:
        rows: list[dict[str, Any]] = [
            {"id": lv.id, "family": lv.family, "difficulty": lv.difficulty, "goal": lv.goal}
            | ({} if study else {"optimal_steps": lv.optimal_steps})
            for lv in catalog.levels.values()
        ]
        return JSONResponse(rows)

    @app.get("/play/{level_id}", response_class=HTMLResponse, include_in_schema=False)
    async def play(level_id: str) -> HTMLResponse:
        if not study:
            catalog.level(level_id)  # 404 for an unknown id
        return HTMLResponse(player_page(level_id, study))

    @app.get("/static/{name}", include_in_schema=False)
    async def static(name: str) -> Response:
        body, media = static_file(name)
        return Response(body, media_type=media, headers={"cache-control": "max-age=3600"})


def serve(catalog: Catalog, options: ServeOptions) -> None:
    """Run until interrupted; uvicorn closes the WebSockets (each session's environment is
    closed, so a study records what was open) and stops within a few seconds."""
    import uvicorn

    app = build_app(catalog, options)
    config = uvicorn.Config(
        app,
        host=options.host,
        port=options.port,
        ws_max_size=2 * limits.MAX_REQUEST_BYTES,  # larger frames: closed by uvicorn
        timeout_graceful_shutdown=5,
        log_level="warning",
        lifespan="on",
    )
    server = _server_class()(config)
    print(
        json.dumps(
            {"serving": f"http://{options.host}:{options.port}/", "levels": len(catalog.levels)}
        ),
        flush=True,
    )
    try:
        server.run()
    finally:
        if catalog.study is not None:
            catalog.study.close()
    print(json.dumps({"stopped": f"http://{options.host}:{options.port}/"}), flush=True)


def _server_class() -> type:
    import uvicorn

    class Server(uvicorn.Server):
        """uvicorn's server, but a SIGTERM/SIGINT it shut down for ends the process normally
        (uvicorn raises the signal again after its graceful shutdown: exit status -15)."""

        def handle_exit(self, sig: int, frame: Any) -> None:
            super().handle_exit(sig, frame)
            self._captured_signals.clear()

    return Server
