"""An external program as an agent, speaking JSON lines on stdin/stdout.

So that agents written in any framework or language plug in. The program is started once per
episode (``options["command"]``, split like a shell would but never run through one) and gets,
one JSON object per line:

- ``{"type": "start", "level": {...}, "seed": S}``: a new episode (id, family, difficulty, goal,
  step budget and piece names);
- ``{"type": "turn", "mode": "act" | "plan", "turn": i, "sample": k, "candidate": c,
  "text": ..., "feedback": ..., "steps_left": n, "images": {"front": "/abs/path.png", ...}}``:
  answer with one line ``{"action": "..."}`` (mode ``act``) or ``{"actions": [...]}`` (mode
  ``plan``), optionally with ``"text"`` (logged) and ``"usage"`` (token counts, same keys as the
  logs);
- ``{"type": "end"}``, after which stdin is closed.

A line that is not a JSON object, or has no action, is an unparseable step; a program that exits
or stays silent past ``timeout`` seconds is an :class:`AgentError` for the episode.
"""

from __future__ import annotations

import hashlib
import json
import queue
import shlex
import subprocess
import tempfile
import threading
from collections.abc import Mapping
from pathlib import Path
from typing import IO, Any

from chaingeo.core.level import Level
from chaingeo.evaluation.agents.base import Agent, AgentError, Reply, Turn
from chaingeo.evaluation.agents.prompt import observation_text
from chaingeo.evaluation.usage import Usage


class CommandAgent(Agent):
    name = "command"

    def __init__(self, options: Mapping[str, Any]) -> None:
        command = options.get("command")
        if not command:
            raise ValueError(
                "the command agent needs a program to run (--agent-option command=...)"
            )
        self.argv = shlex.split(str(command)) if isinstance(command, str) else list(command)
        self.timeout = float(options.get("timeout", 300.0))
        self.uses_images = bool(options.get("images", True))
        self._proc: subprocess.Popen[str] | None = None
        self._lines: queue.Queue[str | None] = queue.Queue()
        self._images = tempfile.TemporaryDirectory(prefix="chain-command-")

    def start(self, level: Level, seed: int) -> None:
        self.close()
        try:
            self._proc = subprocess.Popen(
                self.argv,
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                stderr=subprocess.DEVNULL,
                text=True,
                bufsize=1,
            )
        except OSError as e:
            raise AgentError(f"cannot start {self.argv[0]!r}: {e.strerror or e}") from None
        self._lines = queue.Queue()
        assert self._proc.stdout is not None
        threading.Thread(target=_pump, args=(self._proc.stdout, self._lines), daemon=True).start()
        self._send(
            {
                "type": "start",
                "seed": seed,
                "level": {
                    "id": level.id,
                    "family": level.family,
                    "difficulty": level.difficulty,
                    "goal": level.goal,
                    "max_steps": level.max_steps,
                    "pieces": [p.name for p in level.pieces],
                },
            }
        )

    def _send(self, obj: Mapping[str, Any]) -> None:
        if self._proc is None or self._proc.stdin is None:
            raise AgentError("the agent program is not running")
        try:
            self._proc.stdin.write(json.dumps(obj) + "\n")
            self._proc.stdin.flush()
        except (BrokenPipeError, OSError):
            raise AgentError(f"the agent program {self.argv[0]!r} exited") from None

    def _receive(self) -> str:
        try:
            line = self._lines.get(timeout=self.timeout)
        except queue.Empty:
            raise AgentError(f"the agent program was silent for {self.timeout}s") from None
        if line is None:
            raise AgentError(f"the agent program {self.argv[0]!r} exited")
        return line

    def _ask(self, turn: Turn, mode: str) -> tuple[str, dict[str, Any] | None, Usage]:
        images: dict[str, str] = {}
        text = ""
        steps_left = None
        if turn.observation is not None:
            text = observation_text(turn.observation)
            steps_left = turn.observation.steps_left
            if self.uses_images:
                for view, png in turn.observation.images.items():
                    path = Path(self._images.name) / (hashlib.sha256(png).hexdigest() + ".png")
                    if not path.exists():
                        path.write_bytes(png)
                    images[view] = str(path)
        self._send(
            {
                "type": "turn",
                "mode": mode,
                "turn": turn.index,
                "sample": turn.sample,
                "candidate": turn.candidate,
                "text": text,
                "feedback": turn.last_feedback,
                "steps_left": steps_left,
                "images": images,
            }
        )
        line = self._receive()
        try:
            obj = json.loads(line)
        except json.JSONDecodeError:
            return line, None, Usage()
        if not isinstance(obj, dict):
            return line, None, Usage()
        usage = Usage.from_json(obj["usage"]) if isinstance(obj.get("usage"), dict) else Usage()
        return str(obj.get("text", line)), obj, usage

    def act(self, turn: Turn) -> Reply:
        text, obj, usage = self._ask(turn, "act")
        action = obj.get("action") if obj else None
        if isinstance(action, str) and action.strip():
            return Reply(text, " ".join(action.split()), usage)
        return Reply(text, None, usage, note='the program\'s line had no "action" string')

    def plan(self, turn: Turn) -> Reply:
        text, obj, usage = self._ask(turn, "plan")
        actions = obj.get("actions") if obj else None
        if isinstance(actions, list):
            return Reply(text, None, usage, actions=tuple(str(a) for a in actions))
        return Reply(text, None, usage, note='the program\'s line had no "actions" list')

    def close(self) -> None:
        proc, self._proc = self._proc, None
        if proc is None:
            return
        try:
            if proc.stdin is not None and proc.poll() is None:
                proc.stdin.write(json.dumps({"type": "end"}) + "\n")
                proc.stdin.close()
        except OSError:
            pass
        try:
            proc.wait(timeout=5)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()

    def __del__(self) -> None:
        self.close()


def _pump(stream: IO[str], out: queue.Queue[str | None]) -> None:
    for line in stream:
        if line.strip():
            out.put(line.rstrip("\n"))
    out.put(None)
