"""``chain bench serve``: the environment server's throughput and step latency, against the
in-process environment in the same run.

A ``chain serve`` process is started on 127.0.0.1 (a free port) with a handful of small shipped
levels; N concurrent sessions (OpenEnv's ``GenericEnvClient`` over WebSocket, from this process)
play episodes under two seeded policies: ``oracle`` (each level's stored optimal plan) and
``random`` (a uniformly random legal action each step, from the observation's ``legal`` list, up
to the step budget). The same episodes are played in this process on the one
:class:`~chaingeo.evaluation.episode.Episode`, doing the work the server does per step (the
action, the observation, the legal list when asked) minus the wire. Reported per policy: steps,
steps/s (wall), the latency of one step (p50, p99, ms; served: from sending the step to reading
its observation, so it includes waiting behind other sessions), and ``ratio`` = served / in-process
steps per second. Each side plays its episodes once untimed first (tables built, kernels
compiled). ``--quick``: 4 sessions and fewer episodes.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import socket
import subprocess
import sys
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from chaingeo.core.level import Level
from chaingeo.core.suite import shipped_level
from chaingeo.envs.demos import plan_texts
from chaingeo.evaluation.agents.base import Reply
from chaingeo.evaluation.episode import Episode

REQUIRES = ("openenv",)
EXTRA = "serve"
SEED = 2026
LEVELS = (
    "puzzle-easy-07-burr3",
    "puzzle-easy-02-luban-6-piece",
    "stacking-2x2x3-easy-s103-000000",
    "stacking-2x3x3-easy-s107-000000",
)
POLICIES = ("oracle", "random")


@dataclass(frozen=True)
class Figures:
    steps: int
    seconds: float
    latencies: list[float]

    @property
    def rate(self) -> float:
        return self.steps / self.seconds if self.seconds else 0.0

    def percentile(self, q: float) -> float:
        return float(np.percentile(self.latencies, q)) * 1e3 if self.latencies else 0.0


def _choose(policy: str, level: Level, step: int, legal: list[str] | None, rng: Any) -> str:
    if policy == "oracle":
        plan = plan_texts(level)
        return plan[step] if step < len(plan) else "finish"
    assert legal is not None
    return str(legal[int(rng.integers(len(legal)))]) if legal else "finish"


def _tasks(episodes: int) -> list[tuple[Level, int]]:
    levels = [shipped_level(i) for i in LEVELS]
    return [(levels[i % len(levels)], i) for i in range(episodes)]


def in_process(policy: str, episodes: int) -> Figures:
    """The episodes on :class:`Episode` here: per step the action, the observation, and (random)
    the legal list, as the server computes them."""
    latencies: list[float] = []
    steps = 0
    start = time.perf_counter()
    for level, index in _tasks(episodes):
        rng = np.random.default_rng([SEED, index])
        ep = Episode(level, images=False, keep_images=False)
        ep.observation()
        legal = [a.to_text() for a in ep.state.legal_actions()] if policy == "random" else None
        while not ep.done:
            text = _choose(policy, level, int(ep.state.steps_used), legal, rng)
            t0 = time.perf_counter()
            ep.play(Reply(text, text))
            ep.observation()
            if policy == "random":
                legal = [a.to_text() for a in ep.state.legal_actions()]
            latencies.append(time.perf_counter() - t0)
            steps += 1
    return Figures(steps, time.perf_counter() - start, latencies)


async def _session(url: str, policy: str, tasks: list[tuple[Level, int]], out: list[float]) -> int:
    from openenv.core.generic_client import GenericEnvClient

    steps = 0
    async with GenericEnvClient(base_url=url, message_timeout_s=300) as env:
        for level, index in tasks:
            rng = np.random.default_rng([SEED, index])
            result = await env.reset(level=level.id, legal=policy == "random")
            while not result.done:
                obs = result.observation
                text = _choose(policy, level, int(obs["steps"]), obs.get("legal"), rng)
                t0 = time.perf_counter()
                result = await env.step({"text": text})
                out.append(time.perf_counter() - t0)
                steps += 1
    return steps


def served(url: str, policy: str, episodes: int, sessions: int) -> Figures:
    tasks = _tasks(episodes)
    latencies: list[float] = []

    async def run() -> int:
        shares = [tasks[i::sessions] for i in range(sessions)]
        counts = await asyncio.gather(*(_session(url, policy, s, latencies) for s in shares))
        return sum(counts)

    start = time.perf_counter()
    steps = asyncio.run(run())
    return Figures(steps, time.perf_counter() - start, latencies)


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port: int = s.getsockname()[1]
        return port


def _start_server(sessions: int) -> tuple[subprocess.Popen[str], str]:
    port = _free_port()
    command = [sys.executable, "-m", "chaingeo.cli.main", "serve", *LEVELS, "--port", str(port)]
    command += ["--max-sessions", str(max(sessions, 1))]
    proc = subprocess.Popen(command, stdout=subprocess.PIPE, text=True)
    assert proc.stdout is not None
    line = json.loads(proc.stdout.readline() or "{}")
    if "serving" not in line:
        proc.kill()
        raise RuntimeError("chain serve did not start")
    import httpx

    url = f"http://127.0.0.1:{port}"
    deadline = time.monotonic() + 120
    while True:
        try:
            if httpx.get(f"{url}/health", timeout=5).status_code == 200:
                return proc, url
        except httpx.HTTPError:
            if time.monotonic() > deadline:
                proc.kill()
                raise
            time.sleep(0.1)


def _line(policy: str, where: str, f: Figures, ratio: str = "") -> str:
    return (
        f"{policy:8s}{where:18s}{f.steps:7d}{f.rate:10.0f}"
        f"{f.percentile(50):9.2f}{f.percentile(99):9.2f}{ratio:>8s}"
    )


def run(args: argparse.Namespace) -> int:
    quick = bool(getattr(args, "quick", False))
    sessions = 4 if quick else 16
    episodes = 16 if quick else 64
    proc, url = _start_server(sessions)
    try:
        print(
            f"chain serve on 127.0.0.1: {sessions} concurrent sessions (OpenEnv WebSocket), "
            f"{episodes} episodes a policy over {len(LEVELS)} levels; in-process: the same "
            "episodes on Episode in this process; latency = one step, ms"
        )
        print(
            f"{'policy':8s}{'where':18s}{'steps':>7s}{'steps/s':>10s}{'p50':>9s}{'p99':>9s}"
            f"{'ratio':>8s}"
        )
        for policy in POLICIES:
            in_process(policy, len(LEVELS))  # untimed: tables, kernels
            served(url, policy, len(LEVELS), 1)
            here = in_process(policy, episodes)
            there = served(url, policy, episodes, sessions)
            print(_line(policy, "in-process", here), flush=True)
            ratio = f"{there.rate / here.rate:.2f}x" if here.rate else "-"
            print(_line(policy, f"served x{sessions}", there, ratio), flush=True)
    finally:
        proc.terminate()
        proc.wait(timeout=30)
    return 0
