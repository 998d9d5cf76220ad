"""Reports over run directories: the paper's tables (markdown and CSV) and the cost plot.

- **Table 1**: one row per run: Puzzle, Stacking and All success (Pass@1), Succ.Task,
  AvgSteps (solved), Dist2Opt, NormDist, tokens, cost, Solved per 1M tokens, Solved per USD.
- **Difficulty**: Pass@1 per family and difficulty tier.
- **Interactive vs one-shot**: the same agent under both protocols, and the difference in
  overall success (percentage points).
- **Selection**: for runs with several samples per level: Avg@k, Pass@1..k, Pass^1..k; for
  runs with verifier-based selection: their success, named by judge.

Every figure comes from the metric registry (:data:`~chaingeo.evaluation.metrics.METRICS`): rates
with a 95% interval, means with their standard error, the methods named in each table's caption
(markdown), and the bounds in columns of their own (CSV).
- **Cost vs success**: a scatter plot (PNG) of each run's cost against its overall success.
"""

from __future__ import annotations

import csv
import io
import math
import statistics
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any, Final

from chaingeo.core.files import atomic_path, atomic_write
from chaingeo.evaluation import stats
from chaingeo.evaluation.episode import Outcome
from chaingeo.evaluation.logs import HEADER, RunError, RunLog
from chaingeo.evaluation.metrics import (
    DIFFICULTIES,
    FAMILIES,
    METRICS,
    Metric,
    Summary,
    summarize,
)
from chaingeo.evaluation.stats import Estimate


@dataclass(frozen=True)
class Run:
    path: Path
    label: str  # the agent (model) name
    protocol: dict[str, Any]
    header: dict[str, Any]
    outcomes: list[Outcome]
    errors: int

    @property
    def name(self) -> str:
        """The row name: the label, qualified by protocol and selection when not plain."""
        extra = []
        if self.protocol.get("name") == "oneshot":
            extra.append("one-shot")
        if int(self.protocol.get("candidates", 1)) > 1:
            extra.append(f"best of {self.protocol['candidates']}, {self.protocol.get('judge')}")
        return f"{self.label} ({'; '.join(extra)})" if extra else self.label

    @cached_property
    def summary(self) -> Summary:
        return summarize(self.outcomes)


def find_runs(paths: Sequence[str | Path]) -> list[Path]:
    """Run directories named directly, or found one level below a folder of runs."""
    out: list[Path] = []
    for p in map(Path, paths):
        if (p / HEADER).exists():
            out.append(p)
        elif p.is_dir():
            found = sorted(d for d in p.iterdir() if (d / HEADER).exists())
            if not found:
                raise RunError(f"{p}: no run directories here")
            out.extend(found)
        else:
            raise RunError(f"{p}: not a run directory")
    return out


def load_run(path: str | Path) -> Run:
    log = RunLog(path)
    return run_of(path, log.header(), [Outcome.from_record(r) for r in log.latest().values()])


def run_of(path: str | Path, header: dict[str, Any], outcomes: list[Outcome]) -> Run:
    """The run of a header and its outcomes (read back by :func:`load_run`, or as
    :func:`chaingeo.evaluation.runner.evaluate` returns them)."""
    return Run(
        path=Path(path),
        label=str(header.get("label") or header["agent"]["name"]),
        protocol=dict(header.get("protocol", {})),
        header=header,
        outcomes=outcomes,
        errors=sum(1 for o in outcomes if o.error is not None),
    )


# ---------------------------------------------------------------------------------------------
# Tables: a header row and rows of values (registered metrics' Estimates); formatted by the
# registry for markdown and the site, raw with their uncertainty columns for CSV.
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Table:
    title: str
    columns: list[str]
    rows: list[list[Any]]
    #: The registered metric formatting each column (None: plain text).
    metrics: list[Metric | None]

    @property
    def formats(self) -> list[Callable[[Any], str]]:
        return [m.format if m is not None else _text for m in self.metrics]

    @property
    def caption(self) -> str:
        """The uncertainty methods the table's figures use, named."""
        used = {v.method for row in self.rows for v in row if isinstance(v, Estimate)}
        return "; ".join(text for key, text in stats.METHOD_TEXT.items() if key in used)

    def markdown(self) -> str:
        align = ["---"] + ["---:"] * (len(self.columns) - 1)
        lines = [f"### {self.title}", ""]
        if self.caption:
            lines += [f"Uncertainty: {self.caption}.", ""]
        lines += ["| " + " | ".join(self.columns) + " |", "|" + "|".join(align) + "|"]
        for row in self.rows:
            cells = [fmt(v) for fmt, v in zip(self.formats, row, strict=True)]
            lines.append("| " + " | ".join(cells) + " |")
        return "\n".join(lines) + "\n"

    def _extras(self, j: int) -> tuple[str, ...]:
        """The uncertainty fields of column ``j`` (CSV columns of their own, by its kind)."""
        m = self.metrics[j]
        return () if m is None else CSV_EXTRAS.get(m.kind, ())

    def csv(self) -> str:
        """Raw values; each estimate column followed by its ``low``/``high`` or ``stderr``."""
        extras = [self._extras(j) for j in range(len(self.columns))]
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        head: list[str] = []
        for title, more in zip(self.columns, extras, strict=True):
            head += [title, *(f"{title} {x}" for x in more)]
        w.writerow(head)
        for row in self.rows:
            line: list[Any] = []
            for v, more in zip(row, extras, strict=True):
                e = v if isinstance(v, Estimate) else None
                line.append(_raw(e.value if e is not None else v))
                line += [_raw(getattr(e, x, None)) for x in more]
            w.writerow(line)
        return buf.getvalue()


