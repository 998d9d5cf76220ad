"""BurrTools' own example files beyond the two in ``../shared/burrtools`` (test data only, never
in the project): ``$CHAIN_BURRTOOLS_EXAMPLES`` names a folder holding them (e.g. the
``examples/`` of a local copy of BurrTools); tests that need one skip when it is absent."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from tests.support.shared_files import BT

ENV = "CHAIN_BURRTOOLS_EXAMPLES"


def example(name: str) -> Path:
    """``NAME.xmpuzzle`` from ``$CHAIN_BURRTOOLS_EXAMPLES`` or ``../shared/burrtools``; the
    test skips when neither has it."""
    folders = [Path(os.environ[ENV])] if os.environ.get(ENV) else []
    folders += [BT] if BT is not None else []
    for folder in folders:
        path = folder / f"{name}.xmpuzzle"
        if path.is_file():
            return path
    pytest.skip(f"BurrTools' {name}.xmpuzzle is not present (set ${ENV})")
