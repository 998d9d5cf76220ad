"""Shared fixtures; hypothesis runs derandomised so CI is repeatable."""

from __future__ import annotations

import sys
from typing import Any

from hypothesis import settings

settings.register_profile("ci", derandomize=True, deadline=None, max_examples=100)
settings.load_profile("ci")


def pytest_terminal_summary(terminalreporter: Any) -> None:
    """The burrTxt differential tests' counts (tests/test_burrtxt_diff.py), when they ran."""
    module = sys.modules.get("tests.burrtxt")
    lines = module.summary_lines() if module is not None else []
    if lines:
        terminalreporter.write_sep("-", "BurrTools (burrTxt) differential")
        for line in lines:
            terminalreporter.write_line(line)
