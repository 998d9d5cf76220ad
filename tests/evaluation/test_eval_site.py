"""``chain report --html``: the static run viewer.

Runs are made here, small and real: a scripted model (the fake OpenAI server) plays three
shipped levels through the real environment, so turns carry real rendered pictures, model
replies laced with markup, parsed actions, errors, tokens and cost; the oracle and the random
baseline play the same levels. The site is then checked as files (same numbers as the report,
escaping, relative local assets only, deterministic bytes) and in headless Chromium, which
loads it from disk and drives the real click and key handlers through the page's self-test
hook (see ``chaingeo/evaluation/site.js``).
"""

from __future__ import annotations

import hashlib
import io
import json
import re
import shutil
import subprocess
from html import escape, unescape
from html.parser import HTMLParser
from pathlib import Path
from typing import Any

import pytest
from PIL import Image

from chaingeo.cli.main import main
from chaingeo.core.level import Level, load_level
from chaingeo.core.suite import suite_folder
from chaingeo.evaluation.agents.base import AgentSpec
from chaingeo.evaluation.agents.baselines import oracle_plan
from chaingeo.evaluation.episode import ProtocolConfig
from chaingeo.evaluation.logs import RunError
from chaingeo.evaluation.report.site import write_site
from chaingeo.evaluation.report.tables import find_runs, load_run, sort_value, table1
from chaingeo.evaluation.runner import RunConfig, evaluate
from chaingeo.evaluation.usage import PriceTable
from tests.support.fake_openai import Script, fake_openai, reply
from tests.support.harness import fake_levels

LEVELS = (
    "stacking/stacking-2x2x2-easy-s101-000000.json",
    "stacking/stacking-2x2x2-mid-s102-000000.json",
    "puzzle/puzzle-easy-04-burr6.json",
)
HOSTILE = '<script>alert("x")</script><img src=x onerror=alert(1)> & <b>bold</b>'


def _levels() -> list[Level]:
    return [load_level(suite_folder() / name) for name in LEVELS]


def _act(text: str) -> str:
    return f"<action>{text}</action>"


@pytest.fixture(scope="module")
def made(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, PriceTable]:
    """Four runs over three shipped levels; returns the folder of runs and the price table."""
    root = tmp_path_factory.mktemp("site-runs")
    levels = _levels()
    easy, _, burr = (oracle_plan(lv) for lv in levels)
    (root / "prices.json").write_text(
        json.dumps({"models": {"fake-model": {"input": 2.0, "output": 8.0}}})
    )
    prices = PriceTable.load(root / "prices.json")
    cfg = RunConfig(progress=False)
    interactive = [
        reply(f"{HOSTILE}\n{_act('place red at 0 0 0')}", 1000, 60),  # illegal
        reply("I think </pre></article> is fine", 1100, 20),  # unparseable
        *(reply(f"Next: {_act(a)}", 1200 + 10 * i, 30) for i, a in enumerate(easy)),
        reply(_act("finish"), 900, 10),  # gives up on the mid level
        *(reply(_act(a), 1500, 40) for a in burr),
    ]
    oneshot = [reply("Plan:\n" + "\n".join(_act(a) for a in easy), 2000, 300)]
    for name, entries, proto in (
        ("vlm-interactive", interactive, ProtocolConfig()),
        ("vlm-oneshot", oneshot, ProtocolConfig(name="oneshot")),
    ):
        with fake_openai(Script(entries)) as url:
            spec = AgentSpec("openai", {"model": "fake-model", "base_url": url, "timeout": 5.0})
            evaluate(levels, spec, root / "runs" / name, proto, cfg, prices)
    evaluate(levels, AgentSpec("oracle"), root / "runs" / "oracle-interactive", None, cfg)
    evaluate(levels, AgentSpec("random"), root / "runs" / "random-interactive", None, cfg)
    return root / "runs", prices