#: The uncertainty columns a metric kind adds to a CSV table (a fixed schema whatever the data).
CSV_EXTRAS: dict[str, tuple[str, ...]] = {
    "rate": ("low", "high", "stderr"),
    "ratio": ("low", "high"),
    "mean": ("stderr",),
}


def _raw(v: Any) -> Any:
    return "" if v is None else v


def sort_value(v: Any) -> Any:
    """What a cell sorts by: an estimate's value, anything else as it is."""
    return v.value if isinstance(v, Estimate) else v


def _text(v: Any) -> str:
    return str(v)


#: Table 1's columns after the agent: (metric, family) pairs; the title is the family's or
#: the metric's.
TABLE1: tuple[tuple[str, str | None], ...] = (
    ("pass@1", "puzzle"),
    ("pass@1", "stacking"),
    ("pass@1", None),
    ("succ_task", None),
    ("episodes", None),
    ("avg_steps", None),
    ("dist2opt", None),
    ("normdist", None),
    ("tokens_per_episode", None),
    ("tokens", None),
    ("cost_usd", None),
    ("solved_per_mtok", None),
    ("solved_per_usd", None),
)


def table1(runs: Sequence[Run]) -> Table:
    rows = [[r.name] + [r.summary.estimate(m, f) for m, f in TABLE1] for r in runs]
    titles = [
        (f.capitalize() if f else "All") if m == "pass@1" else METRICS[m].title for m, f in TABLE1
    ]
    return Table(
        "Table 1: success and efficiency (Pass@1, %)",
        ["Agent", *titles],
        rows,
        [None] + [METRICS[m] for m, _ in TABLE1],
    )


def difficulty_table(runs: Sequence[Run]) -> Table:
    keys = [(f, d) for f in FAMILIES for d in DIFFICULTIES]
    rows = [[r.name] + [r.summary.estimate("pass@1", f, d) for f, d in keys] for r in runs]
    return Table(
        "Success by difficulty (Pass@1, %)",
        ["Agent"] + [f"{f.capitalize()} {d.capitalize()}" for f, d in keys],
        rows,
        [None] + [METRICS["pass@1"]] * len(keys),
    )


def protocol_table(runs: Sequence[Run]) -> Table:
    """Agents that have both a plain interactive and a one-shot run."""
    plain = {
        r.label: r
        for r in runs
        if r.protocol.get("name") == "interactive" and int(r.protocol.get("candidates", 1)) == 1
    }
    oneshot = {r.label: r for r in runs if r.protocol.get("name") == "oneshot"}
    rows = []
    for label in sorted(set(plain) & set(oneshot)):
        a, b = plain[label].summary, oneshot[label].summary
        cells = [s.estimate("pass@1", f) for s in (a, b) for f in ("puzzle", "stacking", None)]
        delta = stats.difference(cells[2], cells[5])
        rows.append([label, *cells, delta])
    return Table(
        "Interactive vs one-shot (Pass@1, %; Δ = interactive - one-shot, points)",
        [
            "Agent",
            "Interactive Puzzle",
            "Interactive Stacking",
            "Interactive All",
            "One-shot Puzzle",
            "One-shot Stacking",
            "One-shot All",
            "Δ",
        ],
        rows,
        [None] + [METRICS["pass@1"]] * 7,
    )


def selection_table(runs: Sequence[Run]) -> Table:
    """Avg@k, Pass@k and Pass^k of multi-sample runs (± standard error over levels), and the
    success of verifier-selected runs."""
    rows: list[list[Any]] = []
    for r in runs:
        s = r.summary
        if s.samples > 1:
            k = s.samples
            rows.append([r.name, f"Avg@{k}", s.estimate("avg@k", k=k)])
            rows.extend([r.name, f"Pass@{j}", s.estimate("pass@k", k=j)] for j in s.ks)
            rows.extend([r.name, f"Pass^{j}", s.estimate("pass^k", k=j)] for j in s.ks)
        if int(r.protocol.get("candidates", 1)) > 1:
            rows.append([r.name, f"verifier + {r.protocol.get('judge')}", s.estimate("pass@1")])
    return Table(
        "Selection signal (%)",
        ["Agent", "Strategy", "All"],
        rows,
        [None, None, METRICS["pass@1"]],
    )


