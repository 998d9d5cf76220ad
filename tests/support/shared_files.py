"""Where the files provided beside the project live (``../shared``); tests skip without them."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from tests.support.paths import ROOT


def shared_dir(name: str, variable: str) -> Path | None:
    """``$variable`` if set, else ``../shared/NAME`` beside the checkout; None when absent."""
    env = os.environ.get(variable)
    path = Path(env) if env else ROOT.parent / "shared" / name
    return path if path.is_dir() else None


#: CHAIN's published models (``../shared/chain-models``).
MODELS = shared_dir("chain-models", "CHAIN_MODELS_DIR")
needs_models = pytest.mark.skipif(MODELS is None, reason="../shared/chain-models is not present")
#: BurrTools' example files (``../shared/burrtools``).
BT = shared_dir("burrtools", "CHAIN_BURRTOOLS_DIR")
needs_files = pytest.mark.skipif(BT is None, reason="../shared/burrtools is not present")
