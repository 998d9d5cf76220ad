"""The 3D player in headless Chromium, by real clicks and key presses (DevTools input events):
a level's optimal plan played to the "solved" screen in a study whose record then holds o_i
steps; the canvas shows the level's colours; markup in piece names and feedback stays text."""

from __future__ import annotations

import dataclasses
import io
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

pytest.importorskip("openenv", reason="chain serve needs the serve extra (openenv-core)")

import numpy as np
from PIL import Image

from chaingeo.core.level import Level, StackingSolution
from chaingeo.core.suite import shipped_level
from chaingeo.envs.demos import plan_texts
from chaingeo.evaluation.logs import RunLog
from chaingeo.integrations.serve.environment import Catalog
from chaingeo.integrations.serve.study import Study
from tests.support.cdp import Page, browser, chromium, open_page
from tests.support.serve import get, running

PUZZLE = "puzzle-easy-01-luban-3-piece"  # a turn, then two moves out to infinity
STACKING = "stacking-2x2x2-easy-s101-000000"
PROBE = "<img src=x onerror=document.title=42>"
DIRECTION_KEYS = {"+x": "d", "-x": "a", "+y": "w", "-y": "s", "+z": "e", "-z": "q"}


@pytest.fixture(scope="module")
def devtools() -> Iterator[str]:
    exe = chromium()
    if exe is None:
        pytest.skip("no chromium (Debian: apt-get install chromium; .ci/run installs it)")
    with browser(exe) as address:
        yield address


def _ready(page: Page, steps: int) -> dict[str, Any]:
    status: dict[str, Any] = page.wait(
        f"(s => s && !s.waiting && s.steps === {steps} && s)(window.chainPlayer?.status())"
    )
    return status


def _select(page: Page, group: list[str], keys_only: bool) -> None:
    """Click the group's pieces (shift for the rest); a piece no click can reach, or every piece
    with ``keys_only``, is taken from the keyboard: ] moves the cursor, space adds it."""
    for i, name in enumerate(group):
        point = None if keys_only else page.js(f"window.chainPlayer.pointOf({name!r})")
        if point is not None:
            page.click(point[0], point[1], shift=i > 0)
            continue
        if i == 0:
            page.key("Escape")
        while page.js("window.chainPlayer.status().cursor") != name:
            page.key("]")
        page.key(" ")
    assert page.js("window.chainPlayer.status().selected") == sorted(group)


def _play(page: Page, text: str, keys_only: bool = False) -> None:
    """One action of a plan, by the controls a person uses."""
    words = text.split()
    if words[0] == "place":
        _select(page, [words[1]], keys_only)
        target = text.split(" ", 2)[2]
        for _ in range(500):
            if page.js("window.chainPlayer.status().ghost") == target:
                break
            page.key("n")
        page.key("Enter")
        return
    _select(page, words[1].split("+"), keys_only)
    if words[0] == "rotate":
        page.key(words[2])
        page.key("r" if words[3] == "+90" else "f")
        choices = page.js("window.chainPlayer.status().choices")
        if choices:  # several centres work: the page offers them, numbered
            page.key(str(choices.index(text) + 1))
        return
    assert words[0] == "move" and len(words) == 4, text
    page.key("0" if words[3] == "inf" else words[3])
    page.key(DIRECTION_KEYS[words[2]])


def _solve(page: Page, level: Level, keys_only: bool) -> None:
    _ready(page, 0)
    for i, text in enumerate(plan_texts(level)):
        _play(page, text, keys_only)
        status = _ready(page, i + 1)
        assert status["sent"][-1].startswith(text.split(" about")[0]), (text, status["sent"])
    page.wait("document.body.dataset.state === 'solved'")
    assert page.js("document.getElementById('solved').hidden") is False
    assert page.js("document.getElementById('solvedtitle').textContent") == "Solved!"


@pytest.mark.parametrize(("level_id", "keys_only"), [(PUZZLE, False), (STACKING, True)])
def test_a_study_participant_solves_a_level_by_clicks_and_keys(
    devtools: str, tmp_path: Path, level_id: str, keys_only: bool
) -> None:
    """The puzzle by clicks (the keyboard where no click reaches a piece) and keys, the
    stacking level by the keyboard alone."""
    level = shipped_level(level_id)
    study = Study.create("browser", tmp_path, [level], seed=1)
    with running(Catalog({level_id: level}, study)) as url:
        page = open_page(devtools, f"{url}/play/study?participant=tester")
        try:
            _solve(page, level, keys_only)
            assert page.js("document.getElementById('optimal').textContent") == "hidden"
            assert page.js("document.getElementById('undo').disabled") is True
        finally:
            page.close()
    (record,) = RunLog(tmp_path / "browser").records()
    assert record["participant"] == "tester" and record["success"]
    assert record["steps_used"] == level.optimal_steps == len(record["steps"])
    times = [s["t"] for s in record["steps"]]
    assert times == sorted(times) and record["solve_seconds"] == times[-1]


