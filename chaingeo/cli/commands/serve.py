"""``chain serve``: the environment over HTTP and WebSocket (OpenEnv's protocol), the 3D player
in the browser at ``/play/<level id>``, and with ``--study NAME`` a human-baseline study.

Needs the ``serve`` extra (openenv-core). Binds 127.0.0.1 unless ``--host`` says otherwise;
``--token`` (or ``CHAIN_SERVE_TOKEN``) makes every route but ``/health`` ask for it.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import re
from pathlib import Path
from typing import Any

TOKEN_RE = re.compile(r"[A-Za-z0-9._~+/=-]{16,256}")


def register(sub: Any) -> None:
    from chaingeo.cli.level_arg import add_level_list
    from chaingeo.core import limits

    p = sub.add_parser(
        "serve", help="serve the environment (OpenEnv), the 3D player and human studies"
    )
    add_level_list(p)
    p.add_argument("--host", default="127.0.0.1", help="address to bind")
    p.add_argument("--port", type=int, default=8000, help="port")
    p.add_argument(
        "--token",
        default=None,
        help="require this bearer token (else $CHAIN_SERVE_TOKEN, if set)",
    )
    p.add_argument(
        "--max-sessions",
        type=int,
        default=limits.MAX_SESSIONS,
        help="sessions open at once",
    )
    p.add_argument(
        "--idle",
        type=float,
        default=limits.SESSION_IDLE_SECONDS,
        help="seconds before a silent session is closed",
    )
    p.add_argument("--study", default=None, metavar="NAME", help="run a human-baseline study")
    p.add_argument(
        "--study-dir",
        type=Path,
        default=Path("studies"),
        help="where a study writes its run (as DIR/NAME)",
    )
    p.add_argument("--seed", type=int, default=0, help="a study's seed for the level orders")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from chaingeo.cli.errors import CommandError
    from chaingeo.cli.level_arg import levels_of
    from chaingeo.core import limits

    if importlib.util.find_spec("openenv") is None:
        raise CommandError("chain serve needs openenv-core: pip install 'chaingeo[serve]'")
    from chaingeo.integrations.serve.app import ServeOptions, serve
    from chaingeo.integrations.serve.environment import Catalog
    from chaingeo.integrations.serve.study import Study

    if not 1 <= args.max_sessions <= 10 * limits.MAX_SESSIONS:
        raise CommandError(f"--max-sessions must be from 1 to {10 * limits.MAX_SESSIONS}")
    if not 1 <= args.port <= 65535 or not args.idle > 0:
        raise CommandError("--port must be 1-65535 and --idle above 0")
    levels = {lv.id: lv for lv in levels_of(args)}
    study = None
    if args.study is not None:
        study = Study.create(args.study, args.study_dir, list(levels.values()), args.seed)
    token = args.token if args.token is not None else os.environ.get("CHAIN_SERVE_TOKEN") or None
    if token is not None and not TOKEN_RE.fullmatch(token):
        raise CommandError("a token is 16-256 letters, digits or -._~+/= (it goes in a cookie)")
    catalog = Catalog(levels, study)
    serve(catalog, ServeOptions(args.host, args.port, token, args.max_sessions, args.idle))
    return 0
