"""Fire drills: a hostile model server (:mod:`chaingeo.evaluation.hostile_server`) plays each
attack of issue #21 against a real :func:`~chaingeo.evaluation.runner.evaluate` run.

Each drill runs two episodes (a stacking and a puzzle level of the shipped suite, no pictures)
with a fake key and short deadlines, and counts what matters: the episodes recorded as played or
as server errors, a run that crashed (``evaluate`` raised), a run that hung (past
:data:`HANG_SECONDS`), the key found anywhere it must not be (a log file, an error, another
server), and the bytes of the run's ``episodes.jsonl``. ``chain bench robustness`` prints the
table (:func:`fault_table`).
"""

from __future__ import annotations

import tempfile
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Final

from chaingeo.core.level import Level, load_level
from chaingeo.core.suite import suite_folder
from chaingeo.evaluation.agents.base import AgentSpec
from chaingeo.evaluation.episode import ProtocolConfig
from chaingeo.evaluation.hostile_server import Served, serve
from chaingeo.evaluation.logs import EPISODES
from chaingeo.evaluation.runner import RunConfig, evaluate
from chaingeo.evaluation.usage import Price, PriceTable

#: A fake key: the drills look for it wherever it must not go.
KEY: Final = "sk-drill-do-not-leak-0123456789abcdef"
#: Seconds after which a drill's run counts as hung.
HANG_SECONDS: Final = 60.0
#: The levels played (two episodes a drill).
LEVELS: Final = (
    ("stacking", "stacking-2x3x3-hard-s109-000000.json"),
    ("puzzle", "puzzle-easy-04-burr6.json"),
)
#: Agent options: short deadlines, one retry, a small retry budget, text and tools as offered.
OPTIONS: Final = {
    "model": "hostile",
    "timeout": 1.5,
    "max_retries": 1,
    "backoff_base": 0.01,
    "retry_budget": 3.0,
    "images": False,
}
FINISH: Final = {"reply": "<action>finish</action>"}


def _reply(text: str, **extra: Any) -> dict[str, Any]:
    return {"reply": text, **extra}


def _calls(*made: tuple[Any, Any]) -> dict[str, Any]:
    return {"reply": "", "tool_calls": list(made)}


def _break(answer: Any) -> dict[str, Any]:
    return {"fault": "answer", "answer": answer}


@dataclass(frozen=True)
class Drill:
    kind: str  # the class of attack
    name: str
    entries: tuple[dict[str, Any], ...]
    redirect: bool = False  # the first entry redirects to a second server (watched for the key)


def drills() -> list[Drill]:
    """Every attack of issue #21 items 1-8, in the table's order."""
    image = "data:image/png;base64," + "iVBOR" + "A" * 4_000_000
    wide = [("place", {"piece": "q" * 3_000, "cells": [[1, 1, 1]]})] * 300
    usage = {"prompt_tokens": 100, "completion_tokens": 20}
    return [
        Drill("text", "lone surrogate in a reply", (_reply("\ud800 <action>finish</action>"),)),
        Drill("text", "lone surrogate as a tool name", (_calls(("\ud800", "{}")), FINISH)),
        Drill("text", "160 KB of <action> tags", (_reply("<action>" * 20_000), FINISH)),
        Drill("text", "480 KB of <action> tags", (_reply("<action>" * 60_000), FINISH)),
        Drill(
            "usage",
            "prompt_tokens of 401 digits",
            (_reply("x", raw_usage={**usage, "prompt_tokens": 10**400}),) * 2,
        ),
        Drill(
            "usage",
            "prompt_tokens 1e308",
            (_reply("x", raw_usage={**usage, "prompt_tokens": 1e308}),) * 2,
        ),
        Drill(
            "usage",
            "negative completion_tokens",
            (_reply("x", raw_usage={**usage, "completion_tokens": -7}),) * 2,
        ),
        Drill(
            "tool calls",
            "a 5,000-digit argument",
            (_calls(("place", '{"piece": "red", "cells": [[' + "9" * 5_000 + ",1,1]]}")), FINISH),
        ),
        Drill("tool calls", "90 steps of 300 huge calls", (_calls(*wide),) * 90),
        Drill(
            "transport",
            "a byte every 0.5 s",
            ({"fault": "trickle", "interval": 0.5, "seconds": 20},) * 2,
        ),
        Drill("transport", "Retry-After: 86400", ({"fault": "retry-after", "after": "86400"},) * 2),
        Drill("transport", "302 to another port", ({"fault": "redirect"},) * 2, redirect=True),
        Drill("protocol", '{"choices": [1]}', (_break({"choices": [1]}),) * 2),
        Drill("protocol", 'message: "hi"', (_break({"choices": [{"message": "hi"}]}),) * 2),
        Drill(
            "protocol",
            "content a number",
            (_break({"choices": [{"message": {"content": 5}}]}),) * 2,
        ),
        Drill(
            "protocol", "content null", (_break({"choices": [{"message": {"content": None}}]}),) * 2
        ),
        Drill(
            "protocol",
            "content an object",
            (_break({"choices": [{"message": {"content": {}}}]}),) * 2,
        ),
        Drill("size", "a 4 MB base64 image", (_reply(f"see {image} <action>finish</action>"),)),
        Drill("size", "30 replies of 1 MB", (_reply("z" * 1_000_000),) * 30),
    ]


