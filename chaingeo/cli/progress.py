"""Progress of a long command on standard error: silent for the first few seconds, then a line
every few seconds saying how long it has run and what it is doing, so a long analysis is never
a silent one. The work writes a :class:`chaingeo.solvers.deadline.Progress`; a daemon thread reads
it."""

from __future__ import annotations

import sys
import threading
import time
from types import TracebackType
from typing import TYPE_CHECKING, Final, TextIO

if TYPE_CHECKING:
    from chaingeo.solvers.deadline import Progress

#: Seconds of quiet before the first line, and between two lines.
FIRST_AFTER: Final = 3.0
EVERY: Final = 5.0


class ProgressLines:
    """``with ProgressLines(label, progress): ...`` prints ``label: 8 s, <stage> (<counts>)``."""

    def __init__(
        self,
        label: str,
        progress: Progress,
        *,
        first_after: float = FIRST_AFTER,
        every: float = EVERY,
        stream: TextIO | None = None,
    ) -> None:
        self.label = label
        self.progress = progress
        self.first_after = first_after
        self.every = every
        self.stream = stream if stream is not None else sys.stderr
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="progress", daemon=True)
        self._start = time.monotonic()

    def __enter__(self) -> ProgressLines:
        self._start = time.monotonic()
        self._thread.start()
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        error: BaseException | None,
        trace: TracebackType | None,
    ) -> None:
        self._stop.set()
        self._thread.join()

    def _run(self) -> None:
        wait = self.first_after
        while not self._stop.wait(wait):
            elapsed = time.monotonic() - self._start
            print(f"{self.label}: {elapsed:.0f} s, {self.progress.text()}", file=self.stream)
            self.stream.flush()
            wait = self.every
