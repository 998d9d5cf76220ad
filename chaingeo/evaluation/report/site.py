"""A static run viewer: ``chain report RUNS --html DIR`` writes a site to open from disk.

Layout of ``DIR/``::

    index.html                     the leaderboard (the tables of :mod:`report`, sortable), the
                                   cost plot and a level-by-run matrix
    levels/<level>.html            one level: every run's episodes on it
    episodes/<run>/<level>-s<k>.html   one episode, turn by turn
    images/<sha256>.png            the turns' pictures, copied from the runs' ``images/``
    report/                        the markdown and CSV tables and ``cost_success.png``
    assets/site.css, site.js       the only style and script (package data beside this
                                   module); no CDN, nothing fetched

Why it looks the way it does:

- **Same numbers as the report.** The leaderboard renders :func:`report.tables` (the same
  :class:`~chaingeo.evaluation.report.tables.Table` rows and formatters the markdown uses), and the
  plot and CSV files are :func:`report.write_report` output; nothing here recomputes a metric.
- **Logs are untrusted text.** Model replies can contain anything, markup included: every
  string from a run passes :func:`html.escape` here, and the script only ever sets
  ``textContent``. A Content-Security-Policy forbids inline scripts and any network access, so a
  slip in escaping still could not run code or phone home. Image names are used only when they
  are SHA-256 file names whose content matches, so a log cannot point outside the run.
- **Complete without JavaScript.** Every turn is in the page; the script hides all but one and
  steps through them (buttons, arrow keys, ``#step=N``, a play button with pause and speed)
  and sorts tables (header buttons,
  ``#sort=TABLE.COLUMN&dir=asc``).
- **Deterministic.** The same runs give the same bytes: no clocks, sorted iteration, stable
  file names. The site is built beside ``DIR`` and moved into place, and an existing ``DIR`` is
  replaced only when an earlier ``--html`` wrote it (it holds the ``.chain-site`` marker).
"""

from __future__ import annotations

import hashlib
import os
import re
import shutil
import tempfile
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from html import escape
from importlib import resources
from pathlib import Path
from typing import Any, Final

from chaingeo.core import limits
from chaingeo.core.files import UnreadableFile, atomic_write, folder_locked, read_bounded
from chaingeo.evaluation.logs import IMAGES, RunError, RunLog
from chaingeo.evaluation.report.tables import Run, Table, sort_value, tables, write_report
from chaingeo.evaluation.usage import PriceTable, Usage

MARKER: Final = ".chain-site"
ASSETS: Final = ("site.css", "site.js")
#: Allows the site's own files (file:// counts as 'self' in Chromium) and nothing else.
CSP: Final = (
    "default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self'; "
    "base-uri 'none'; form-action 'none'"
)
_IMAGE_NAME = re.compile(r"[0-9a-f]{64}\.png")
_UNSAFE = re.compile(r"[^A-Za-z0-9._-]+")
#: Views in the order the harness renders them; any others follow alphabetically.
_VIEW_ORDER = ("front", "side", "top", "iso", "tray", "target")


@dataclass(frozen=True)
class EpisodePage:
    """One episode record of one run, and where its page goes."""

    run: Run
    run_index: int
    record: dict[str, Any]
    page: str  # relative to the site root


def write_site(runs: Sequence[Run], out_dir: str | Path, prices: PriceTable | None = None) -> Path:
    """Write the site for ``runs`` to ``out_dir`` (see the module docstring) and return it.

    ``prices`` prices each turn (records carry a cost per episode only); give the table the
    runs were evaluated with. A turn's cost is shown only when the turns add up to the
    episode's recorded cost, so a differing table shows "—" rather than a wrong figure.
    """
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise RunError(f"{out}: not a folder")
    if out.exists() and not (out / MARKER).exists() and any(out.iterdir()):
        raise RunError(f"{out}: exists and was not written by `chain report --html`; pick another")
    with folder_locked(out):  # a second writer is refused, not raced
        build = Path(tempfile.mkdtemp(prefix=f".{out.name}.building.", dir=out.parent))
        try:
            build.chmod(0o755)
            _Builder(runs, build, prices or PriceTable.load()).build()
            if out.exists():
                shutil.rmtree(out)
            build.rename(out)
        finally:
            if build.exists():
                shutil.rmtree(build)
    return out


