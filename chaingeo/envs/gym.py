"""Gymnasium environments: ``chaingeo/Stacking-v0`` and ``chaingeo/Puzzle-v0``.

Importing this module registers both ids (``import chaingeo.envs.gym``, or
``gymnasium.make("chaingeo.envs.gym:chaingeo/Stacking-v0")``, which imports it). Each wraps the
state machine of :mod:`chaingeo.envs.machines.state`, so its steps are the agents' and the solvers'
steps.

* ``reset(seed=..., options={"level": id})`` starts a level: the one named, else one drawn
  with the environment's seeded generator from the levels it was given (default: the shipped
  ``levels/`` folder, filtered by family).
* Actions are text, exactly what an agent writes (``place red (1,1,1) ...``, ``move red +x 2``,
  ``finish``). The action space is ``Text(max_length=ACTION_MAX_LENGTH, charset=CHARSET)``:
  printable ASCII plus newline, long enough for a placement of 64 cells; a sampled string is
  almost always unparseable, which the environment answers like any other unreadable action.
* Observations are a dict: ``text`` (instruction, pieces, recent turns, steps left, and with
  ``text_state=True`` every piece's cells; characters outside the charset become ``?``; at most
  :data:`~chaingeo.core.limits.MAX_OBSERVATION_CHARS`) and, with ``images=True``, ``images``:
  one ``uint8`` array ``(image_size, image_size, 3)`` per picture (``front side top iso`` and
  ``tray`` or ``target``), drawn straight to arrays (:mod:`chaingeo.envs.frames`; pixel-equal
  to decoding the PNG ``render_state`` gives) and cached by what they show.
* The spaces are fixed per environment id and constructor arguments, whatever level is drawn,
  so ``gymnasium.make_vec(id, num_envs=8, vectorization_mode="sync" | "async")`` batches them;
  a vector environment autoresets as Gymnasium 1.x defines it (next step by default).
  :class:`chaingeo.envs.vector.SeedSequenceSeeds` seeds sub-environment ``i`` of a batch from
  ``SeedSequence([seed, i])``.
* Reward 1 on the step that solves the level, else 0. ``terminated`` when the level is solved
  or ``finish`` was played; ``truncated`` when the step budget is spent.
* ``info``: ``legal``, ``error`` (None, "unparseable", "illegal", "ambiguous"), ``code``
  (CHAIN's error name of an illegal stacking action, else None), ``feedback``,
  ``steps_used``, ``level_id``, ``optimal_steps``, ``success``. Stacking levels also give
  ``action_mask`` (``int8``, length :data:`~chaingeo.core.limits.MAX_STACKING_ACTIONS`): entry
  ``i`` is 1 when the ``i``-th action of :meth:`ChainEnv.action_catalogue` (every action that
  can ever be legal in the level, in sorted order) is legal now; past the catalogue, 0. Puzzle
  moves are not enumerable up front (the distances depend on the position), so the puzzle
  environment gives ``legal_actions`` (their texts) instead when built with
  ``list_legal_actions=True``.
"""

from __future__ import annotations

import re
import string
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any, ClassVar, Final

import gymnasium
import numpy as np
from gymnasium import spaces

from chaingeo.core.errors import ChainGeoError
from chaingeo.core.level import Level, load_levels
from chaingeo.core.limits import MAX_OBSERVATION_CHARS, MAX_STACKING_ACTIONS, LimitError
from chaingeo.core.suite import suite_folder
from chaingeo.envs.actions.text_space import ObservationText
from chaingeo.envs.actions.types import Action
from chaingeo.envs.frames import Frame, FrameCache, picture_names
from chaingeo.envs.machines import new_state
from chaingeo.envs.machines.state import BaseState
from chaingeo.envs.observation import DEFAULT_HISTORY, VIEWS, observe
from chaingeo.pictures.scene import MIN_SIZE

