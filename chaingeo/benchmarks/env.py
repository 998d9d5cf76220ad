"""``chain bench env``: Gymnasium steps per second, single and vectorised, with and without images.

Every row runs the shipped levels of one family through ``gymnasium.make`` (single) or
``gymnasium.make_vec`` with 2 sub-environments (``sync``, and ``async``: one worker process
each), at the environments' default 256 px, under two seeded policies:

* ``random``: text sampled from the action space (almost always unreadable: the picture does
  not change; the policy of the figures in issue #23);
* ``plan``: each level's stored optimal plan, then ``finish`` (every step legal and every
  picture new: this times drawing).

Rows with images are timed twice on the very same trajectory: ours (pictures drawn to arrays by
:mod:`chaingeo.pictures.scene_kernel`'s kernels, cached by what they show) and the reference, the
old
path (:mod:`chaingeo.pictures.scene` through Pillow, every picture encoded to PNG and decoded
back, nothing cached) in the same run; ``ratio`` = ours / reference steps per second. ``vs today``
divides by the single-environment reference of the same family and policy.
Each environment first plays its trajectory once untimed (level tables built, numba compiled),
then forgets its pictures and plays it again timed; steps/s counts sub-environment steps, wall
clock (the async workers are other processes). A single environment with images, the row the
goal is about, plays ours and the reference in turn ``--repeat`` times and reports medians
(:class:`Paired`), the ratio also by CPU time: on cores shared with other jobs one wall-clock
play moves by 10% or more. ``--quick``: 30 steps a row instead of 200.

First, the pictures alone: one observation's pictures along the plans of the first levels of
each family, drawn to arrays (:func:`render_frames`, no cache), by the old renderer without PNG
(:func:`reference_frames`) and with the PNG round trip (:func:`png_frames`), best of
``--repeat`` CPU times: what the kernels and dropping PNG save by themselves.
"""

from __future__ import annotations

import argparse
import gc
import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import gymnasium
from gymnasium.vector import AsyncVectorEnv, SyncVectorEnv

from chaingeo.core.level import Level
from chaingeo.envs.demos import plan_texts
from chaingeo.envs.frames import Frame, png_frames, reference_frames, render_frames
from chaingeo.envs.gym import ChainEnv, PuzzleEnv, StackingEnv
from chaingeo.envs.machines import new_state
from chaingeo.envs.machines.state import BaseState

SEED = 2026
SIZE = 256
NUM_ENVS = 2
GOAL_RATIO = 3.0


class PngStackingEnv(StackingEnv):
    """The reference: today's pictures, PNG-encoded and decoded on every observation."""

    def _draw(self, state: BaseState) -> dict[str, Frame]:
        return png_frames(state, self.image_size)


class PngPuzzleEnv(PuzzleEnv):
    """The reference: today's pictures, PNG-encoded and decoded on every observation."""

    def _draw(self, state: BaseState) -> dict[str, Frame]:
        return png_frames(state, self.image_size)


FAMILIES: dict[str, tuple[str, type[ChainEnv], type[ChainEnv]]] = {
    "stacking": ("chaingeo/Stacking-v0", StackingEnv, PngStackingEnv),
    "puzzle": ("chaingeo/Puzzle-v0", PuzzleEnv, PngPuzzleEnv),
}


@dataclass(frozen=True)
class Row:
    family: str
    policy: str
    mode: str
    images: bool
    ours: float
    reference: float | None
    ratio: float | None = None  # ours / reference (a median of turns where paired)
    cpu_ratio: float | None = None


def _plan_action(plans: dict[str, list[str]], level_id: str, steps_used: int) -> str:
    plan = plans[level_id]
    return plan[steps_used] if steps_used < len(plan) else "finish"


