"""CHAIN-geo in ten lines: load, step, analyse, count, read BurrTools."""

import chaingeo

level = chaingeo.load_level("puzzle-easy-07-burr3")  # a shipped level by id (or a file path)
state = chaingeo.new_state(level)  # its state machine, at the start
action = state.legal_actions()[0].to_text()  # a legal action, as an agent would write it
print(action, "->", state.step_text(action).feedback)  # step it; the machine's feedback
figures = chaingeo.analyze(level)  # BurrTools level, moves and o_i (optimal steps)
print(figures.level, figures.moves, figures.o_i)
soma = chaingeo.PIECESETS["soma"].pieces  # the seven Soma cube pieces
print(chaingeo.count_packings(soma, (3, 3, 3)).distinct)  # into a 3x3x3 box: 240
puzzle = chaingeo.read_burrtools(chaingeo.EXAMPLES / "soma_problems.xmpuzzle")  # a BurrTools file
print(chaingeo.analyze(puzzle, problem=0).to_json())  # the line `chain analyze` prints