#: Characters of text actions and observations: printable ASCII and newline.
CHARSET: Final = frozenset(c for c in string.printable if c not in "\x0b\x0c\r")
ACTION_MAX_LENGTH: Final = 1024
OBSERVATION_MAX_LENGTH: Final = MAX_OBSERVATION_CHARS
DEFAULT_LEVELS: Final = suite_folder()


#: The longest history window (turns echoed in the observation): with actions of at most
#: :data:`ACTION_MAX_LENGTH` characters, the text observation stays under its limit.
MAX_HISTORY_WINDOW: Final = 16


class EnvError(ChainGeoError, ValueError):
    """A call the environment cannot take as made: an unknown level, options that are not a
    mapping, a history window past its bound (the agent's own actions are never refused this
    way: see :meth:`ChainEnv.step`)."""


class EpisodeOver(ChainGeoError, RuntimeError):
    """A step before :meth:`ChainEnv.reset` or after the episode ended."""


#: Every character outside :data:`CHARSET` (printable ASCII less \x0b \x0c \r), one at a time.
_NOT_CHARSET: Final = re.compile(r"[^\t\n\x20-\x7e]")


def _ascii(text: str) -> str:
    """``text`` with each character outside :data:`CHARSET` replaced by ``?`` (one pass in C:
    a character by character check cost more than the rest of a step without images)."""
    return _NOT_CHARSET.sub("?", text)


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
        if not 0 <= history_window <= MAX_HISTORY_WINDOW:
            raise EnvError(
                f"history_window must be 0 to {MAX_HISTORY_WINDOW}, got {history_window}"
            )
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
        if images and image_size < MIN_SIZE:
            raise ValueError(f"image_size must be at least {MIN_SIZE} pixels, got {image_size}")
        self._templates: dict[str, BaseState] = {}
        self._catalogues: dict[str, tuple[list[str], dict[Action, int]]] = {}
        #: Per level: catalogue index by object identity (a state's legal placements are the
        #: very objects of its level's table: looking them up skips hashing each one).
        self._by_id: dict[str, dict[int, int]] = {}
        self._frames = FrameCache(image_size)
        self._state: BaseState | None = None
        self.action_space = spaces.Text(ACTION_MAX_LENGTH, min_length=0, charset=CHARSET)
        obs: dict[str, spaces.Space[Any]] = {
            "text": ObservationText(OBSERVATION_MAX_LENGTH, CHARSET)
        }
        if images:
            shape = (image_size, image_size, 3)
            obs["images"] = spaces.Dict(
                {
                    v: spaces.Box(0, 255, shape=shape, dtype=np.uint8)
                    for v in picture_names(self.family)
                }
            )
        self.observation_space = spaces.Dict(obs)

    # -- helpers ------------------------------------------------------------------------------
    def _start(self, level_id: str) -> BaseState:
        from chaingeo.envs.machines.stacking import StackingState

        if level_id not in self._templates:
            template = new_state(self.levels[level_id])
            if isinstance(template, StackingState):
                actions = template.catalogue()
                if len(actions) > MAX_STACKING_ACTIONS:
                    raise LimitError(
                        f"level {level_id!r} has {len(actions)} possible actions; the action "
                        f"mask holds at most {MAX_STACKING_ACTIONS} (MAX_STACKING_ACTIONS)"
                    )
                index = {a: i for i, a in enumerate(actions)}
                self._catalogues[level_id] = ([a.to_text() for a in actions], index)
                self._by_id[level_id] = {id(a): i for a, i in index.items()}
            self._templates[level_id] = template
        return self._templates[level_id].clone()

    @property
    def state(self) -> BaseState:
        if self._state is None:
            raise EpisodeOver("call reset() first")
        return self._state

    def action_catalogue(self) -> list[str]:
        """Stacking: every action that can ever be legal in the current level (the mask's
        index); puzzles: empty (not enumerable up front)."""
        texts, _ = self._catalogues.get(self.state.level.id, ([], {}))
        return list(texts)

    def clear_picture_cache(self) -> None:
        """Forget the pictures drawn so far (benchmarks time drawing with it; vector
        environments reach it through ``envs.call("clear_picture_cache")``)."""
        self._frames.clear()

    def _draw(self, state: BaseState) -> dict[str, Frame]:
        """The pictures of ``state`` (the benchmark swaps in today's PNG round trip here)."""
        return self._frames.frames(state)

    def _observation(self) -> dict[str, Any]:
        obs = observe(
            self.state,
            history_window=self.history_window,
            text_state=self.text_state,
            images=False,
        )
        names = picture_names(self.family) if self.images else ()
        text = _ascii(obs.to_text(views=names))
        if len(text) > OBSERVATION_MAX_LENGTH:
            raise LimitError(
                f"observation text of {len(text)} characters exceeds MAX_OBSERVATION_CHARS "
                f"({OBSERVATION_MAX_LENGTH})"
            )
        out: dict[str, Any] = {"text": text}
        if self.images:
            out["images"] = self._draw(self.state)
        return out

    def _info(self, result: Any | None) -> dict[str, Any]:
        from chaingeo.envs.machines.stacking import StackingState

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
            _, index = self._catalogues[state.level.id]
            by_id = self._by_id[state.level.id]
            mask = np.zeros(MAX_STACKING_ACTIONS, dtype=np.int8)
            mask[[by_id.get(id(a)) or index[a] for a in state.legal_actions()]] = 1
            info["action_mask"] = mask
        elif self.list_legal_actions:
            info["legal_actions"] = [a.to_text() for a in state.legal_actions()]
        return info

    # -- the Gymnasium API --------------------------------------------------------------------
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Any], dict[str, Any]]:
        super().reset(seed=seed)
        if options is not None and not isinstance(options, Mapping):
            raise EnvError(
                f"options must be a mapping (e.g. {{'level': id}}), got {_kind(options)}"
            )
        wanted = (options or {}).get("level")
        ids = list(self.levels)
        if wanted is None:
            level_id = ids[int(self.np_random.integers(len(ids)))]
        elif isinstance(wanted, str) and wanted in self.levels:
            level_id = str(wanted)
        else:
            raise EnvError(f"unknown {self.family} level {str(wanted)[:80]!r}")
        self._state = self._start(level_id)
        return self._observation(), self._info(None)

    def step(self, action: str) -> tuple[dict[str, Any], float, bool, bool, dict[str, Any]]:
        """Apply ``action`` (one step, legal or not, as the state machine counts it), or refuse
        it without consuming the step when it is not in the action space (not text, or longer
        than :data:`ACTION_MAX_LENGTH`): the agent's text is bounded before the observation
        echoes it, so no action makes a later observation too long."""
        state = self.state
        if state.is_success() or state.finished:
            raise EpisodeOver("the episode has ended; call reset()")
        if not isinstance(action, str) or len(action) > ACTION_MAX_LENGTH:
            return self._refuse(action)
        result = state.step_text(action)
        terminated = state.is_success() or state.finished
        truncated = state.is_truncated() and not terminated
        reward = 1.0 if result.success and result.legal else 0.0
        return self._observation(), reward, terminated, truncated, self._info(result)

    def _refuse(self, action: Any) -> tuple[dict[str, Any], float, bool, bool, dict[str, Any]]:
        what = f"{len(action)} characters" if isinstance(action, str) else _kind(action)
        info = self._info(None)
        info.update(
            legal=False,
            error="refused",
            feedback=f"Action refused ({what}; at most {ACTION_MAX_LENGTH} characters of text); "
            "no step was used.",
        )
        state = self.state
        truncated = state.is_truncated() and not state.is_success()
        return self._observation(), 0.0, False, truncated, info


def _kind(value: Any) -> str:
    return "null" if value is None else type(value).__name__


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