@pytest.fixture(scope="module")
def site(made: tuple[Path, PriceTable], tmp_path_factory: pytest.TempPathFactory) -> Path:
    runs_dir, prices = made
    runs = [load_run(p) for p in find_runs([runs_dir])]
    return write_site(runs, tmp_path_factory.mktemp("site") / "site", prices)


class _Tables(HTMLParser):
    """Every table of a page: id -> rows of cell texts (header row first)."""

    def __init__(self) -> None:
        super().__init__()
        self.tables: dict[str, list[list[str]]] = {}
        self._table: list[list[str]] | None = None
        self._cell: list[str] | None = None

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        if tag == "table":
            self._table = self.tables.setdefault(dict(attrs).get("id") or "", [])
        elif tag == "tr" and self._table is not None:
            self._table.append([])
        elif tag in ("td", "th"):
            self._cell = []

    def handle_endtag(self, tag: str) -> None:
        if tag in ("td", "th") and self._cell is not None and self._table is not None:
            self._table[-1].append("".join(self._cell))
            self._cell = None
        elif tag == "table":
            self._table = None

    def handle_data(self, data: str) -> None:
        if self._cell is not None:
            self._cell.append(data)


def _tables(html: str) -> dict[str, list[list[str]]]:
    parser = _Tables()
    parser.feed(html)
    return parser.tables


def _pages(site: Path) -> list[Path]:
    return sorted(site.rglob("*.html"))


def _episode(site: Path, run: str, level: str) -> Path:
    return site / "episodes" / run / f"{level}-s0.html"


# ---------------------------------------------------------------------------------------------
# The site as files
# ---------------------------------------------------------------------------------------------


def test_leaderboard_shows_the_reports_numbers(made: tuple[Path, PriceTable], site: Path) -> None:
    runs = [load_run(p) for p in find_runs([made[0]])]
    expected = table1(runs)
    shown = _tables((site / "index.html").read_text("utf-8"))
    assert shown["table1"][0] == expected.columns
    want = [[f(v) for f, v in zip(expected.formats, row, strict=True)] for row in expected.rows]
    assert shown["table1"][1:] == want
    assert {"difficulty", "interactive_vs_oneshot", "levels"} <= set(shown)
    # the same error bars as the markdown and the CSV, and the caption naming their methods
    assert f"Uncertainty: {expected.caption}." in (site / "index.html").read_text("utf-8")
    assert all("[" in cell for cell in [row[3] for row in shown["table1"][1:]])
    assert shown["difficulty"][0][1:] == [
        f"{f} {d}" for f in ("Puzzle", "Stacking") for d in ("Easy", "Mid", "Hard")
    ]
    # The plot and the CSV tables are the report's own files, referred to relatively.
    assert (site / "report" / "cost_success.png").read_bytes().startswith(b"\x89PNG")
    assert (site / "report" / "table1.csv").read_text() == expected.csv()


def test_every_level_has_a_page_with_every_runs_result(site: Path) -> None:
    for level in _levels():
        rows = _tables((site / "levels" / f"{level.id}.html").read_text("utf-8"))["episodes"]
        assert sorted(r[0] for r in rows[1:]) == [
            "fake-model",
            "fake-model (one-shot)",
            "oracle",
            "random",
        ]
        assert all(r[-1] == "view turns" for r in rows[1:])
    page = site / "levels" / f"{_levels()[0].id}.html"
    by_run = {r[0]: r for r in _tables(page.read_text("utf-8"))["episodes"][1:]}
    assert by_run["oracle"][2] == "solved" and by_run["fake-model"][2] == "solved"
    assert by_run["fake-model"][3:5] == ["4", "2"]  # 4 steps used, 2 of them invalid