class _Builder:
    def __init__(self, runs: Sequence[Run], root: Path, prices: PriceTable) -> None:
        self.runs, self.root, self.prices = list(runs), root, prices
        self.run_slugs = _unique([_slug(r.path.name) for r in runs])
        self.episodes: list[EpisodePage] = []
        for i, run in enumerate(self.runs):
            records = sorted(
                RunLog(run.path).latest().values(),
                key=lambda r: (str(r.get("level_id")), int(r.get("sample", 0))),
            )
            pages = _unique(
                [f"{_slug(str(r.get('level_id')))}-s{int(r.get('sample', 0))}" for r in records]
            )
            for rec, page in zip(records, pages, strict=True):
                self.episodes.append(
                    EpisodePage(run, i, rec, f"episodes/{self.run_slugs[i]}/{page}.html")
                )
        level_ids = sorted({str(e.record.get("level_id")) for e in self.episodes})
        level_slugs = _unique([_slug(i) for i in level_ids])
        self.level_pages = {
            i: f"levels/{s}.html" for i, s in zip(level_ids, level_slugs, strict=True)
        }
        self.copied: set[str] = set()

    # -- files -------------------------------------------------------------------------------

    def write(self, rel: str, text: str) -> None:
        path = self.root / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        atomic_write(path, text.encode("utf-8"))

    def build(self) -> None:
        (self.root / MARKER).write_bytes(b"written by chain report --html\n")
        package = resources.files("chaingeo.evaluation.report")
        for name in ASSETS:
            self.write(f"assets/{name}", package.joinpath(name).read_text("utf-8"))
        write_report(self.runs, self.root / "report")
        self.write("index.html", self.index())
        for level_id, page in self.level_pages.items():
            self.write(page, self.level_page(level_id))
        for ep in self.episodes:
            self.write(ep.page, self.episode_page(ep))

    def image(self, run: Run, name: Any, up: str, alt: str) -> str:
        """An ``<img>`` of a run's stored picture, copied into the site; text when the name is
        not a content hash or the file is missing or altered."""
        name = str(name)
        if name not in self.copied:
            source = run.path / IMAGES / name
            inside = os.path.realpath(run.path) + os.sep + IMAGES + os.sep + name
            if not (_IMAGE_NAME.fullmatch(name) and os.path.realpath(source) == inside):
                return f'<p class="muted">picture missing: {escape(name)}</p>'
            try:  # a regular file of the run itself (no link out of it), bounded
                data = read_bounded(source, limits.MAX_RUN_IMAGE_BYTES)
            except UnreadableFile:
                return f'<p class="muted">picture missing: {escape(name)}</p>'
            if hashlib.sha256(data).hexdigest() + ".png" != name:
                return f'<p class="muted">picture altered: {escape(name)}</p>'
            (self.root / "images").mkdir(exist_ok=True)
            atomic_write(self.root / "images" / name, data)
            self.copied.add(name)
        return f'<img src="{up}images/{name}" alt="{escape(alt)}" loading="lazy">'

    # -- pages -------------------------------------------------------------------------------

    def index(self) -> str:
        parts = ["<h1>Leaderboard</h1>"]
        parts.append(
            '<p class="note">Click a column header to sort. Runs: '
            + ", ".join(escape(str(r.path.name)) for r in self.runs)
            + ". Downloads: "
            + ", ".join(
                f'<a href="report/{n}{s}">{n}{s}</a>'
                for n, _ in tables(self.runs)
                for s in (".csv", ".md")
            )
            + ".</p>"
        )
        for name, table in tables(self.runs):
            parts.append(f"<h2>{escape(table.title)}</h2>")
            if table.caption:
                parts.append(f'<p class="note">Uncertainty: {escape(table.caption)}.</p>')
            parts.append(_report_table(name, table))
        parts.append("<h2>Cost versus success</h2>")
        parts.append(
            '<img class="plot" src="report/cost_success.png" alt="cost of each run against its '
            'overall success">'
        )
        parts.append("<h2>Levels</h2>")
        parts.append(self.level_matrix())
        return _page("Leaderboard", "\n".join(parts), up="")

    def level_matrix(self) -> str:
        """Rows: levels; columns: runs; a cell: solved samples of the run on that level."""
        by_cell: dict[tuple[str, int], list[EpisodePage]] = {}
        facts: dict[str, dict[str, Any]] = {}
        for ep in self.episodes:
            level_id = str(ep.record.get("level_id"))
            by_cell.setdefault((level_id, ep.run_index), []).append(ep)
            facts.setdefault(level_id, ep.record)
        head = [("Level", False), ("Family", False), ("Tier", False), ("Optimal", True)]
        head += [(r.name, True) for r in self.runs]
        rows = []
        for level_id, page in self.level_pages.items():
            rec = facts[level_id]
            cells = [
                _cell(level_id, level_id, href=page),
                _cell(rec.get("family"), rec.get("family")),
                _cell(rec.get("difficulty"), rec.get("difficulty")),
                _cell(rec.get("optimal_steps"), rec.get("optimal_steps")),
            ]
            for i in range(len(self.runs)):
                eps = by_cell.get((level_id, i), [])
                if not eps:
                    cells.append(_cell("—", None))
                    continue
                won = sum(bool(e.record.get("success")) for e in eps)
                text = _result(eps[0].record)[0] if len(eps) == 1 else f"{won}/{len(eps)}"
                cls = "solved" if won else "error" if _errored(eps) else "unsolved"
                cells.append(_cell(text, won / len(eps), href=page, cls=cls))
            rows.append(cells)
        return _sortable("levels", head, rows)

    def level_page(self, level_id: str) -> str:
        eps = [e for e in self.episodes if str(e.record.get("level_id")) == level_id]
        rec = eps[0].record
        parts = [
            _crumbs([("Leaderboard", "../index.html")], level_id),
            f"<h1>{escape(level_id)}</h1>",
            _facts(
                [
                    ("Family", rec.get("family")),
                    ("Tier", rec.get("difficulty")),
                    ("Goal", rec.get("goal")),
                    ("Optimal steps", rec.get("optimal_steps")),
                    ("Step budget", rec.get("max_steps")),
                ]
            ),
        ]
        head = [("Run", False), ("Sample", True), ("Result", False), ("Steps", True)]
        head += [("Invalid", True), ("Tokens", True), ("USD", True), ("Episode", False)]
        rows = []
        for ep in eps:
            r = ep.record
            text, cls = _result(r)
            usage = Usage.from_json(r.get("usage") or {})
            rows.append(
                [
                    _cell(ep.run.name, ep.run.name),
                    _cell(r.get("sample", 0), r.get("sample", 0)),
                    _cell(text, text, cls=cls),
                    _cell(r.get("steps_used"), r.get("steps_used")),
                    _cell(r.get("invalid"), r.get("invalid")),
                    _cell(_tokens(usage.total_tokens), usage.total_tokens),
                    _cell(_usd(r.get("cost_usd")), r.get("cost_usd")),
                    _cell("view turns", None, href="../" + ep.page),
                ]
            )
        parts.append(_sortable("episodes", head, rows))
        return _page(level_id, "\n".join(parts), up="../")

    def episode_page(self, ep: EpisodePage) -> str:
        r, up = ep.record, "../../"
        level_id = str(r.get("level_id"))
        text, cls = _result(r)
        usage = Usage.from_json(r.get("usage") or {})
        title = f"{level_id} · {ep.run.name} · sample {r.get('sample', 0)}"
        parts = [
            _crumbs(
                [("Leaderboard", up + "index.html"), (level_id, up + self.level_pages[level_id])],
                f"{ep.run.name}, sample {r.get('sample', 0)}",
            ),
            f"<h1>{escape(title)}</h1>",
            _facts(
                [
                    ("Run", ep.run.path.name),
                    ("Agent", r.get("agent")),
                    ("Model", r.get("model")),
                    ("Protocol", r.get("protocol")),
                    ("Result", _span(text, cls)),
                    (
                        "Steps used",
                        f"{r.get('steps_used')} (optimal {r.get('optimal_steps')}, "
                        f"budget {r.get('max_steps')})",
                    ),
                    (
                        "Invalid turns",
                        f"{r.get('invalid')} (unparseable {r.get('unparseable')}, "
                        f"illegal {r.get('illegal')}, ambiguous {r.get('ambiguous')})",
                    ),
                    ("Tokens", _usage_text(usage)),
                    ("Cost", _usd(r.get("cost_usd"))),
                    ("Error", r.get("error")),
                ]
            ),
        ]
        frames = self.frames(ep, up)
        if r.get("cost_usd") is not None and usage.calls and self.turn_costs(r) is None:
            parts.append(
                '<p class="note">Per-turn cost: "—", the price table given to the report does '
                "not reproduce this episode's recorded cost (pass the run's --prices).</p>"
            )
        parts.append('<section id="viewer" class="viewer">')
        parts.append(
            '<div class="stepper"><button type="button" id="first">First</button>'
            '<button type="button" id="prev">◀ Previous</button><span id="position"></span>'
            '<button type="button" id="next">Next ▶</button>'
            '<button type="button" id="last">Last</button>'
            '<button type="button" id="play" aria-pressed="false">▶ Play</button>'
            '<label class="muted">speed <select id="speed">'
            '<option value="0.5">0.5&times;</option><option value="1" selected>1&times;</option>'
            '<option value="2">2&times;</option><option value="4">4&times;</option>'
            "</select></label>"
            '<span class="muted">or the ← → keys, space to play</span></div>'
        )
        parts.extend(frames or ['<p class="note">No turn was played.</p>'])
        parts.append("</section>")
        return _page(title, "\n".join(parts), up=up)

    def turn_costs(self, r: Mapping[str, Any]) -> list[float] | None:
        """USD of the plan (one-shot) and of each turn, when they add up to the record's."""
        recorded = r.get("cost_usd")
        if recorded is None:
            return None
        model = r.get("model")
        judge_model = (r.get("judge") or {}).get("model")
        items: list[tuple[Any, Any]] = []
        if isinstance(r.get("plan"), Mapping):
            items.append((r["plan"].get("usage"), None))
        items.extend((s.get("usage"), s.get("judge_usage")) for s in _steps(r))
        costs: list[float] = []
        for usage, judge in items:
            cost = self.prices.cost(model, Usage.from_json(usage or {}))
            if judge:
                extra = self.prices.cost(judge_model, Usage.from_json(judge))
                cost = None if cost is None or extra is None else cost + extra
            if cost is None:
                return None
            costs.append(cost)
        if abs(sum(costs) - float(recorded)) > 1e-9 * max(1.0, abs(float(recorded))):
            return None
        return costs

    def frames(self, ep: EpisodePage, up: str) -> list[str]:
        r = ep.record
        costs = self.turn_costs(r)
        out: list[str] = []
        plan = r.get("plan")
        if isinstance(plan, Mapping):
            body = [
                self.views(ep.run, plan.get("images"), up, "plan"),
                _block("Model reply", plan.get("reply")),
                _block("Actions read from it", "\n".join(map(str, plan.get("actions") or []))),
                _block("Harness note", plan.get("note")),
                _turn_usage(plan.get("usage"), costs[0] if costs else None),
            ]
            out.append(_frame(len(out), "Plan", "<h3>One-shot plan</h3>" + "".join(body)))
        offset = len(out)
        for i, s in enumerate(_steps(r)):
            turn = int(s.get("turn", i)) + 1
            kind = "legal" if s.get("legal") else str(s.get("error") or "illegal")
            body = [
                f"<h3>Turn {turn} {_span(kind, _slug(kind))}</h3>",
                self.views(ep.run, s.get("images"), up, f"turn {turn}"),
                _block("Model reply", s.get("reply")),
                _block("Reasoning", s.get("reasoning")),
                _facts(
                    [
                        ("Parsed action", s.get("action") or "none"),
                        (
                            "Sent",
                            s.get("sent") if s.get("sent") not in ("", s.get("action")) else None,
                        ),
                        ("Error", s.get("error")),
                    ]
                ),
                _block("Feedback", s.get("feedback")),
                _block("Harness note", s.get("note")),
                _candidates(s.get("candidates")),
                _turn_usage(s.get("usage"), costs[offset + i] if costs else None),
            ]
            out.append(_frame(len(out), f"Turn {turn}", "".join(body)))
        return out

    def views(self, run: Run, images: Any, up: str, what: str) -> str:
        if not isinstance(images, Mapping) or not images:
            return '<p class="muted">No pictures (this agent was not shown any).</p>'
        order = sorted(images, key=lambda v: (_VIEW_ORDER.index(v) if v in _VIEW_ORDER else 99, v))
        figs = [
            f"<figure>{self.image(run, images[v], up, f'{v} view, {what}')}"
            f"<figcaption>{escape(str(v))}</figcaption></figure>"
            for v in order
        ]
        return '<div class="views">' + "".join(figs) + "</div>"


