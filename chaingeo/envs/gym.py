"""Gymnasium environments: ``chaingeo/Stacking-v0`` and ``chaingeo/Puzzle-v0``.

Importing this module registers both ids (``import chaingeo.envs.gym``, or
``gymnasium.make("chaingeo.envs.gym:chaingeo/Stacking-v0")``, which imports it). Each wraps the
state machine of :mod:`chaingeo.envs.state`, so its steps are the agents' and the solvers' steps.

* ``reset(seed=..., options={"level": id})`` starts a level: the one named, else one drawn
  with the environment's seeded generator from the levels it was given (default: the shipped
  ``levels/`` folder, filtered by family).
* Actions are text, exactly what an agent writes (``place red (1,1,1) ...``, ``move red +x 2``,
  ``finish``). The action space is ``Text(max_length=ACTION_MAX_LENGTH, charset=CHARSET)``:
  printable ASCII plus newline, long enough for a placement of 64 cells; a sampled string is
  almost always unparseable, which the environment answers like any other unreadable action.
* Observations are a dict: ``text`` (instruction, pieces, recent turns, steps left, and with
  ``text_state=True`` every piece's cells; characters outside the charset become ``?``) and,
  with ``images=True``, ``images``: one ``uint8`` array ``(H, W, 3)`` per view.
* Reward 1 on the step that solves the level, else 0. ``terminated`` when the level is solved
  or ``finish`` was played; ``truncated`` when the step budget is spent.
* ``info``: ``legal``, ``error`` (None, "unparseable", "illegal", "ambiguous"), ``code``
  (CHAIN's error name of an illegal stacking action, else None), ``feedback``,
  ``steps_used``, ``level_id``, ``optimal_steps``, ``success``. Stacking levels also give
  ``action_mask`` (``int8``) over :meth:`ChainEnv.action_catalogue`, every action that can
  ever be legal in the level, in sorted order. Puzzle moves are not enumerable up front (the
  distances depend on the position), so the puzzle environment gives ``legal_actions`` (their
  texts) instead when built with ``list_legal_actions=True``.
"""

from __future__ import annotations

import io
import string
from collections.abc import Sequence
from pathlib import Path
from typing import Any, ClassVar, Final

import gymnasium
import numpy as np
from gymnasium import spaces

from chaingeo.core.level import Level, load_levels
from chaingeo.core.suite import shipped_levels
from chaingeo.envs.machines import new_state
from chaingeo.envs.observation import DEFAULT_HISTORY, VIEWS, observe, render_state
from chaingeo.envs.state import BaseState

#: Characters of text actions and observations: printable ASCII and newline.
CHARSET: Final = frozenset(c for c in string.printable if c not in "\x0b\x0c\r")
ACTION_MAX_LENGTH: Final = 1024
OBSERVATION_MAX_LENGTH: Final = 1 << 16
DEFAULT_LEVELS: Final = shipped_levels()


def _ascii(text: str) -> str:
    return "".join(c if c in CHARSET else "?" for c in text)


def _decode_png(data: bytes) -> np.ndarray[Any, np.dtype[np.uint8]]:
    from PIL import Image

    with Image.open(io.BytesIO(data)) as img:
        return np.asarray(img.convert("RGB"), dtype=np.uint8).copy()