def _play(env: gymnasium.Env[Any, str], policy: str, steps: int) -> tuple[float, float]:
    """(wall, CPU) seconds of ``steps`` steps from a seeded reset, no picture kept before."""
    base = env.unwrapped
    assert isinstance(base, ChainEnv)
    plans = {lv.id: plan_texts(lv) for lv in base.levels.values()}
    base.clear_picture_cache()
    env.action_space.seed(SEED)
    _, info = env.reset(seed=SEED)
    gc.collect()  # a collection owed by earlier rows would land in this row's short window
    start, cpu = time.perf_counter(), time.process_time()
    for _ in range(steps):
        if policy == "plan":
            action = _plan_action(plans, info["level_id"], info["steps_used"])
        else:
            action = env.action_space.sample()
        _, _, terminated, truncated, info = env.step(action)
        if terminated or truncated:
            _, info = env.reset()
    return time.perf_counter() - start, time.process_time() - cpu


def _single(env: gymnasium.Env[Any, str], policy: str, steps: int) -> float:
    _play(env, policy, steps)  # untimed: tables built, kernels compiled
    return steps / _play(env, policy, steps)[0]


@dataclass(frozen=True)
class Paired:
    """A single environment with images, ours and the reference played in turn ``repeat``
    times on the same trajectory: medians of steps/s (wall) and of the per-turn ratios (wall
    and CPU), so that a burst of load on shared cores moves one turn, not the figure."""

    ours: float
    reference: float
    ratio: float
    cpu_ratio: float


def _paired(family: str, policy: str, steps: int, repeat: int) -> Paired:
    env_id, _, png = FAMILIES[family]
    ours, ref = gymnasium.make(env_id, images=True), png(images=True)
    _play(ours, policy, steps)
    _play(ref, policy, steps)
    turns = [(_play(ours, policy, steps), _play(ref, policy, steps)) for _ in range(repeat)]
    return Paired(
        statistics.median(steps / o[0] for o, _ in turns),
        statistics.median(steps / r[0] for _, r in turns),
        statistics.median(r[0] / o[0] for o, r in turns),
        statistics.median(r[1] / o[1] for o, r in turns),
    )


def _vector(
    envs: SyncVectorEnv | AsyncVectorEnv, levels: list[Level], policy: str, steps: int
) -> float:
    plans = {lv.id: plan_texts(lv) for lv in levels}
    elapsed = 0.0
    for _ in range(2):  # untimed, then timed
        envs.call("clear_picture_cache")
        envs.action_space.seed(SEED)
        _, info = envs.reset(seed=SEED)
        start = time.perf_counter()
        for _ in range(steps):
            if policy == "plan":
                actions: Any = tuple(
                    _plan_action(plans, str(info["level_id"][i]), int(info["steps_used"][i]))
                    for i in range(envs.num_envs)
                )
            else:
                actions = envs.action_space.sample()
            _, _, _, _, info = envs.step(actions)
        elapsed = time.perf_counter() - start
    envs.close()
    return steps * envs.num_envs / elapsed


def _measure(family: str, policy: str, mode: str, images: bool, ref: bool, steps: int) -> float:
    env_id, ours, png = FAMILIES[family]
    cls = png if ref else ours
    kwargs: dict[str, Any] = {"images": images}
    if mode == "single":
        env = gymnasium.make(env_id, **kwargs) if not ref else cls(**kwargs)
        return _single(env, policy, steps)
    if not ref:
        envs = gymnasium.make_vec(env_id, num_envs=NUM_ENVS, vectorization_mode=mode, **kwargs)
        assert isinstance(envs, SyncVectorEnv | AsyncVectorEnv)
    else:
        fns: list[Callable[[], ChainEnv]] = [lambda: cls(**kwargs)] * NUM_ENVS
        envs = SyncVectorEnv(fns) if mode == "sync" else AsyncVectorEnv(fns)
    levels = list(cls(images=False).levels.values())
    return _vector(envs, levels, policy, steps)


def _plan_states(level: Level) -> list[BaseState]:
    state = new_state(level)
    out = [state.clone()]
    for text in plan_texts(level):
        state.step_text(text)
        out.append(state.clone())
    return out