# ---------------------------------------------------------------------------------------------
# HTML pieces: every argument that may come from a log is escaped here.
# ---------------------------------------------------------------------------------------------


def _page(title: str, body: str, up: str) -> str:
    return (
        "<!DOCTYPE html>\n"
        '<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        f'<meta http-equiv="Content-Security-Policy" content="{CSP}">\n'
        '<meta name="viewport" content="width=device-width, initial-scale=1">\n'
        f"<title>{escape(title)} — CHAIN-geo runs</title>\n"
        f'<link rel="stylesheet" href="{up}assets/site.css">\n'
        f"</head>\n<body>\n{body}\n"
        f'<script src="{up}assets/site.js"></script>\n</body>\n</html>\n'
    )


@dataclass(frozen=True)
class _Cell:
    text: str
    sort: str  # raw value for sorting; "" = none
    href: str | None = None
    cls: str | None = None


def _cell(text: Any, sort: Any, href: str | None = None, cls: str | None = None) -> _Cell:
    return _Cell("—" if text is None else str(text), _sort_key(sort), href, cls)


def _sort_key(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, bool):
        return str(int(v))
    if isinstance(v, int | float):
        return repr(float(v))
    return str(v)


def _sortable(table_id: str, head: Sequence[tuple[str, bool]], rows: Iterable[list[_Cell]]) -> str:
    """A table the script sorts: ``head`` is (title, numeric) per column."""
    kinds = {True: ' data-type="num"', False: ' class="text"'}
    ths = "".join(
        f'<th scope="col"{kinds[num]}><button type="button">{escape(title)}</button></th>'
        for title, num in head
    )
    body = []
    for row in rows:
        tds = []
        for c, (_, num) in zip(row, head, strict=True):
            cls = " ".join(x for x in (c.cls, None if num else "text") if x)
            text = escape(c.text)
            if c.href is not None:
                text = f'<a href="{escape(c.href)}">{text}</a>'
            attr = f' class="{cls}"' if cls else ""
            tds.append(f'<td data-sort="{escape(c.sort)}"{attr}>{text}</td>')
        body.append("<tr>" + "".join(tds) + "</tr>")
    return (
        f'<div class="scroll"><table class="sortable" id="{escape(table_id)}">'
        f"<thead><tr>{ths}</tr></thead>\n<tbody>\n" + "\n".join(body) + "\n</tbody></table></div>"
    )


