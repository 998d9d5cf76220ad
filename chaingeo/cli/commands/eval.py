"""``chain eval``: run agents on a level suite and print the leaderboard.

With no arguments it runs the built-in baselines (oracle, greedy, random) on the shipped suite
``levels/`` and prints Table 1. ``chain eval --agent openai --model NAME --base-url URL``
evaluates a model on any OpenAI-compatible server (the key comes from ``$OPENAI_API_KEY`` or the
variable named by ``--api-key-env``; it is never logged). Each (agent, protocol) pair writes one
run directory under ``--out``; ``--resume`` continues killed runs there.

Tools: a model is offered one function per action kind and plays by calling them (``--tools``,
i.e. ``on``); by default (``auto``) a server that refuses tools is played in text instead, said
once per run. ``--model-option KEY=VALUE`` passes a field through to the server's request body
(``reasoning_effort=high``, ``max_tokens=4096``, ``temperature=null`` to drop one,
``extra_body='{"top_k": 20}'`` merged in).

Exit status: 0 when every episode was played; 1 when some episode errored (agent or environment
fault, server down after every retry; said above the leaderboard with one line per distinct
reason and its count), unless ``--allow-errors``;
2 for a usage error or refused credentials (HTTP 401/403, or no key for a remote server), which
stop the run at the first call.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import re
import sys
from collections import Counter
from pathlib import Path
from typing import TYPE_CHECKING, Any

from chaingeo.cli.errors import CommandError
from chaingeo.cli.out_arg import add_out

if TYPE_CHECKING:
    from chaingeo.evaluation.episode import Outcome


def register(sub: Any) -> None:
    p = sub.add_parser(
        "eval",
        help="evaluate agents on a level suite (no arguments: the baselines on the shipped suite)",
        description=__doc__,
    )
    p.add_argument(
        "--levels",
        type=Path,
        default=None,
        metavar="LEVELS",
        help="a folder of levels, a chain-level/1 file or the id of a shipped level (default: "
        "the shipped suite)",
    )
    p.add_argument(
        "--agent",
        action="append",
        default=None,
        help="agent to run, repeatable (default: oracle, greedy, random)",
    )
    p.add_argument("--model", help="model name (openai agent)")
    p.add_argument("--base-url", help="OpenAI-compatible base URL, e.g. http://127.0.0.1:8000/v1")
    p.add_argument("--api-key-env", default=None, help="variable holding the API key")
    p.add_argument("--label", help="name shown in reports (default: the model or agent)")
    p.add_argument(
        "--agent-option",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="agent option (VALUE read as JSON when it parses), repeatable",
    )
    p.add_argument(
        "--tools",
        nargs="?",
        const="on",
        choices=("auto", "on", "off"),
        default=None,
        help="native tool calls for the openai agent: on (the flag alone), off, or auto (the"
        " default: tools, or text when the server refuses them)",
    )
    p.add_argument(
        "--model-option",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="request body field for the model server (VALUE read as JSON when it parses), e.g."
        " reasoning_effort=high or extra_body='{\"top_k\": 20}', repeatable",
    )
    p.add_argument(
        "--config",
        metavar="NAME|FILE",
        help="an evaluation protocol as a file: sampling, history, budgets, pictures, protocols"
        f" (shipped: {', '.join(_config_names())}; or a .toml path); flags given explicitly"
        " override it",
    )
    p.add_argument(
        "--protocol",
        choices=("interactive", "oneshot", "both"),
        default=None,
        help="turn by turn with feedback, or the whole plan at once (default: interactive, or"
        " the config's)",
    )
    p.add_argument(
        "--samples", type=int, default=None, help="episodes per level (Pass@k, Pass^k, Avg@k)"
    )
    p.add_argument("--candidates", type=int, default=1, help="candidates per turn (verifier)")
    p.add_argument(
        "--judge",
        default="first",
        help="ranks verified candidates: first, vote, progress, or model (a VLM judge)",
    )
    p.add_argument(
        "--judge-option",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="judge option, e.g. model=NAME base_url=URL (for --judge model), repeatable",
    )
    p.add_argument(
        "--history-window",
        type=int,
        default=None,
        help="recent turns shown (5 unless the config says)",
    )
    p.add_argument("--text-state", action="store_true", help="add every piece's cells as text")
    p.add_argument("--seed", type=int, default=0, help="seed of the agents' randomness")
    p.add_argument("--jobs", type=int, default=1, help="episodes in parallel (processes)")
    p.add_argument("--dask", metavar="ADDRESS", help="run episodes on a Dask scheduler")
    p.add_argument("--family", choices=("stacking", "puzzle"), help="only this family")
    p.add_argument("--difficulty", choices=("easy", "mid", "hard"), help="only this tier")
    p.add_argument("--limit", type=int, help="only the first N levels (by id)")
    add_out(p, "folder", "the run directories (default: runs/<time>)")
    p.add_argument("--resume", action="store_true", help="continue the runs in --out")
    p.add_argument("--retry-errors", action="store_true", help="with --resume: rerun errors")
    p.add_argument("--prices", action="append", default=[], help="extra price table (JSON)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument(
        "--allow-errors",
        action="store_true",
        help="exit 0 even when some episodes errored (they are still reported)",
    )
    # The module providing new_state and observe; tests point it at a double.
    p.add_argument("--env", default="chaingeo", help=argparse.SUPPRESS)
    p.add_argument(
        "--questions",
        type=Path,
        metavar="FILE",
        help="instead of levels: ask the questions.jsonl of `chain questions` single-turn",
    )
    p.add_argument(
        "--split",
        choices=("test", "train", "all"),
        default="test",
        help="with --questions: the questions asked",
    )
    p.set_defaults(func=run)


def _config_names() -> list[str]:
    from chaingeo.evaluation.eval_config import config_names

    return config_names()


def _option(text: str, flag: str = "--agent-option") -> tuple[str, Any]:
    if "=" not in text:
        raise CommandError(f"{flag} {text!r}: expected KEY=VALUE")
    key, value = text.split("=", 1)
    try:
        return key.strip(), json.loads(value)
    except json.JSONDecodeError:
        return key.strip(), value


#: Options only a model agent takes; the built-in baselines are run without them.
MODEL_ONLY = (
    "model",
    "base_url",
    "api_key_env",
    "tools",
    "model_options",
    "temperature",
    "top_p",
    "max_tokens",
    "images",
)


def _slug(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "-", text).strip("-") or "agent"


def _say_tool_fallback(run: str, refused: list[str]) -> None:
    """One line per run whose server refused native tools (its episodes were played in text)."""
    if refused:
        print(
            f"NOTE: {run}: the server refused tools ({refused[0]}); {len(refused)} episode(s)"
            " played with text actions instead"
        )


#: Characters of one error reason printed on the console.
MAX_REASON_CHARS = 300


def _error_reasons(failed: list[Outcome]) -> list[str]:
    """One line per distinct reason of the errored episodes, most frequent first, with counts
    (cleaned of code points a terminal cannot take, bounded)."""
    from chaingeo.evaluation.sanitize import clean_text, shorten

    reasons = Counter(shorten(clean_text(o.error or "?"), MAX_REASON_CHARS) for o in failed)
    return [f"  {n} x {reason}" for reason, n in sorted(reasons.items(), key=lambda x: -x[1])]


def run(args: argparse.Namespace) -> int:
    if args.questions is not None:
        from chaingeo.cli.eval_questions import run_questions

        return run_questions(args, dict(_option(o) for o in args.agent_option))
    from chaingeo.cli.level_arg import find_level
    from chaingeo.core.level import load_levels
    from chaingeo.core.suite import suite_folder
    from chaingeo.evaluation.agents.base import AgentSpec, AuthenticationError
    from chaingeo.evaluation.agents.openai_chat import provider_fields
    from chaingeo.evaluation.agents.registry import BASELINES
    from chaingeo.evaluation.eval_config import ConfigError, EvalConfig, load_config
    from chaingeo.evaluation.report.tables import Run, run_of, table1
    from chaingeo.evaluation.runner import RunConfig, evaluate
    from chaingeo.evaluation.usage import PriceTable

    source = args.levels or suite_folder()
    # a folder of levels, else one level: a file or the id of a shipped level
    levels = load_levels(source) if source.is_dir() else [find_level(source)]
    if args.family:
        levels = [lv for lv in levels if lv.family == args.family]
    if args.difficulty:
        levels = [lv for lv in levels if lv.difficulty == args.difficulty]
    if args.limit is not None:
        levels = levels[: args.limit]
    if not levels:
        raise CommandError(f"{source}: no levels to evaluate")
    try:
        config = load_config(args.config) if args.config else EvalConfig()
    except ConfigError as e:
        raise CommandError(str(e)) from None
    levels = config.budgeted(levels)

    names = args.agent or list(BASELINES)
    options = dict(_option(o) for o in args.agent_option)
    if args.model:
        options["model"] = args.model
    if args.base_url:
        options["base_url"] = args.base_url
    if args.api_key_env:
        options["api_key_env"] = args.api_key_env
    if args.label:
        options["label"] = args.label
    for key, value in config.sampling().items():  # the config's sampling; options win
        options.setdefault(key, value)
    if not config.images:
        options.setdefault("images", False)
    if args.tools:
        options["tools"] = args.tools
    if args.model_option:
        model_options = dict(options.get("model_options") or {})
        model_options.update(_option(o, "--model-option") for o in args.model_option)
        try:
            provider_fields(model_options)
        except ValueError as e:
            raise CommandError(f"--model-option: {e}") from None
        options["model_options"] = model_options
    if args.protocol is None:
        protocols: list[str] = list(config.protocols)
    else:
        protocols = ["interactive", "oneshot"] if args.protocol == "both" else [args.protocol]
    if args.out is None:
        if args.resume:
            raise CommandError("--resume needs --out (the folder of the runs to continue)")
        stamp = _dt.datetime.now(_dt.UTC).strftime("%Y%m%d-%H%M%S")
        args.out = Path("runs") / stamp
    prices = PriceTable.load(*args.prices)
    cfg = RunConfig(
        samples=config.samples if args.samples is None else args.samples,
        seed=args.seed,
        jobs=args.jobs,
        dask=args.dask,
        resume=args.resume,
        retry_errors=args.retry_errors,
        progress=not args.no_progress,
    )
    runs: list[Run] = []
    errored: dict[str, int] = {}
    failed: list[Outcome] = []
    for name in names:
        # Built-in baselines take no model options; only pass what was given explicitly.
        opts = (
            options
            if name not in BASELINES
            else {k: v for k, v in options.items() if k not in MODEL_ONLY}
        )
        spec = AgentSpec(name, opts)
        for proto_name in protocols:
            try:
                window = args.history_window
                proto = config.protocol(
                    proto_name,  # type: ignore[arg-type]
                    history_window=config.history_window if window is None else window,
                    text_state=args.text_state or config.text_state,
                    candidates=args.candidates,
                    judge=args.judge,
                    judge_options=dict(_option(o) for o in args.judge_option),
                    env=args.env,
                )
            except ValueError as e:
                raise CommandError(str(e)) from None
            run_dir = args.out / f"{_slug(spec.label)}-{proto_name}"
            try:
                outcomes = evaluate(levels, spec, run_dir, proto, cfg, prices, stream=sys.stderr)
            except AuthenticationError as e:
                raise CommandError(f"{spec.label}: authentication failed: {e}") from None
            runs.append(run_of(run_dir, outcomes.header, outcomes))
            errors = [o for o in outcomes if o.error is not None]
            errored[run_dir.name] = len(errors)
            failed += errors
            _say_tool_fallback(run_dir.name, outcomes.tools_refused)
    total = sum(errored.values())
    if total:
        where = ", ".join(f"{name}: {n}" for name, n in errored.items() if n)
        verdict = "accepted (--allow-errors)" if args.allow_errors else "exit status 1"
        print(
            f"WARNING: {total} episode(s) errored ({where}); they count as unsolved;"
            f" {verdict}; `--resume --retry-errors` reruns them"
        )
        print("\n".join(_error_reasons(failed)))
    print(table1(runs).markdown())
    print(f"runs written to {args.out}; `chain report {args.out}` for every table and the plot")
    return 1 if total and not args.allow_errors else 0
