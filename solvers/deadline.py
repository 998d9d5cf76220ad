"""The wall-clock budget of one analysis, shared by every search in it.

One :class:`Deadline` is made per analysis (``SearchLimits.seconds``) and handed down to every
search it runs: the exact-cover enumeration of assemblies
(:class:`chaingeo.solvers.cover.search.CoverSearch`) and the disassembly searches
(:mod:`chaingeo.solvers.motion.disassemble`, :mod:`chaingeo.solvers.motion.partsearch`). Numba
kernels cannot read the clock, so each of them stops after a budget of work and the Python side
checks the deadline between two calls.
"""

from __future__ import annotations

import math
import time

from chaingeo.core.kinematics import SearchLimitError


class Progress:
    """What an analysis is doing now (``stage``) and its running counts, written by the
    searches as they go and read by a front end that reports progress (from another thread:
    plain attribute writes, read as a snapshot)."""

    def __init__(self) -> None:
        self.stage = ""
        self.counts: dict[str, int] = {}
        self.workers: dict[int, float] = {}  # CPU seconds of counting, per process id

    def text(self) -> str:
        counts = ", ".join(f"{k} {v}" for k, v in self.counts.items())
        return f"{self.stage} ({counts})" if counts else self.stage


class Deadline:
    """The wall-clock budget shared by every search of one analysis (None: no time limit),
    with the analysis' :class:`Progress`. ``ValueError`` for a negative or NaN number of
    seconds (NaN would never expire). ``stated`` is the limit its error names when this
    deadline is what is left of a longer one (a whole command's ``--seconds``)."""

    def __init__(
        self, seconds: float | None, cap: str = "seconds", stated: float | None = None
    ) -> None:
        if seconds is not None and (math.isnan(seconds) or seconds < 0):
            raise ValueError(f"seconds: a time limit must be >= 0, got {seconds}")
        self.seconds = seconds
        self.stated = seconds if stated is None else stated
        self.cap = cap  # the field of SearchLimits this time limit is
        self.start = time.monotonic()
        self.end = None if seconds is None else self.start + seconds
        self.progress = Progress()

    def within(self, seconds: float | None, cap: str) -> Deadline:
        """A deadline of at most ``seconds`` (None: this one's) that never outlasts this one,
        sharing its progress; when it is the shorter, its error names ``cap``."""
        if seconds is None:
            return self
        if self.end is not None and self.end - time.monotonic() <= seconds:
            return self
        inner = Deadline(seconds, cap)
        inner.progress = self.progress
        return inner

    @property
    def bounded(self) -> bool:
        """Whether there is a time limit at all."""
        return self.end is not None

    def expired(self) -> bool:
        return self.end is not None and time.monotonic() > self.end

    def error(self, where: str = "") -> SearchLimitError:
        """The error that names this cap (``where``: what was running, for the message)."""
        at = f" in {where}" if where else ""
        return SearchLimitError(f"time limit of {self.stated:g} s reached{at}", self.cap)

    def check(self) -> None:
        if self.expired():
            raise self.error()


def deadline_of(seconds: float | None, deadline: Deadline | None) -> Deadline:
    """``deadline`` when the caller shares one, else a new one of ``seconds``."""
    return Deadline(seconds) if deadline is None else deadline