def _report_table(name: str, table: Table) -> str:
    """A report table with its own formatters for the text and the raw values for sorting."""
    numeric = [
        all(isinstance(sort_value(row[j]), int | float | None) for row in table.rows) and j > 0
        for j in range(len(table.columns))
    ]
    rows = [
        [_Cell(fmt(v), _sort_key(sort_value(v))) for fmt, v in zip(table.formats, row, strict=True)]
        for row in table.rows
    ]
    return _sortable(name, list(zip(table.columns, numeric, strict=True)), rows)


def _crumbs(links: Sequence[tuple[str, str]], here: str) -> str:
    parts = [f'<a href="{escape(href)}">{escape(text)}</a>' for text, href in links]
    return '<nav class="crumbs">' + " \u203a ".join([*parts, escape(here)]) + "</nav>"


def _facts(items: Sequence[tuple[str, Any]]) -> str:
    """A definition list; values that are ``_Html`` go in as they are, others escaped; None
    values are left out."""
    rows = [
        f"<dt>{escape(k)}</dt><dd>{v if isinstance(v, _Html) else escape(str(v))}</dd>"
        for k, v in items
        if v is not None
    ]
    return '<dl class="facts">' + "".join(rows) + "</dl>" if rows else ""


class _Html(str):
    """Markup this module built itself (already escaped)."""


