"""What the round-three classes of ``chain bench robustness`` share
(:mod:`chaingeo.benchmarks._surfaces`): one row of counts a surface, a case bounded in time,
special files, and the table."""

from __future__ import annotations

import contextlib
import os
import threading
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from chaingeo.core.errors import ChainGeoError

SEED = 20261128
#: Seconds one case may take before it counts as a hang.
CASE_SECONDS = 20.0


@dataclass
class Surface:
    """The counts of one surface (one row of the table)."""

    name: str
    cases: int = 0
    tracebacks: int = 0
    hangs: int = 0
    wrong: int = 0
    outside: int = 0
    kinds: dict[str, int] = field(default_factory=dict)

    def bad(self) -> int:
        return self.tracebacks + self.hangs + self.wrong + self.outside

    def run(self, call: Callable[[], Any], wrong: Callable[[Any], bool] = lambda _: False) -> Any:
        """One case: ``call()`` in a thread bounded by :data:`CASE_SECONDS`; a typed error
        is a refusal, anything else escaping a traceback; ``wrong(result)`` a wrong
        acceptance."""
        self.cases += 1
        out: list[Any] = []
        err: list[BaseException] = []

        def body() -> None:
            try:
                out.append(call())
            except ChainGeoError as e:
                err.append(e)
            except BaseException as e:  # the figure this class exists for
                err.append(e)

        worker = threading.Thread(target=body, daemon=True)
        worker.start()
        worker.join(CASE_SECONDS)
        if worker.is_alive():
            self.hangs += 1
            return None
        if err:
            if not isinstance(err[0], ChainGeoError):
                self.tracebacks += 1
                name = type(err[0]).__name__
                self.kinds[name] = self.kinds.get(name, 0) + 1
            return err[0]
        if wrong(out[0]):
            self.wrong += 1
        return out[0]


def always(_: Any) -> bool:
    return True


def never(_: Any) -> bool:
    return False


def valid(verdict: Any) -> bool:
    return bool(verdict.valid)


def usable(found: Any) -> bool:
    return bool(found.usable)


def grew(seen: list[str], before: int, _: Any) -> bool:
    return len(seen) > before


def whole_clip(clip: Any) -> bool:
    return len(clip.frames) == 120


def refused_but_used(env: Any, used: int, out: Any) -> bool:
    return bool(out[4]["error"] == "refused" and env.state.steps_used != used)


def special(path: Path, kind: str) -> Path:
    """``path`` made a link to ``/dev/zero``, a FIFO (opened for writing by a helper thread
    after a while, so a reader that blocks on it ends), or a sparse file of 3 GB."""
    path.unlink(missing_ok=True)
    if kind == "zero":
        path.symlink_to("/dev/zero")
    elif kind == "fifo":
        os.mkfifo(path)

        def release() -> None:
            with contextlib.suppress(OSError):
                fd = os.open(path, os.O_WRONLY | os.O_NONBLOCK)
                os.close(fd)

        timer = threading.Timer(CASE_SECONDS + 1, release)
        timer.daemon = True
        timer.start()
    else:
        with open(path, "wb") as fh:
            fh.truncate(3 * 1024**3)
    return path


SPECIALS = ("zero", "fifo", "huge")


def surface_table(rows: list[Surface]) -> str:
    """Markdown: one row a surface, as the issue's table, then the totals."""
    head = "| surface | cases | tracebacks | hangs | wrong acceptances | files outside/partial |"
    lines = [head, "|---|---:|---:|---:|---:|---:|"]
    for r in [*rows, total_of(rows)]:
        kinds = f" ({', '.join(f'{k} {v}' for k, v in sorted(r.kinds.items()))})" if r.kinds else ""
        lines.append(
            f"| {r.name} | {r.cases} | {r.tracebacks}{kinds} | {r.hangs} | {r.wrong} | "
            f"{r.outside} |"
        )
    return "\n".join(lines)


def total_of(rows: list[Surface]) -> Surface:
    total = Surface("**all**")
    for r in rows:
        total.cases += r.cases
        total.tracebacks += r.tracebacks
        total.hangs += r.hangs
        total.wrong += r.wrong
        total.outside += r.outside
    return total