@dataclass
class _Outcome:
    error: BaseException | None = None
    done: threading.Event = field(default_factory=threading.Event)


def _levels() -> list[Level]:
    return [load_level(suite_folder(family) / name) for family, name in LEVELS]


def run_drill(drill: Drill, levels: Sequence[Level], work: Path) -> dict[str, Any]:
    """One drill: its row of the table."""
    elsewhere = Served()
    run_dir = work / "run"
    outcome = _Outcome()
    started = time.monotonic()
    with serve([FINISH] * 3, elsewhere) as target:
        entries = [
            {**e, "location": f"{target}/chat/completions"} if drill.redirect else e
            for e in drill.entries
        ]
        with serve(entries) as url:
            spec = AgentSpec("openai", {**OPTIONS, "base_url": url}, {"api_key": KEY})
            prices = PriceTable({"hostile": Price(1.0, 2.0)})

            def play() -> None:
                try:
                    evaluate(
                        levels, spec, run_dir, ProtocolConfig(), RunConfig(progress=False), prices
                    )
                except BaseException as e:  # the figure this drill counts
                    outcome.error = e
                finally:
                    outcome.done.set()

            threading.Thread(target=play, daemon=True).start()
            hung = not outcome.done.wait(HANG_SECONDS)
    log = run_dir / EPISODES
    records = log.read_text("utf-8").splitlines() if log.exists() else []
    written = b"".join(f.read_bytes() for f in run_dir.rglob("*") if f.is_file())
    leak = KEY.encode() in written or KEY in str(outcome.error or "")
    leak = leak or any(KEY in str(h) for h in elsewhere.headers)
    return {
        "kind": drill.kind,
        "drill": drill.name,
        "episodes": len(records),
        "done": sum('"status": "done"' in r for r in records),
        "server_errors": sum('"status": "error"' in r for r in records),
        "crash": int(outcome.error is not None),
        "hang": int(hung),
        "leak": int(leak),
        "log_bytes": log.stat().st_size if log.exists() else 0,
        "seconds": round(time.monotonic() - started, 1),
    }


def server_fault_rows(names: Sequence[str] | None = None) -> list[dict[str, Any]]:
    """The table's rows: every drill (or those named), each in a fresh temporary run."""
    levels = _levels()
    rows = []
    for drill in drills():
        if names is not None and drill.name not in names:
            continue
        with tempfile.TemporaryDirectory(prefix="chain-drill-") as tmp:
            rows.append(run_drill(drill, levels, Path(tmp)))
    return rows


_COLUMNS: Final = (
    ("kind", "class"),
    ("drill", "attack"),
    ("episodes", "episodes"),
    ("done", "played"),
    ("server_errors", "server errors"),
    ("crash", "run crashes"),
    ("hang", "hangs"),
    ("leak", "key leaks"),
    ("log_bytes", "log bytes"),
    ("seconds", "seconds"),
)


def fault_table(rows: Sequence[dict[str, Any]]) -> str:
    """Markdown: one row a drill, then the totals (log bytes: the largest)."""
    lines = [
        "| " + " | ".join(title for _, title in _COLUMNS) + " |",
        "|" + "|".join("---" if k in ("kind", "drill") else "---:" for k, _ in _COLUMNS) + "|",
    ]
    for row in rows:
        lines.append("| " + " | ".join(str(row[k]) for k, _ in _COLUMNS) + " |")
    total: dict[str, Any] = {k: sum(r[k] for r in rows) for k, _ in _COLUMNS[2:]}
    total.update(kind="**all**", drill=f"{len(rows)} attacks")
    total["log_bytes"] = max((r["log_bytes"] for r in rows), default=0)
    total["seconds"] = round(total["seconds"], 1)
    lines.append("| " + " | ".join(str(total[k]) for k, _ in _COLUMNS) + " |")
    return "\n".join(lines)