def _span(text: str, cls: str) -> _Html:
    return _Html(f'<span class="{escape(cls)}">{escape(text)}</span>')


def _block(title: str, text: Any) -> str:
    if text is None or text == "":
        return ""
    return f"<h4>{escape(title)}</h4><pre>{escape(str(text))}</pre>"


def _frame(index: int, label: str, body: str) -> str:
    return (
        f'<article class="frame" id="frame-{index + 1}" data-label="{escape(label)}">'
        f"{body}</article>"
    )


def _candidates(cands: Any) -> str:
    if not isinstance(cands, list) or not cands:
        return ""
    rows = "".join(
        "<tr>"
        + "".join(
            f"<td>{escape(str(x))}</td>"
            for x in (
                "chosen" if c.get("chosen") else "",
                c.get("action") or "none",
                "legal" if c.get("legal") else c.get("error") or "illegal",
                _tokens(Usage.from_json(c.get("usage") or {}).total_tokens),
            )
        )
        + "</tr>"
        for c in cands
        if isinstance(c, Mapping)
    )
    return (
        "<h4>Candidates</h4><table><thead><tr><th></th><th>Action</th><th>Check</th>"
        f"<th>Tokens</th></tr></thead><tbody>{rows}</tbody></table>"
    )


def _turn_usage(usage: Any, cost: float | None) -> str:
    u = Usage.from_json(usage if isinstance(usage, Mapping) else {})
    return _facts([("Tokens", _usage_text(u)), ("Cost", _usd(cost))])