def test_episode_page_has_every_turn_escaped(site: Path) -> None:
    page = _episode(site, "vlm-interactive", _levels()[0].id).read_text("utf-8")
    assert page.count('class="frame"') == 4
    # Replies are text: the markup a model wrote is shown, never parsed.
    assert escape(HOSTILE) in page
    assert "<b>bold" not in page and "onerror=alert" not in page.replace("onerror=alert(1)&gt;", "")
    assert "I think &lt;/pre&gt;&lt;/article&gt; is fine" in page
    assert re.findall(r"<script[^>]*>", page) == ['<script src="../../assets/site.js">']
    # Parsed action, feedback, error kind, tokens and the turn's own cost.
    assert "place green (1,2,1) (1,2,2) (2,2,1) (2,2,2)" in page
    assert "Illegal action" in page and "unparseable" in page
    assert "1060 (1000 in" in page and "$0.0025" in page  # 1000 * 2 + 60 * 8 per 1M


def test_oneshot_episode_starts_with_the_plan(site: Path) -> None:
    page = _episode(site, "vlm-oneshot", _levels()[0].id).read_text("utf-8")
    frames = re.findall(r'data-label="([^"]*)"', page)
    assert frames == ["Plan", "Turn 1", "Turn 2"]
    assert "One-shot plan" in page and "Actions read from it" in page


def test_pictures_are_copied_and_referenced_relatively(site: Path) -> None:
    for page in _pages(site):
        text = page.read_text("utf-8")
        for ref in re.findall(r'(?:src|href)="([^"]*)"', text):
            assert not re.match(r"[a-z]+:|//", ref), f"{page}: non-local reference {ref}"
            target = (page.parent / ref).resolve()
            assert target.is_file() and site.resolve() in target.parents, (page, ref)
    images = list((site / "images").iterdir())
    assert len(images) > 5
    for img in images:
        assert hashlib.sha256(img.read_bytes()).hexdigest() + ".png" == img.name
    for asset in ("site.js", "site.css"):
        assert "http" not in (site / "assets" / asset).read_text()


def test_same_runs_give_the_same_bytes(made: tuple[Path, PriceTable], tmp_path: Path) -> None:
    runs = [load_run(p) for p in find_runs([made[0]])]
    a = write_site(runs, tmp_path / "a", made[1])
    b = write_site(runs, tmp_path / "b", made[1])

    def files(root: Path) -> dict[str, bytes]:
        return {str(p.relative_to(root)): p.read_bytes() for p in root.rglob("*") if p.is_file()}

    assert files(a) == files(b)
    write_site(runs, a, made[1])  # an earlier site is replaced...
    assert files(a) == files(b)
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("keep")
    with pytest.raises(RunError, match="not written by"):  # ...any other folder is refused
        write_site(runs, tmp_path / "mine", made[1])
    assert (tmp_path / "mine" / "notes.txt").read_text() == "keep"


def test_turn_costs_need_the_runs_prices(made: tuple[Path, PriceTable], tmp_path: Path) -> None:
    runs = [load_run(made[0] / "vlm-interactive")]
    site = write_site(runs, tmp_path / "s")  # the shipped table has no fake-model
    page = _episode(site, "vlm-interactive", _levels()[0].id).read_text("utf-8")
    assert "does not reproduce" in page and "$0.0025" not in page


def test_candidates_and_errored_episodes(tmp_path: Path) -> None:
    """Verifier runs show each turn's candidates; an episode that broke shows its error."""
    proto = ProtocolConfig(env="tests.support.faulty_env", candidates=2)
    run = tmp_path / "run"
    evaluate(fake_levels(3, pieces=2), AgentSpec("random"), run, proto, RunConfig(progress=False))
    site = write_site([load_run(run)], tmp_path / "site")
    ok = (site / "episodes" / "run" / "L00-s0.html").read_text("utf-8")
    assert "<h4>Candidates</h4>" in ok and "<td>chosen</td>" in ok
    broken = (site / "episodes" / "run" / "L01-s0.html").read_text("utf-8")
    assert "ZeroDivisionError: the environment divided by zero" in broken
    assert "No turn was played." in broken and 'class="frame"' not in broken
    matrix = _tables((site / "index.html").read_text("utf-8"))["levels"]
    assert [r[-1] for r in matrix[1:]] == ["solved", "error", "error"]


