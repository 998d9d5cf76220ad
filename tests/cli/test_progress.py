"""Progress lines of long commands: quiet at first, then the stage and counts the work wrote."""

from __future__ import annotations

import io
import time

from chaingeo.cli.progress import ProgressLines
from chaingeo.solvers.deadline import Deadline


def test_quiet_first_then_stage_and_counts() -> None:
    progress = Deadline(None).progress
    stream = io.StringIO()
    with ProgressLines("job", progress, first_after=0.2, every=0.05, stream=stream):
        progress.stage = "counting assemblies"
        progress.counts.update(assemblies=3, solutions=1)
        time.sleep(0.1)
        assert stream.getvalue() == ""  # nothing in the first seconds
        time.sleep(0.3)
    lines = stream.getvalue().splitlines()
    assert len(lines) >= 2
    assert all(line.startswith("job: ") for line in lines)
    assert lines[-1].endswith("s, counting assemblies (assemblies 3, solutions 1)")


def test_a_short_job_prints_nothing_and_leaves_no_thread() -> None:
    stream = io.StringIO()
    lines = ProgressLines("job", Deadline(1.0).progress, first_after=5.0, stream=stream)
    t0 = time.monotonic()
    with lines:
        pass
    assert time.monotonic() - t0 < 1.0 and stream.getvalue() == ""
    assert not lines._thread.is_alive()
