"""``chain import``: a CHAIN puzzle model (URDF + OBJ parts) as a ``chain-level/1`` file.

The importer (:mod:`chaingeo.core.formats.models`) puts the parts on the lattice;
:mod:`chaingeo.generator.imported` adds what needs the solvers: a puzzle's level and optimal plan
(with caps) or a stacking model's packing. A model that is not on a lattice, or a puzzle that does
not come apart, is an error and nothing is written.

``chain import --report ROOT`` imports every model folder under ROOT and prints one table row
per model (imported or refused, unit, fit residual, pieces, cells per piece, whether and how it
comes apart), for checking a new batch of models before levels are made from them.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from chaingeo.cli.errors import CommandError

if TYPE_CHECKING:
    from chaingeo.core.formats.models import ImportedModel
    from chaingeo.core.level import Level
    from chaingeo.solvers.limits import SearchLimits
    from chaingeo.solvers.motion.disassemble import Analysis


def register(sub: Any) -> None:
    # 'import' is a Python keyword, so the module is import_model; the command is 'import'
    p = sub.add_parser("import", help="import a CHAIN URDF/OBJ puzzle model as a level")
    p.add_argument("model", type=Path, help="a model folder (PART/urdf/*.urdf), or with "
                   "--report a folder of model folders")  # fmt: skip
    p.add_argument(
        "--out",
        type=Path,
        metavar="FILE.json|DIR",
        help="file: the level, when the name ends in .json; else folder (created when missing) "
        "that gets LEVEL_ID.json (default: print the level)",
    )
    p.add_argument(
        "--goal",
        choices=("disassemble", "assemble"),
        default="disassemble",
        help="what the level asks",
    )
    p.add_argument(
        "--kind", choices=("auto", "puzzle", "stacking"), default="auto", help="what the model is"
    )
    p.add_argument("--max-group", type=int, default=None, help="most pieces one move may carry")
    p.add_argument("--turns", action="store_true", help="allow 90-degree turns of groups "
                   "(rules turns=true; the model's round rods spin in place)")  # fmt: skip
    p.add_argument("--max-states", type=int, default=500_000, help="state cap per part search")
    p.add_argument(
        "--max-total-states", type=int, default=3_000_000, help="state cap of all part searches"
    )
    p.add_argument("--seconds", type=float, default=120.0, help="time cap of each analysis")
    p.add_argument("--report", action="store_true", help="table of every model under MODEL")
    p.add_argument("--json", action="store_true", help="with --report: JSON lines, not markdown")
    p.set_defaults(func=run)


@dataclass(frozen=True)
class ModelReport:
    """One model's row: ``model`` is None when the import refused (``reason`` says why)."""

    name: str
    model: ImportedModel | None
    reason: str | None = None
    analysis: Analysis | None = None
    note: str | None = None  # e.g. the search cap that was hit

    def row(self) -> dict[str, Any]:
        if self.model is None:
            return {"model": self.name, "result": "refused", "why": self.reason}
        s = self.model.summary()
        out: dict[str, Any] = {
            "model": self.name,
            "result": f"imported ({self.model.kind})",
            "unit": s["unit"],
            "rms_units": s["rms_units"],
            "worst_units": s["worst_units"],
            "pieces": len(self.model.parts),
            "cells": s["cells"],
            "moved": {k: [round(v, 2) for v in m] for k, m in self.model.moved_parts(0.1).items()},
            "decided_cells": sum(len(p.decided) for p in self.model.parts),
        }
        if self.model.box is not None:
            out["box"] = list(self.model.box)
        a = self.analysis
        if a is not None:
            out["comes_apart"] = a.disassemblable
            out["level"] = a.level
            out["optimal_steps"] = a.optimal_steps
        if self.note:
            out["note"] = self.note
        return out


def limits_of(args: argparse.Namespace) -> SearchLimits:
    from chaingeo.solvers.limits import SearchLimits

    return SearchLimits(
        max_states=args.max_states,
        seconds=args.seconds,
        max_total_states=args.max_total_states,
    )