def cost_plot(runs: Sequence[Run], path: str | Path) -> Path:
    """Scatter: run cost in USD (symmetric log axis, so free baselines sit at 0) vs success."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.2), dpi=120)
    for r in runs:
        s = r.summary
        ok, cost = s.estimate("pass@1"), s.value("cost_usd")
        if ok.value is None:
            continue
        x = cost if cost is not None else 0.0
        marker = "o" if cost is not None else "x"
        y = 100 * ok.value
        err = None
        if ok.low is not None and ok.high is not None:  # the 95% interval as an error bar
            err = [[y - 100 * ok.low], [100 * ok.high - y]]
        ax.errorbar([x], [y], yerr=err, fmt=marker, markersize=6, capsize=3)
        ax.annotate(r.name, (x, y), textcoords="offset points", xytext=(5, 4), fontsize=8)
    ax.set_xscale("symlog", linthresh=0.01)
    costs = [r.summary.value("cost_usd") or 0.0 for r in runs]
    ax.set_xlim(left=-0.001, right=max([0.1, *costs]) * 3)
    ax.set_xlabel("cost of the run (USD; x = unknown price)")
    ax.set_ylabel("success, all levels (Pass@1, %, 95% interval)")
    ax.set_ylim(-5, 105)
    ax.grid(True, alpha=0.3)
    ax.set_title("Cost versus success")
    fig.tight_layout()
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(out) as tmp:
        fig.savefig(tmp, format="png", metadata={"Software": None})
    plt.close(fig)
    return out


# ---------------------------------------------------------------------------------------------
# Human baselines (chain serve --study): solve times by tier, as the paper calibrates its tiers
# ---------------------------------------------------------------------------------------------

#: The paper's tiers of human solve time, in seconds: easy under 5 minutes, medium 5-15, hard
#: over 15.
TIME_TIERS: Final = ((0.0, 300.0), (300.0, 900.0), (900.0, math.inf))


def is_human(run: Run) -> bool:
    agent = run.header.get("agent")
    return isinstance(agent, dict) and agent.get("kind") == "human"


def _human_row(name: str, tier: str, records: Sequence[dict[str, Any]]) -> list[Any]:
    won = [r for r in records if r.get("success")]
    times = [float(r["solve_seconds"]) for r in won if r.get("solve_seconds") is not None]
    # each time tier's share of the solves: a rate, with its Wilson interval
    shares = [stats.rate(sum(1 for t in times if a <= t < b), len(times)) for a, b in TIME_TIERS]
    outcomes = [Outcome.from_record(r) for r in records]
    figures = [METRICS[m].compute(outcomes, 1) for m in _HUMAN_METRICS]
    median = f"{statistics.median(times):.0f}" if times else "—"
    return [name, tier, *figures, median, *shares]


#: The registered metrics of the human table, after the study and the tier.
_HUMAN_METRICS: Final = ("episodes", "pass@1", "avg_steps", "normdist")


def human_table(runs: Sequence[Run]) -> Table:
    """Each human study's episodes by tier (family and difficulty, then all): Pass@1 with its
    95% interval, AvgSteps and NormDist of the solved (mean ± standard error), the median
    solve time, and the share (%) of solves under 5, 5-15 and over 15 minutes (each with its
    95% Wilson interval)."""
    rows: list[list[Any]] = []
    for run in (r for r in runs if is_human(r)):
        records = list(RunLog(run.path).latest().values())
        for f, d in ((f, d) for f in FAMILIES for d in DIFFICULTIES):
            tier = [r for r in records if r["family"] == f and r["difficulty"] == d]
            if tier:
                rows.append(_human_row(run.name, f"{f} {d}", tier))
        rows.append(_human_row(run.name, "all", records))
    titles = [METRICS[m].title for m in _HUMAN_METRICS]
    return Table(
        "Human baseline: success and solve times by tier (Pass@1, %)",
        ["Study", "Tier", *titles, "Median solve s", "< 5 min %", "5-15 min %", "> 15 min %"],
        rows,
        [None, None, *(METRICS[m] for m in _HUMAN_METRICS), None, *[METRICS["pass@1"]] * 3],
    )


def tables(runs: Sequence[Run]) -> list[tuple[str, Table]]:
    out = [("table1", table1(runs)), ("difficulty", difficulty_table(runs))]
    if any(is_human(r) for r in runs):
        out.append(("human", human_table(runs)))
    proto = protocol_table(runs)
    if proto.rows:
        out.append(("interactive_vs_oneshot", proto))
    sel = selection_table(runs)
    if sel.rows:
        out.append(("selection", sel))
    return out


def write_report(runs: Sequence[Run], out_dir: str | Path) -> list[Path]:
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for name, table in tables(runs):
        for suffix, text in ((".md", table.markdown()), (".csv", table.csv())):
            f = out / f"{name}{suffix}"
            written.append(atomic_write(f, text.encode("utf-8")))
    written.append(cost_plot(runs, out / "cost_success.png"))
    return written
