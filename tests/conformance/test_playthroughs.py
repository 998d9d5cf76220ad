"""Golden playthroughs per rule variant, like OpenSpiel's ``playthroughs/``: one fixed, seeded
playthrough for each variant of the rules (stacking with contact, drop and CHAIN's profile;
puzzles to assemble, to take apart, one piece at a time, with turns), recording at every step
the observation text an agent reads (no images; with the text state), the number of listed
legal actions, the action's canonical text and the feedback it gets. The recording must match
``tests/golden/playthroughs/VARIANT.txt`` byte for byte, so any change of wording, of the
legal actions or of their order shows up as a diff.

After a deliberate change, regenerate with
``CHAIN_UPDATE_GOLDEN=1 python -m pytest tests/conformance/test_playthroughs.py``
and review the diff (the same variable regenerates ``tests/conformance/test_golden.py``)."""

from __future__ import annotations

import os
from dataclasses import replace

import numpy as np
import pytest

from chaingeo.core.level import Level, load_level, load_levels
from chaingeo.core.rules import PuzzleRules, StackingRules
from chaingeo.envs.machines import new_state
from chaingeo.envs.machines.state import BaseState
from chaingeo.envs.observation import observe
from tests.support.paths import GOLDEN, LEVELS

PLAYTHROUGHS = GOLDEN / "playthroughs"
SEED = 2026
STEPS = 8
#: Turns at which the agent types something unreadable instead (its refusal is recorded too).
JUNK_AT = {2: "move ??? +x 1"}


#: Each rule variant: a recorded golden level and the rules it is played under.
VARIANTS: dict[str, tuple[str, StackingRules | PuzzleRules]] = {
    "stacking-contact": ("soma", StackingRules()),
    "stacking-drop": ("drop", StackingRules(support="drop")),
    "stacking-chain": ("soma", StackingRules(profile="chain")),
    "puzzle-assemble": ("lock3-assemble", PuzzleRules()),
    "puzzle-disassemble": ("lock3-disassemble", PuzzleRules()),
    "puzzle-single": ("lock3-disassemble", PuzzleRules(max_group=1)),
    "puzzle-turns": ("lock3-disassemble", PuzzleRules(turns=True)),
}


def _level(variant: str) -> Level:
    name, rules = VARIANTS[variant]
    return replace(load_level(GOLDEN / "levels" / f"{name}.json"), rules=rules)


def _observation(state: BaseState, instruction: str) -> str:
    """The observation text; the instruction is written out only where it changed."""
    text = observe(state, images=False, text_state=True).to_text()
    return text.replace(instruction, "(instruction as above)", 1) if instruction else text


def _choice(state: BaseState, rng: np.random.Generator) -> str:
    """A seeded legal action other than ``finish`` (unless that is all there is), as text."""
    texts = [a.to_text() for a in state.legal_actions()]
    moves = [t for t in texts if t != "finish"] or texts
    return moves[int(rng.integers(len(moves)))]


def playthrough(variant: str) -> str:
    """The recording of ``variant``'s seeded playthrough."""
    name = VARIANTS[variant][0]
    level = _level(variant)
    state = new_state(level)
    rng = np.random.default_rng(np.random.SeedSequence([SEED, STEPS]))
    out = [
        f"# Golden playthrough: rule variant {variant}, level {name}, {level.rules}, seed {SEED}",
    ]
    instruction = ""
    for step in range(STEPS):
        out += [f"## observation {step}", _observation(state, instruction)]
        instruction = instruction or observe(state, images=False).instruction
        if state.finished or not state.legal_actions():
            break
        out.append(f"## legal actions: {len(state.legal_actions())}")
        text = JUNK_AT.get(step) or _choice(state, rng)
        out += [f"> {text}", f"< {state.step_text(text).feedback}"]
    out.append(f"# end: success={state.is_success()} steps={state.steps_used}/{state.max_steps}")
    return "\n".join(out) + "\n"


@pytest.mark.parametrize("variant", sorted(VARIANTS))
def test_golden_playthrough_per_rule_variant(variant: str) -> None:
    path = PLAYTHROUGHS / f"{variant}.txt"
    got = playthrough(variant).encode("utf-8")
    if os.environ.get("CHAIN_UPDATE_GOLDEN") == "1":
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(got)
    assert path.is_file(), f"no recording: run with CHAIN_UPDATE_GOLDEN=1 to write {path}"
    assert got == path.read_bytes()


def test_every_rule_variant_has_a_playthrough_and_no_recording_is_stale() -> None:
    levels = {v: _level(v) for v in VARIANTS}
    assert all(lv.family == v.split("-")[0] for v, lv in levels.items())
    goals = {lv.goal for lv in levels.values()}
    assert {"pack", "assemble", "disassemble"} <= goals
    shipped = {str(lv.rules) for lv in load_levels(LEVELS)} if LEVELS.is_dir() else set()
    assert shipped <= {str(lv.rules) for lv in levels.values()}, (
        "a shipped variant has no playthrough"
    )
    assert {p.stem for p in PLAYTHROUGHS.glob("*.txt")} == set(VARIANTS)
