"""``chain play LEVEL``: play a level in the terminal with the agents' own action text.

After every turn it prints the feedback (the very text an agent gets), the state with every
piece's cells (1-based) and the paths of the freshly rendered views. ``undo`` takes back the
last action that was carried out and gives back the one step it cost; a refused turn changed
nothing, so there is nothing of it to undo and its step stays counted (every turn is a step, as
for an agent). So "Steps used" is always the turns taken minus the actions undone. ``undo``
is not a turn. ``help`` repeats the task; ``quit`` (or end of input) stops. Exit status 0 when
solved, else 1.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path
from typing import Any, TextIO

from chaingeo.cli.level_arg import add_level, find_level


def register(sub: Any) -> None:
    p = sub.add_parser("play", help="play a level in the terminal (same actions as an agent)")
    add_level(p, help="a chain-level/1 file or the id of a level under --levels")
    p.add_argument(
        "--levels",
        type=Path,
        default=None,
        metavar="DIR",
        help="folder to look ids up in (default: the shipped suite)",
    )
    p.add_argument(
        "--views",
        type=Path,
        default=None,
        metavar="DIR",
        help="folder (created when missing): the rendered views (default: a temporary one)",
    )
    p.add_argument("--no-images", action="store_true", help="do not render views")
    p.add_argument("--size", type=int, default=512, help="image size in pixels")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    level = find_level(args.level, args.levels)
    views = None
    if not args.no_images:
        views = args.views or Path(tempfile.mkdtemp(prefix=f"chain-play-{level.id}-"))
    return play(level, sys.stdin, sys.stdout, views, args.size)


def _undo(state: Any) -> str:
    """Take back the last action carried out (see the module doc) and say what happened."""
    refused = bool(state.history) and not state.history[-1].legal
    note = " (refused turns change nothing and keep their steps)" if refused else ""
    try:
        undone = state.pop()
    except IndexError:
        return f"Nothing to undo: no action has been carried out{note}."
    if refused:
        note = " (your last turn was refused and changed nothing; this was the last action "
        note += "carried out, and the refused turns keep their steps)"
    return f"Undone: {undone.to_text()}{note}"


def play(level: Any, stdin: TextIO, out: TextIO, views: Path | None, size: int = 512) -> int:
    """The game loop (separate from argument handling so tests can drive it)."""
    from chaingeo.envs.machines import new_state
    from chaingeo.envs.observation import instruction, render_state, state_text

    state = new_state(level)

    def show() -> None:
        print(state_text(state), file=out)
        print(f"Steps used: {state.steps_used} of {state.max_steps}", file=out)
        if views is not None:
            views.mkdir(parents=True, exist_ok=True)
            for name, png in render_state(state, size).items():
                path = views / f"{name}.png"
                path.write_bytes(png)
                print(f"view {name}: {path}", file=out)
        print("> ", end="", file=out, flush=True)

    print(f"Level {level.id} ({level.family}, {level.goal}, {level.difficulty})", file=out)
    print(instruction(state), file=out)
    print("Type an action, 'undo', 'help' or 'quit'.", file=out)
    show()
    for line in stdin:
        text = line.strip()
        if not text:
            print("> ", end="", file=out, flush=True)
            continue
        word = text.lower()
        if word in ("quit", "exit"):
            break
        if word == "help":
            print(instruction(state), file=out)
        elif word == "undo":
            print(_undo(state), file=out)
        else:
            result = state.step_text(text)
            print(result.feedback, file=out)
            if result.success:
                print(
                    f"Solved in {state.steps_used} steps (optimal: {level.optimal_steps}).",
                    file=out,
                )
                return 0
            if state.finished:
                return 1
            if result.truncated:
                print(f"Out of steps ({state.max_steps}).", file=out)
                return 1
        show()
    print("", file=out)
    return 0 if state.is_success() else 1