def test_chain_report_html(made: tuple[Path, PriceTable], tmp_path: Path) -> None:
    args = ["report", str(made[0]), "--out", str(tmp_path / "rep"), "--html", str(tmp_path / "s")]
    assert main([*args, "--prices", str(made[0].parent / "prices.json")]) == 0
    assert (tmp_path / "s" / "index.html").exists() and (tmp_path / "rep" / "table1.md").exists()
    (tmp_path / "other").mkdir()
    (tmp_path / "other" / "x").write_text("")
    assert main([*args[:-1], str(tmp_path / "other")]) == 2


# ---------------------------------------------------------------------------------------------
# The site in a browser: headless Chromium from disk, no driver
# ---------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def chromium() -> str:
    """The browser, or a skip that says how to get one (asked first, before runs are made)."""
    for name in ("chromium", "chromium-browser", "google-chrome"):
        found = shutil.which(name)
        if found:
            return found
    pytest.skip(
        "no Chromium on PATH: the browser test of the HTML run viewer needs it "
        "(Debian: apt-get install chromium; .ci/run installs it where apt is usable)"
    )


def _browse(chromium: str, tmp_path: Path, url: str, *extra: str) -> str:
    """Run headless Chromium on ``url``; returns what it printed (the DOM for --dump-dom)."""
    cmd = [
        chromium,
        "--headless",
        "--disable-gpu",
        "--no-sandbox",
        "--no-first-run",
        "--hide-scrollbars",
        "--disable-dev-shm-usage",
        f"--user-data-dir={tmp_path / 'profile'}",
        "--virtual-time-budget=5000",
        *extra,
        url,
    ]
    done = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stdout


def _selftest(dom: str) -> tuple[list[tuple[str, dict[str, Any]]], dict[str, str]]:
    """What the page's self-test wrote, (action, state shown after it) per line, and the
    attributes of its element."""
    match = re.search(r'<pre id="selftest"([^>]*)>(.*?)</pre>', dom, re.S)
    assert match, "the self-test did not run (no <pre id=selftest> in the DOM)"
    attrs = dict(re.findall(r'([\w-]+)="([^"]*)"', match.group(1)))
    lines = [ln.split(" ", 1) for ln in unescape(match.group(2)).strip().splitlines()]
    return [(action, json.loads(state)) for action, state in lines], attrs


def _click_sorted(rows: list[list[Any]], col: int, desc: bool) -> list[list[Any]]:
    """What the page's sort should give: stable, by raw value, rows without one last."""
    have = [r for r in rows if r[col] is not None]
    return sorted(have, key=lambda r: r[col], reverse=desc) + [r for r in rows if r[col] is None]


def test_browser_sorts_the_leaderboard(
    chromium: str, made: tuple[Path, PriceTable], site: Path, tmp_path: Path
) -> None:
    table = table1([load_run(p) for p in find_runs([made[0]])])
    rows = [[sort_value(v) for v in r] for r in table.rows]
    mtok = table.columns.index("Solved/1M tok")
    clicks = [(3, False), (3, True), (mtok, False), (mtok, True), (0, False)]
    # Telling data: "All" differs between runs; "Solved/1M tok" is blank for the baselines.
    assert len({r[3] for r in rows}) > 1 and {r[mtok] is None for r in rows} == {True, False}
    expected = [[r[0] for r in rows]]
    for col, desc in clicks:
        rows = _click_sorted(rows, col, desc)
        expected.append([r[0] for r in rows])
    actions = ",".join(f"sort:table1.{col}" for col, _ in clicks)
    dom = _browse(
        chromium, tmp_path, (site / "index.html").as_uri() + f"?selftest={actions}", "--dump-dom"
    )
    lines, attrs = _selftest(dom)
    assert attrs.get("data-done") == "yes"
    assert [action for action, _ in lines] == ["start", *actions.split(",")]
    assert [shown["table1"] for _, shown in lines] == expected
    assert all(shown["levels"] == lines[0][1]["levels"] for _, shown in lines)  # untouched
    # The final DOM carries the state the click handler set, and the plot was loaded.
    assert re.search(r'<th scope="col" class="text" aria-sort="ascending"><button[^>]*>Agent<', dom)
    assert attrs["data-images"] == "1/1"
    # The URL hash sorts too (what a shared link does).
    dom = _browse(
        chromium, tmp_path, (site / "index.html").as_uri() + "#sort=table1.3&dir=desc", "--dump-dom"
    )
    assert [r[0] for r in _tables(dom)["table1"][1:]] == expected[2]