def build_level(model: ImportedModel, args: argparse.Namespace) -> Level:
    """The verified level of an imported model (:mod:`chaingeo.generator.imported`: solvers find the
    plan or the packing)."""
    from chaingeo.generator.imported import imported_puzzle_level, imported_stacking_level

    if model.kind == "stacking":
        return imported_stacking_level(model)
    level, _ = imported_puzzle_level(
        model, goal=args.goal, turns=args.turns, max_group=args.max_group, limits=limits_of(args)
    )
    return level


def report_model(folder: Path, args: argparse.Namespace) -> ModelReport:
    """Import one model and, for a puzzle, analyse it under the command's caps."""
    from chaingeo.core.formats.models import ModelImportError, import_model
    from chaingeo.core.kinematics import SearchLimitError
    from chaingeo.solvers.analysis import analyze_puzzle

    try:
        model = import_model(folder, args.kind)
    except ModelImportError as e:
        return ModelReport(folder.name, None, e.reason)
    if model.kind != "puzzle":
        return ModelReport(folder.name, model)
    try:
        a = analyze_puzzle(
            model.shapes,
            max_group=args.max_group,
            limits=limits_of(args),
            turns=args.turns,
            rods=model.rods,
        )
    except SearchLimitError as e:
        return ModelReport(folder.name, model, note=f"analysis stopped: {e}")
    how = "translations and turns" if args.turns else "translations (needs a turn? try --turns)"
    note = None if a.disassemblable else f"does not come apart by {how}"
    return ModelReport(folder.name, model, analysis=a, note=note)


def _markdown(rows: list[dict[str, Any]]) -> str:
    head = "| model | result | unit | residual (rms / worst, units) | pieces | cells per piece " \
        "| comes apart | level | o_i | notes |"  # fmt: skip
    lines = [head, "|" + "---|" * 10]
    for r in rows:
        if r["result"] == "refused":
            lines.append(f"| {r['model']} | refused | | | | | | | | {r['why']} |")
            continue
        notes = []
        if r.get("box"):
            notes.append(f"box {'x'.join(map(str, r['box']))}")
        if r["moved"]:
            notes.append(f"snapped: {r['moved']}")
        if r["decided_cells"]:
            notes.append(f"{r['decided_cells']} partly filled outer cells decided by majority")
        if r.get("note"):
            notes.append(r["note"])
        apart = r.get("comes_apart")
        lines.append(
            f"| {r['model']} | {r['result']} | {r['unit']} | {r['rms_units']} / "
            f"{r['worst_units']} | {r['pieces']} | {' '.join(map(str, r['cells'].values()))} | "
            f"{'' if apart is None else ('yes' if apart else 'no')} | {r.get('level') or ''} | "
            f"{r.get('optimal_steps') or ''} | {'; '.join(notes)} |"
        )
    return "\n".join(lines)


def import_target(out: Path, level_id: str) -> Path:
    """``--out``'s file: ``out`` itself when it names a ``.json`` file, else ``out/ID.json`` in
    the folder ``out`` (made when missing; a new folder's name is never taken as a file's)."""
    from chaingeo.cli.out_arg import out_folder

    if out.suffix.lower() == ".json" and not out.is_dir():
        return out
    return out_folder(out) / f"{level_id}.json"


def run(args: argparse.Namespace) -> int:
    from chaingeo.core.formats.models import import_model
    from chaingeo.core.kinematics import SearchLimitError
    from chaingeo.core.level import level_bytes, save_level

    if args.report:
        folders = sorted(p for p in args.model.iterdir() if p.is_dir())
        rows = [report_model(f, args).row() for f in folders]
        print("\n".join(json.dumps(r) for r in rows) if args.json else _markdown(rows))
        return 0
    model = import_model(args.model, args.kind)
    try:
        level = build_level(model, args)
    except SearchLimitError as e:
        raise CommandError(f"{model.model}: optimal plan not found within the caps: {e}") from None
    if args.out is None:
        print(level_bytes(level).decode("utf-8"), end="")
        return 0
    print(save_level(level, import_target(args.out, level.id)))
    return 0
