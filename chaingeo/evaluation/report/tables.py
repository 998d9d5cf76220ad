"""Reports over run directories: the paper's tables (markdown and CSV) and the cost plot.

- **Table 1**: one row per run: Puzzle, Stacking and All success (Pass@1), Succ.Task,
  AvgSteps (solved), Dist2Opt, NormDist, tokens, cost, Solved per 1M tokens, Solved per USD.
- **Difficulty**: Pass@1 per family and difficulty tier.
- **Interactive vs one-shot**: the same agent under both protocols, and the difference in
  overall success (percentage points).
- **Selection**: for runs with several samples per level: Avg@k, Pass@1..k; for runs with
  verifier-based selection: their success, named by judge.
- **Cost vs success**: a scatter plot (PNG) of each run's cost against its overall success.
"""

from __future__ import annotations

import csv
import io
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from chaingeo.core.files import atomic_path, atomic_write
from chaingeo.evaluation.logs import HEADER, RunError, RunLog
from chaingeo.evaluation.metrics import DIFFICULTIES, FAMILIES, Outcome, Summary, summarize
from chaingeo.evaluation.runner import outcome_of


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

    @property
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
    header = log.header()
    latest = list(log.latest().values())
    return Run(
        path=Path(path),
        label=str(header.get("label") or header["agent"]["name"]),
        protocol=dict(header.get("protocol", {})),
        header=header,
        outcomes=[outcome_of(r) for r in latest],
        errors=sum(1 for r in latest if r.get("status") == "error"),
    )


# ---------------------------------------------------------------------------------------------
# Tables: a header row and rows of raw values; formatted for markdown, raw for CSV.
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Table:
    title: str
    columns: list[str]
    rows: list[list[Any]]
    formats: list[Callable[[Any], str]]

    def markdown(self) -> str:
        align = ["---"] + ["---:"] * (len(self.columns) - 1)
        lines = [
            f"### {self.title}",
            "",
            "| " + " | ".join(self.columns) + " |",
            "|" + "|".join(align) + "|",
        ]
        for row in self.rows:
            cells = [fmt(v) for fmt, v in zip(self.formats, row, strict=True)]
            lines.append("| " + " | ".join(cells) + " |")
        return "\n".join(lines) + "\n"

    def csv(self) -> str:
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(self.columns)
        for row in self.rows:
            w.writerow(["" if v is None else v for v in row])
        return buf.getvalue()


def _text(v: Any) -> str:
    return str(v)


def _pct(v: Any) -> str:
    return "—" if v is None else f"{100 * v:.1f}"


def _num(digits: int) -> Callable[[Any], str]:
    def fmt(v: Any) -> str:
        return "—" if v is None else f"{v:.{digits}f}"

    return fmt


def _int(v: Any) -> str:
    return "—" if v is None else str(int(v))


def _tok(v: Any) -> str:
    if v is None:
        return "—"
    return f"{v / 1e6:.2f}M" if v >= 1e6 else f"{v / 1e3:.1f}k" if v >= 1e3 else str(v)


def table1(runs: Sequence[Run]) -> Table:
    rows = []
    for r in runs:
        s = r.summary
        rows.append(
            [
                r.name,
                s.puzzle,
                s.stacking,
                s.pass_at_1,
                s.succ_task,
                s.episodes,
                s.avg_steps,
                s.dist2opt,
                s.normdist,
                s.usage.total_tokens,
                s.cost_usd,
                s.solved_per_mtok,
                s.solved_per_usd,
            ]
        )
    return Table(
        "Table 1: success and efficiency (Pass@1, %)",
        [
            "Agent",
            "Puzzle",
            "Stacking",
            "All",
            "Succ.Task",
            "Episodes",
            "AvgSteps",
            "Dist2Opt",
            "NormDist",
            "Tokens",
            "USD",
            "Solved/1M tok",
            "Solved/USD",
        ],
        rows,
        [
            _text,
            _pct,
            _pct,
            _pct,
            _int,
            _int,
            _num(2),
            _num(2),
            _num(3),
            _tok,
            _num(4),
            *[_num(2)] * 2,
        ],
    )


def difficulty_table(runs: Sequence[Run]) -> Table:
    keys = [(f, d) for f in FAMILIES for d in DIFFICULTIES]
    rows = [[r.name] + [r.summary.by_difficulty[f"{f}/{d}"] for f, d in keys] for r in runs]
    return Table(
        "Success by difficulty (Pass@1, %)",
        ["Agent"] + [f"{f.capitalize()} {d.capitalize()}" for f, d in keys],
        rows,
        [_text] + [_pct] * len(keys),
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
        delta = None if a.pass_at_1 is None or b.pass_at_1 is None else a.pass_at_1 - b.pass_at_1
        rows.append(
            [label, a.puzzle, a.stacking, a.pass_at_1, b.puzzle, b.stacking, b.pass_at_1, delta]
        )
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
        [_text] + [_pct] * 7,
    )


def selection_table(runs: Sequence[Run]) -> Table:
    """Avg@k and Pass@k of multi-sample runs, and the success of verifier-selected runs."""
    rows: list[list[Any]] = []
    for r in runs:
        s = r.summary
        if s.samples > 1:
            k = s.samples
            rows.append([r.name, f"Avg@{k}", s.avg_at.get(k)])
            rows.extend([r.name, f"Pass@{j}", v] for j, v in sorted(s.pass_at.items()))
        if int(r.protocol.get("candidates", 1)) > 1:
            rows.append([r.name, f"verifier + {r.protocol.get('judge')}", s.pass_at_1])
    return Table("Selection signal (%)", ["Agent", "Strategy", "All"], rows, [_text, _text, _pct])


def cost_plot(runs: Sequence[Run], path: str | Path) -> Path:
    """Scatter: run cost in USD (symmetric log axis, so free baselines sit at 0) vs success."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.2), dpi=120)
    for r in runs:
        s = r.summary
        if s.pass_at_1 is None:
            continue
        x = s.cost_usd if s.cost_usd is not None else 0.0
        marker = "o" if s.cost_usd is not None else "x"
        ax.scatter([x], [100 * s.pass_at_1], marker=marker, s=40)
        ax.annotate(
            r.name, (x, 100 * s.pass_at_1), textcoords="offset points", xytext=(5, 4), fontsize=8
        )
    ax.set_xscale("symlog", linthresh=0.01)
    costs = [r.summary.cost_usd or 0.0 for r in runs]
    ax.set_xlim(left=-0.001, right=max([0.1, *costs]) * 3)
    ax.set_xlabel("cost of the run (USD; x = unknown price)")
    ax.set_ylabel("success, all levels (Pass@1, %)")
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


def tables(runs: Sequence[Run]) -> list[tuple[str, Table]]:
    out = [("table1", table1(runs)), ("difficulty", difficulty_table(runs))]
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
