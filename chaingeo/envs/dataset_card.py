"""The dataset card (``README.md``) of an exported dataset folder: the Hub's YAML header, then
how the data was made, the tier rule and the baselines.

The header lists every split found on disk for each configuration, so exporting a ``test``
and a ``train`` split into one folder gives one card naming both. Counts are computed from the
levels exported; the baselines are the README's measured figures on the shipped suite.
"""

from __future__ import annotations

import json
from collections import Counter
from collections.abc import Sequence
from pathlib import Path
from typing import Final

from chaingeo.core.level import Level
from chaingeo.envs.dataset import CONFIGS, LEVELS, QUESTIONS, splits_on_disk

PRETTY_NAME: Final = "CHAIN-geo: interlocking puzzles and 3D stacking, exact levels and plans"
_SIZES: Final = ((1_000, "n<1K"), (10_000, "1K<n<10K"), (100_000, "10K<n<100K"))

_TIERS: Final = """\
## Tiers

- **Stacking**: the generator's mode. *easy*: cuboid pieces; *mid*: pieces grown in one plane;
  *hard*: free shapes, all distinct, that need a least exact-cover search effort to pack.
- **Puzzles** (first-part level L: moves until the first part comes free; o: optimal steps;
  n: pieces): *easy* n <= 6 and L <= 2 and o <= 8; *hard* L >= 5, or o >= 20, or n >= 12 and
  L >= 3; *mid* everything else.
"""

_BASELINES: Final = """\
## Baselines

The built-in agents on the shipped suite (`chain eval --family F`, default budgets, one episode
per level; solved of easy / mid / hard):

| agent | puzzle (10 / 12 / 10) | stacking (10 / 20 / 47) |
|---|---|---|
| oracle | 10 / 12 / 10 | 10 / 20 / 47 |
| greedy | 3 / 3 / 1 | 10 / 14 / 8 |
| random | 0 / 0 / 0 | 6 / 4 / 0 |

Greedy and random see the legal actions, which a model does not; neither solves a puzzle
assembly level. `chain eval` runs them, and any OpenAI-compatible model, on the whole suite.
"""

_MADE: Final = """\
## How it was made

Every level is a `chain-level/1` file (`level_json`) with a verified optimal plan: stacking
levels come from the CHAIN-style generator (`chain generate stacking`) and are checked by exact
cover; puzzles are CHAIN's own models imported exactly, or generated burrs, cubes and towers,
with o_i (`optimal_steps`) proven by the solvers. Pictures are the renderer's deterministic
PNGs: in `levels`, the start state's views (`front side top iso`, then `tray` or `target`) and
the solved level (`solved-assembly`, `solved-pieces`); in `demonstrations`, the views shown with
each step. Demonstrations replay each level's optimal plan through the environment an agent
plays (`chain demos` gives the same steps as JSON lines): the user turn is the observation
(pictures, then text), the assistant turn the canonical action text. Cells in the text are
1-based, in the files 0-based. Same levels, same bytes (`chain export-dataset`).

`signature` is the split signature (pieces up to rotation plus the box, or the assembled shape
up to rotation plus the pieces): `chain generate ... --split train` refuses every level whose
signature is in the shipped suite, so a training split made that way never holds a test level.
Demonstrations of the `test` split are for analysis; train on a generated `train` split.
"""


def _size_category(rows: int) -> str:
    for bound, name in _SIZES:
        if rows < bound:
            return name
    return "100K<n<1M"


def _header(folder: Path, rows: int, licenses: Sequence[str]) -> str:
    lines = ["---"]
    if list(licenses) == ["mit"]:
        lines.append("license: mit")
    else:
        lines += ["license: other", "license_name: " + "-and-".join(licenses)]
    lines += ["pretty_name: " + json.dumps(PRETTY_NAME), "task_categories:"]
    lines += ["- reinforcement-learning", "- image-text-to-text"]
    lines += ["tags:", "- 3d", "- puzzles", "- planning"]
    lines += ["size_categories:", f"- {_size_category(rows)}", "configs:"]
    for config in (*CONFIGS, QUESTIONS):
        if not splits_on_disk(folder, config):
            continue
        lines.append(f"- config_name: {config}")
        if config == LEVELS:
            lines.append("  default: true")
        lines.append("  data_files:")
        for split in splits_on_disk(folder, config):
            lines += [f"  - split: {split}", f"    path: {config}/{split}-*.parquet"]
    lines.append("---")
    return "\n".join(lines) + "\n"


def _counts(levels: Sequence[Level]) -> str:
    tally = Counter((lv.family, lv.difficulty) for lv in levels)
    rows = ["| family | easy | mid | hard | steps |", "|---|---:|---:|---:|---:|"]
    for family in sorted({lv.family for lv in levels}):
        steps = sum(lv.optimal_steps for lv in levels if lv.family == family)
        cells = " | ".join(str(tally[family, d]) for d in ("easy", "mid", "hard"))
        rows.append(f"| {family} | {cells} | {steps} |")
    return "\n".join(rows) + "\n"


def licenses_of(levels: Sequence[Level]) -> list[str]:
    """``mit`` (the toolkit's levels), plus ``apache-2.0`` when a level came from CHAIN's
    Apache-2.0 models (its provenance says so)."""
    apache = any("Apache-2.0" in lv.provenance.generator for lv in levels)
    return ["mit", "apache-2.0"] if apache else ["mit"]


def dataset_card(folder: Path, levels: Sequence[Level], split: str, rows: dict[str, int]) -> str:
    """The card's text for the levels just exported as ``split`` into ``folder``."""
    intro = (
        f"# {PRETTY_NAME}\n\nLevels of the CHAIN-geo toolkit with exact optimal plans, and "
        "demonstrations of those plans as chat turns for supervised fine-tuning.\n\n"
        f"This export (split `{split}`): {rows.get(LEVELS, 0)} levels, "
        f"{rows.get('demonstrations', 0)} demonstration steps.\n\n{_counts(levels)}\n"
        "```python\nfrom datasets import load_dataset  # DIR: this folder, or its Hub id\n"
        'levels = load_dataset("DIR", "levels")\n'
        'demos = load_dataset("DIR", "demonstrations")\n```\n'
    )
    notes = ""
    if len(licenses_of(levels)) > 1:
        notes = (
            "## License\n\nMIT, except the levels imported from CHAIN's puzzle models "
            "(Apache License 2.0, copyright the CHAIN authors; their `level_json` provenance "
            "says so).\n"
        )
    total = max(rows.values(), default=0)
    body = "\n".join([intro, _MADE, _TIERS, _BASELINES, notes]).rstrip() + "\n"
    return _header(folder, total, licenses_of(levels)) + "\n" + body