def _usage_text(u: Usage) -> str:
    return (
        f"{u.total_tokens} ({u.input_tokens} in, of which {u.cached_tokens} cached; "
        f"{u.output_tokens} out, of which {u.reasoning_tokens} reasoning; {u.calls} calls)"
    )


def _usd(v: Any) -> str:
    return "—" if v is None else f"${float(v):.4f}"


def _tokens(n: int) -> str:
    return f"{n / 1e6:.2f}M" if n >= 1e6 else f"{n / 1e3:.1f}k" if n >= 1e3 else str(n)


def _steps(r: Mapping[str, Any]) -> list[dict[str, Any]]:
    steps = r.get("steps")
    return [s for s in steps if isinstance(s, dict)] if isinstance(steps, list) else []


def _result(r: Mapping[str, Any]) -> tuple[str, str]:
    """The outcome in words and its CSS class."""
    if r.get("status") == "error":
        return "error", "error"
    if r.get("success"):
        return "solved", "solved"
    if r.get("finished"):
        return "gave up", "unsolved"
    return ("out of steps" if r.get("truncated") else "unsolved"), "unsolved"


def _errored(eps: Sequence[EpisodePage]) -> bool:
    return any(e.record.get("status") == "error" for e in eps)


def _slug(text: str) -> str:
    """A file-name-safe form of a run or level name (anything else becomes ``_``)."""
    return _UNSAFE.sub("_", text).strip("._") or "_"


def _unique(names: Sequence[str]) -> list[str]:
    """``names`` with repeats made distinct by ``-2``, ``-3``... in order (deterministic)."""
    taken: set[str] = set()
    out = []
    for n in names:
        candidate, k = n, 1
        while candidate in taken:
            k += 1
            candidate = f"{n}-{k}"
        taken.add(candidate)
        out.append(candidate)
    return out
