"""Golden playthroughs: recorded agent texts and the exact feedback each gets.

Each ``tests/golden/*.txt`` names its level file, then lists turns as ``> text`` followed by
``< feedback``, and ends with the outcome. The test replays the texts and rebuilds the file;
it must match byte for byte. After a deliberate change of wording, regenerate with
``CHAIN_UPDATE_GOLDEN=1 python -m pytest tests/conformance/test_golden.py`` and review the diff.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from chaingeo.core.level import load_level
from chaingeo.envs.machines import new_state
from tests.support.paths import GOLDEN


def replay(path: Path) -> str:
    lines = path.read_text(encoding="utf-8").splitlines()
    header = [line for line in lines if line.startswith("# ") and not line.startswith("# end")]
    level_line = next(line for line in header if line.startswith("# level: "))
    level = load_level(GOLDEN / level_line.removeprefix("# level: "))
    state = new_state(level)
    out = list(header)
    for line in lines:
        if line.startswith("> "):
            text = line[2:]
            result = state.step_text(text)
            out += [f"> {text}", f"< {result.feedback}"]
    out.append(
        f"# end: success={state.is_success()} steps={state.steps_used}/{state.max_steps} "
        f"optimal={level.optimal_steps}"
    )
    return "\n".join(out) + "\n"


@pytest.mark.parametrize("path", sorted(GOLDEN.glob("*.txt")), ids=lambda p: p.stem)
def test_golden_playthrough(path: Path) -> None:
    got = replay(path)
    if os.environ.get("CHAIN_UPDATE_GOLDEN") == "1":
        path.write_bytes(got.encode("utf-8"))
    assert got.encode("utf-8") == path.read_bytes()


def test_there_are_goldens_for_both_families() -> None:
    names = {p.stem for p in GOLDEN.glob("*.txt")}
    assert {"soma", "drop", "lock3-disassemble", "lock3-assemble"} <= names