class ChainEnv(gymnasium.Env[dict[str, Any], str]):
    """One family's levels behind the Gymnasium API (see the module docstring)."""

    metadata: dict[str, Any] = {"render_modes": []}  # noqa: RUF012 (Gymnasium's own type)
    family: ClassVar[str] = ""

    def __init__(
        self,
        levels: Sequence[Level] | str | Path | None = None,
        *,
        history_window: int = DEFAULT_HISTORY,
        text_state: bool = False,
        images: bool = True,
        image_size: int = 256,
        list_legal_actions: bool = False,
    ) -> None:
        super().__init__()
        source = DEFAULT_LEVELS if levels is None else levels
        loaded = load_levels(source) if isinstance(source, str | Path) else list(source)
        self.levels: dict[str, Level] = {
            lv.id: lv for lv in sorted(loaded, key=lambda lv: lv.id) if lv.family == self.family
        }
        if not self.levels:
            raise ValueError(f"no {self.family} levels in {source!s}; pass levels=[...]")
        self.history_window = history_window
        self.text_state = text_state
        self.images = images
        self.image_size = image_size
        self.list_legal_actions = list_legal_actions
        self._templates: dict[str, BaseState] = {}
        self._state: BaseState | None = None
        self.action_space = spaces.Text(ACTION_MAX_LENGTH, min_length=0, charset=CHARSET)
        obs: dict[str, spaces.Space[Any]] = {
            "text": spaces.Text(OBSERVATION_MAX_LENGTH, min_length=0, charset=CHARSET)
        }
        if images:
            probe = self._start(next(iter(self.levels)))
            shapes = {
                v: _decode_png(png).shape for v, png in render_state(probe, image_size).items()
            }
            obs["images"] = spaces.Dict(
                {v: spaces.Box(0, 255, shape=s, dtype=np.uint8) for v, s in shapes.items()}
            )
        self.observation_space = spaces.Dict(obs)

    # -- helpers ------------------------------------------------------------------------------
    def _start(self, level_id: str) -> BaseState:
        if level_id not in self._templates:
            self._templates[level_id] = new_state(self.levels[level_id])
        return self._templates[level_id].clone()

    @property
    def state(self) -> BaseState:
        if self._state is None:
            raise RuntimeError("call reset() first")
        return self._state

    def action_catalogue(self) -> list[str]:
        """Stacking: every action that can ever be legal in the current level (the mask's
        index); puzzles: empty (not enumerable up front)."""
        from chaingeo.envs.stacking import StackingState

        state = self.state
        if isinstance(state, StackingState):
            return [a.to_text() for a in state.catalogue()]
        return []

    def _observation(self) -> dict[str, Any]:
        obs = observe(
            self.state,
            history_window=self.history_window,
            text_state=self.text_state,
            images=self.images,
            image_size=self.image_size,
        )
        text = _ascii(obs.to_text())
        if len(text) > OBSERVATION_MAX_LENGTH:
            raise RuntimeError(f"observation text of {len(text)} characters exceeds the space")
        out: dict[str, Any] = {"text": text}
        if self.images:
            out["images"] = {v: _decode_png(png) for v, png in obs.images.items()}
        return out

    def _info(self, result: Any | None) -> dict[str, Any]:
        from chaingeo.envs.stacking import StackingState

        state = self.state
        info: dict[str, Any] = {
            "level_id": state.level.id,
            "optimal_steps": state.level.optimal_steps,
            "steps_used": state.steps_used,
            "success": state.is_success(),
            "legal": True if result is None else result.legal,
            "error": None if result is None else result.error,
            "code": None if result is None else result.code,
            "feedback": "" if result is None else result.feedback,
        }
        if isinstance(state, StackingState):
            legal = set(state.legal_actions())
            info["action_mask"] = np.array([a in legal for a in state.catalogue()], dtype=np.int8)
        elif self.list_legal_actions:
            info["legal_actions"] = [a.to_text() for a in state.legal_actions()]
        return info

    # -- the Gymnasium API --------------------------------------------------------------------
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Any], dict[str, Any]]:
        super().reset(seed=seed)
        wanted = (options or {}).get("level")
        ids = list(self.levels)
        if wanted is None:
            level_id = ids[int(self.np_random.integers(len(ids)))]
        elif wanted in self.levels:
            level_id = str(wanted)
        else:
            raise ValueError(f"unknown {self.family} level {wanted!r}")
        self._state = self._start(level_id)
        return self._observation(), self._info(None)

    def step(self, action: str) -> tuple[dict[str, Any], float, bool, bool, dict[str, Any]]:
        state = self.state
        if state.is_success() or state.finished:
            raise RuntimeError("the episode has ended; call reset()")
        result = state.step_text(str(action))
        terminated = state.is_success() or state.finished
        truncated = state.is_truncated() and not terminated
        reward = 1.0 if result.success and result.legal else 0.0
        return self._observation(), reward, terminated, truncated, self._info(result)


class StackingEnv(ChainEnv):
    family = "stacking"


class PuzzleEnv(ChainEnv):
    family = "puzzle"


ENV_IDS: Final = {"chaingeo/Stacking-v0": StackingEnv, "chaingeo/Puzzle-v0": PuzzleEnv}


def register_envs() -> None:
    """Register both ids with Gymnasium (idempotent)."""
    for env_id, cls in ENV_IDS.items():
        if env_id not in gymnasium.registry:
            gymnasium.register(id=env_id, entry_point=f"{__name__}:{cls.__name__}")


register_envs()

__all__ = ["CHARSET", "ENV_IDS", "VIEWS", "ChainEnv", "PuzzleEnv", "StackingEnv", "register_envs"]
