import tempfile
from pathlib import Path

from chaingeo.core.formats.bt_level import level_puzzle
from chaingeo.core.formats.burrtools import read_xmpuzzle, write_xmpuzzle
from chaingeo.core.level import load_level
from chaingeo.core.piecesets import get_pieceset
from chaingeo.core.suite import shipped_levels
from chaingeo.envs.machines import new_state
from chaingeo.solvers.analysis import analyze_level
from chaingeo.solvers.cover.packings import count_packings

level = load_level(shipped_levels("puzzle") / "puzzle-easy-01-luban-3-piece.json")
state = new_state(level)  # the state machine an agent plays
result = state.step_text(state.legal_actions()[0].to_text())  # one turn, one step
print(result.feedback, state.steps_used)

analysis = analyze_level(level)  # BurrTools' level string and o_i, the optimal plan length
print(analysis.level, analysis.optimal_steps)

soma = get_pieceset("soma").pieces
print(count_packings(soma, (3, 3, 3)).solutions)  # the Soma cube's packings

with tempfile.TemporaryDirectory() as tmp:  # a BurrTools file, written and read back
    puzzle = read_xmpuzzle(write_xmpuzzle(level_puzzle(level), Path(tmp) / "lock.xmpuzzle"))
    print(len(puzzle.shapes), "shapes,", len(puzzle.problems), "problem")
