"""The environments, in rooms: actions and the text parser (:mod:`.actions`), the two state
machines (:mod:`.machines`); observations, the Gymnasium wrappers and the dataset export beside
them.

Built on :mod:`chaingeo.core`, :mod:`chaingeo.solvers` and the pictures
(:mod:`chaingeo.pictures`); the evaluation harness and the video-model checks
(:mod:`chaingeo.worldmodel`) sit above.

Its entry points are exported here and imported on first use: ``new_state``, ``observe``,
``render_state``, ``parse_action``, the action types, and the Gymnasium environments
(``ENV_IDS``, ``register_envs``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Final

from chaingeo.core.lazy import lazy_exports

if TYPE_CHECKING:  # the real types for mypy and editors; at run time see _LAZY
    from chaingeo.envs.actions.parse import parse_action
    from chaingeo.envs.actions.types import (
        Action,
        ActionError,
        AmbiguousActionError,
        FinishAction,
        IllegalActionError,
        MoveAction,
        PickupAction,
        PlaceAction,
        StateAction,
        TurnAction,
        UnparseableActionError,
    )
    from chaingeo.envs.gym import ENV_IDS, ChainEnv, PuzzleEnv, StackingEnv, register_envs
    from chaingeo.envs.machines import new_state
    from chaingeo.envs.machines.puzzle import PuzzleState
    from chaingeo.envs.machines.stacking import StackingState
    from chaingeo.envs.machines.state import BaseState
    from chaingeo.envs.observation import Observation, observe, render_state

#: Public name -> "module:attribute", imported on first use (:mod:`chaingeo.core.lazy`).
_LAZY: Final = {
    "Action": "chaingeo.envs.actions.types:Action",
    "ActionError": "chaingeo.envs.actions.types:ActionError",
    "AmbiguousActionError": "chaingeo.envs.actions.types:AmbiguousActionError",
    "BaseState": "chaingeo.envs.machines.state:BaseState",
    "ChainEnv": "chaingeo.envs.gym:ChainEnv",
    "ENV_IDS": "chaingeo.envs.gym:ENV_IDS",
    "FinishAction": "chaingeo.envs.actions.types:FinishAction",
    "IllegalActionError": "chaingeo.envs.actions.types:IllegalActionError",
    "MoveAction": "chaingeo.envs.actions.types:MoveAction",
    "Observation": "chaingeo.envs.observation:Observation",
    "PickupAction": "chaingeo.envs.actions.types:PickupAction",
    "PlaceAction": "chaingeo.envs.actions.types:PlaceAction",
    "PuzzleEnv": "chaingeo.envs.gym:PuzzleEnv",
    "PuzzleState": "chaingeo.envs.machines.puzzle:PuzzleState",
    "StackingEnv": "chaingeo.envs.gym:StackingEnv",
    "StackingState": "chaingeo.envs.machines.stacking:StackingState",
    "StateAction": "chaingeo.envs.actions.types:StateAction",
    "TurnAction": "chaingeo.envs.actions.types:TurnAction",
    "UnparseableActionError": "chaingeo.envs.actions.types:UnparseableActionError",
    "new_state": "chaingeo.envs.machines:new_state",
    "observe": "chaingeo.envs.observation:observe",
    "parse_action": "chaingeo.envs.actions.parse:parse_action",
    "register_envs": "chaingeo.envs.gym:register_envs",
    "render_state": "chaingeo.envs.observation:render_state",
}

__all__ = [
    "ENV_IDS",
    "Action",
    "ActionError",
    "AmbiguousActionError",
    "BaseState",
    "ChainEnv",
    "FinishAction",
    "IllegalActionError",
    "MoveAction",
    "Observation",
    "PickupAction",
    "PlaceAction",
    "PuzzleEnv",
    "PuzzleState",
    "StackingEnv",
    "StackingState",
    "StateAction",
    "TurnAction",
    "UnparseableActionError",
    "new_state",
    "observe",
    "parse_action",
    "register_envs",
    "render_state",
]

if not TYPE_CHECKING:
    __getattr__, __dir__ = lazy_exports(__name__, _LAZY)