def pictures(family: str, levels: int, repeat: int) -> tuple[int, list[float]]:
    """(observations, ms per observation: ours, the old drawing, the old drawing and PNG),
    best CPU times."""
    env = FAMILIES[family][1](images=False)
    states = [s for lv in list(env.levels.values())[:levels] for s in _plan_states(lv)]
    best = []
    for draw in (render_frames, reference_frames, png_frames):
        draw(states[0], SIZE)  # warm-up: fonts, kernels
        times = []
        for _ in range(repeat):
            start = time.process_time()
            for state in states:
                draw(state, SIZE)
            times.append(time.process_time() - start)
        best.append(min(times) / len(states) * 1e3)
    return len(states), best


def _line(row: Row, today: float | None) -> str:
    ref = "-" if row.reference is None else f"{row.reference:.0f}"
    ratio = "-" if row.ratio is None else f"{row.ratio:.2f}x"
    vs = f"{row.ours / today:.2f}x" if row.images and today else "-"
    cpu = "" if row.cpu_ratio is None else f"{row.cpu_ratio:9.2f}x"
    return (
        f"{row.family:9s}{row.policy:8s}{row.mode:7s}{'yes' if row.images else 'no':7s}"
        f"{row.ours:9.0f}{ref:>9s}{ratio:>8s}{vs:>9s}{cpu}"
    )


def _row(family: str, policy: str, mode: str, images: bool, steps: int, repeat: int) -> Row:
    if mode == "single" and images:
        p = _paired(family, policy, steps, repeat)
        return Row(family, policy, mode, images, p.ours, p.reference, p.ratio, p.cpu_ratio)
    mine = _measure(family, policy, mode, images, False, steps)
    if not images:
        return Row(family, policy, mode, images, mine, None)
    ref = _measure(family, policy, mode, images, True, steps)
    return Row(family, policy, mode, images, mine, ref, mine / ref)


def rows(steps: int, repeat: int = 1) -> list[Row]:
    """Every measurement, ours and (with images) the reference, in the same run; each row is
    printed as soon as it is measured (the single-environment pair comes first: ``repeat``
    turns each, see :class:`Paired`)."""
    out: list[Row] = []
    for family in FAMILIES:
        for policy in ("random", "plan"):
            today: float | None = None
            for mode in ("single", "sync", "async"):
                for images in (False, True):
                    row = _row(family, policy, mode, images, steps, repeat)
                    if mode == "single" and images:
                        today = row.reference
                    print(_line(row, today), flush=True)
                    out.append(row)
    return out


def run(args: argparse.Namespace) -> int:
    quick = bool(getattr(args, "quick", False))
    steps = 30 if quick else 200
    repeat = max(1, int(getattr(args, "repeat", 3)))
    print(f"pictures of one observation, {SIZE} px, CPU ms (best of {repeat})")
    for family in FAMILIES:
        n, (arrays, old, png) = pictures(family, 1 if quick else 3, repeat)
        print(
            f"  {family:9s} {n:3d} states: arrays {arrays:6.1f}  old drawing {old:6.1f}  "
            f"+ PNG round trip {png:6.1f}  ratio {png / arrays:.2f}x",
            flush=True,
        )
    print(
        f"env steps/s (wall), shipped levels, {SIZE} px, vector envs of {NUM_ENVS}; "
        f"{steps} steps per row (the same trajectory with and without images)"
    )
    print(
        f"single env with images: ours and the reference in turn, {repeat} turns each, medians "
        f"(steps/s and ratio wall, 'CPU ratio' by CPU time)"
    )
    print(
        f"{'family':9s}{'policy':8s}{'mode':7s}{'images':7s}{'ours':>9s}{'PNG ref':>9s}"
        f"{'ratio':>8s}{'vs today':>9s}{'CPU ratio':>10s}"
    )
    table = rows(steps, repeat)
    single = [r for r in table if r.mode == "single" and r.ratio is not None]
    worst = min(r.ratio for r in single if r.ratio is not None)
    worst_cpu = min(r.cpu_ratio for r in single if r.cpu_ratio is not None)
    print(
        f"single env with images, worst ratio over families and policies: {worst:.2f}x wall, "
        f"{worst_cpu:.2f}x CPU (goal >= {GOAL_RATIO:.0f}x)"
    )
    return 0
