"""Shared fixtures; hypothesis runs derandomised so CI is repeatable. Also the burrTxt
differential tests' counts, gathered from every pytest-xdist worker and printed once."""

from __future__ import annotations

import dataclasses
import os
import sys
import tempfile
from pathlib import Path
from typing import Any

import pytest
from hypothesis import settings

from chaingeo.kernels import aot

settings.register_profile("ci", derandomize=True, deadline=None, max_examples=100)
settings.load_profile("ci")

#: The kernels ``chain precompile`` stored for this user (what tests/kernels/test_aot.py checks).
#: Every other test, and every ``chain`` it starts, sees an empty store, so that what
#: ``--jit auto`` chooses does not depend on whether this machine has precompiled.
USER_KERNELS = aot.store_dir()
os.environ[aot.DIR_ENV] = os.path.join(tempfile.mkdtemp(prefix="chaingeo-tests-"), "no-kernels")


@pytest.fixture
def user_kernels() -> Path:
    """The user's precompiled kernels (skips when there are none usable)."""
    found = aot.status(USER_KERNELS)
    if not found.usable:
        pytest.skip(f"{USER_KERNELS}: {found.sentence}")
    return USER_KERNELS


#: Outcomes the workers sent back (the controller's list; empty without xdist).
_FROM_WORKERS: list[dict[str, str]] = []


def _local_outcomes() -> list[Any]:
    module = sys.modules.get("tests.support.burrtxt")
    return list(module.OUTCOMES) if module is not None else []


def pytest_sessionfinish(session: pytest.Session) -> None:
    """A worker hands its differential outcomes to the controller."""
    output = getattr(session.config, "workeroutput", None)
    if output is not None:
        output["burrtxt"] = [dataclasses.asdict(o) for o in _local_outcomes()]


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node: Any, error: Any) -> None:
    """The controller keeps what a finished worker sent (pytest-xdist's hook)."""
    _FROM_WORKERS.extend(getattr(node, "workeroutput", {}).get("burrtxt", []))


def pytest_terminal_summary(terminalreporter: Any) -> None:
    """The burrTxt differential tests' counts (conformance/test_burrtxt_diff.py), when they ran."""
    outcomes = _local_outcomes()
    if _FROM_WORKERS:
        from tests.support.burrtxt import Outcome

        outcomes += [Outcome(**o) for o in _FROM_WORKERS]
    if not outcomes:
        return
    from tests.support.burrtxt import summary_lines

    terminalreporter.write_sep("-", "BurrTools (burrTxt) differential")
    for line in summary_lines(outcomes):
        terminalreporter.write_line(line)