def test_browser_steps_an_episode(chromium: str, site: Path, tmp_path: Path) -> None:
    page = _episode(site, "vlm-interactive", _levels()[0].id)
    actions = (
        "key:ArrowRight,key:ArrowRight,key:ArrowLeft,click:next,click:prev,click:last,key:Home"
    )
    dom = _browse(chromium, tmp_path, page.as_uri() + f"?selftest={actions}#step=2", "--dump-dom")
    lines, attrs = _selftest(dom)
    assert attrs.get("data-done") == "yes"
    assert [(a, shown["step"]) for a, shown in lines] == [
        ("start", 2),
        ("key:ArrowRight", 3),
        ("key:ArrowRight", 4),
        ("key:ArrowLeft", 3),
        ("click:next", 4),
        ("click:prev", 3),
        ("click:last", 4),
        ("key:Home", 1),
    ]
    assert not any(shown["playing"] for _, shown in lines)
    # One turn visible, the others hidden; its five pictures loaded from ../../images.
    shown = re.findall(r'<article class="frame" id="frame-(\d)"([^>]*)>', dom)
    assert [(i, "hidden" in a) for i, a in shown] == [
        ("1", False),
        ("2", True),
        ("3", True),
        ("4", True),
    ]
    assert attrs["data-images"] == "5/5"
    assert 'id="position">Turn 1 (1 of 4)<' in dom
    assert "<img src=x" not in dom and "alert(1)&gt;" in dom


def test_browser_plays_an_episode(chromium: str, site: Path, tmp_path: Path) -> None:
    """Play steps on by itself (1.5 s a step at 1x), pause holds, speed changes the pace, it
    stops at the last step and plays again from the first; a step by hand pauses it."""
    page = _episode(site, "vlm-interactive", _levels()[0].id)
    script = [
        ("click:play", 1, True),
        ("wait:1600", 2, True),  # one step in 1.5 s
        ("click:play", 2, False),  # paused
        ("wait:1600", 2, False),  # and it stays
        ("select:speed=4", 2, False),
        ("click:play", 2, True),
        ("wait:400", 3, True),  # 4x: a step in 375 ms
        ("wait:400", 4, False),  # the last step: it stops by itself
        ("key:Space", 1, True),  # from the start again
        ("click:next", 2, False),  # a step by hand takes over
    ]
    actions = ",".join(a for a, _, _ in script)
    dom = _browse(chromium, tmp_path, page.as_uri() + f"?selftest={actions}#step=1", "--dump-dom")
    lines, attrs = _selftest(dom)
    assert attrs.get("data-done") == "yes"
    assert [(a, s["step"], s["playing"]) for a, s in lines] == [("start", 1, False), *script]
    assert re.search(r'<button type="button" id="play" aria-pressed="false">▶ Play<', dom)


def test_browser_screenshot_is_not_blank(chromium: str, site: Path, tmp_path: Path) -> None:
    page = _episode(site, "vlm-interactive", _levels()[2].id)  # a puzzle: coloured pieces
    shot = tmp_path / "shot.png"
    _browse(
        chromium,
        tmp_path,
        page.as_uri() + "#step=1",
        f"--screenshot={shot}",
        "--window-size=1200,900",
    )
    img = Image.open(io.BytesIO(shot.read_bytes())).convert("RGB")
    assert img.size == (1200, 900)
    colours = img.getcolors(maxcolors=1 << 20)
    assert colours is not None and len(colours) > 200, f"{len(colours or [])} colours"
    assert max(n for n, _ in colours) < 0.9 * img.size[0] * img.size[1]  # not one flat colour