def _probe_level() -> Level:
    """A stacking level whose first piece is named with markup (only Python can build it: the
    level format allows letters only)."""
    level = shipped_level(STACKING)
    old = level.pieces[0].name
    rename = {old: PROBE}
    sol = level.solution
    assert isinstance(sol, StackingSolution)
    return dataclasses.replace(
        level,
        id="probe",
        pieces=tuple(dataclasses.replace(p, name=rename.get(p.name, p.name)) for p in level.pieces),
        solution=dataclasses.replace(
            sol,
            order=tuple(rename.get(n, n) for n in sol.order),
            placements={rename.get(k, k): v for k, v in sol.placements.items()},
        ),
    )


def _colour_pixels(png: bytes, rgb: str) -> int:
    """Pixels that are a shade of ``rgb`` (the colour times some brightness, within a margin)."""
    pixels = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=float).reshape(-1, 3)
    c = np.array([int(rgb[i : i + 2], 16) for i in (1, 3, 5)], dtype=float)
    k = pixels @ c / (c @ c)
    residual = np.linalg.norm(pixels - k[:, None] * c, axis=1)
    return int(np.count_nonzero((k > 0.45) & (k < 1.4) & (residual < 18)))


def test_canvas_colours_undo_and_markup_stays_text(devtools: str) -> None:
    probe, puzzle = _probe_level(), shipped_level(PUZZLE)
    marked = dataclasses.replace(puzzle, id="a<b>b")  # the format allows no such id; Python can
    with running(Catalog({"probe": probe, PUZZLE: puzzle, marked.id: marked})) as url:
        index = get(f"{url}/").text
        assert "a&lt;b&gt;b" in index and "a<b>" not in index
        page = open_page(devtools, f"{url}/play/{PUZZLE}")
        try:
            _ready(page, 0)
            shot = page.screenshot()
            for piece in puzzle.pieces:
                assert _colour_pixels(shot, piece.rgb) > 800, piece
            assert _colour_pixels(shot, "#e6194b") < 50  # red: no piece of this level
            _play(page, plan_texts(puzzle)[0])
            _ready(page, 1)
            page.key("u")
            _ready(page, 0)
            page.key("v")  # the agent's view: its pictures and its text
            page.wait("document.querySelectorAll('#agentimages img').length === 5")
            text = page.js("document.getElementById('agenttext').textContent")
            assert text.startswith("Take the interlocking puzzle apart") and "Views: " in text
        finally:
            page.close()
        page = open_page(devtools, f"{url}/play/probe")
        try:
            _ready(page, 0)
            page.js("document.getElementById('typed').focus()")
            page.call("Input.insertText", text=f"place {PROBE} <b>bold</b>")
            page.key("Enter")
            _ready(page, 1)
            feedback = page.js("document.getElementById('feedback').textContent")
            assert PROBE in feedback and "<b>bold</b>" in feedback
            labels = page.js("[...document.querySelectorAll('.label')].map(e => e.textContent)")
            assert PROBE in labels
            assert page.js("document.querySelectorAll('img').length") == 0  # no agent view here
            assert (
                page.js("document.querySelectorAll('#feedback *, #labels b, #pieces b').length")
                == 0
            )
            assert page.js("document.title") == "CHAIN-geo player"
        finally:
            page.close()


@pytest.mark.slow
def test_every_shipped_puzzle_and_some_stacking_levels_in_the_browser(devtools: str) -> None:
    """Free play: every shipped puzzle (clicks and keys) and the first ten stacking levels (keys
    alone) to the solved screen in exactly o_i steps."""
    from chaingeo.core.suite import shipped_levels

    ids = shipped_levels("puzzle") + shipped_levels("stacking")[:10]
    with running(Catalog({i: shipped_level(i) for i in ids})) as url:
        for level_id in ids:
            level = shipped_level(level_id)
            page = open_page(devtools, f"{url}/play/{level_id}")
            try:
                _solve(page, level, keys_only=level.family == "stacking")
                assert page.js("window.chainPlayer.status().steps") == level.optimal_steps
            except Exception as e:
                status = page.js("JSON.stringify(window.chainPlayer.status())")
                feedback = page.js("document.getElementById('feedback').textContent")
                raise AssertionError(f"{level_id}: {status} {feedback}") from e
            finally:
                page.close()
