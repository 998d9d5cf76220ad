"""Questions as a model sees them: prompts with 1-based cells, the action texts that reach the
state shown, its picture, and the files VLMEvalKit and lmms-eval read.

The generator decides what is asked and proves the answer (:mod:`chaingeo.generator.questions`);
this module, above both the generator and the environments, presents it with the environments'
one cell conversion for agents (:func:`chaingeo.envs.actions.types.cells_text`) and their
pictures (the renderer and views an agent gets, :func:`chaingeo.envs.observation.state_images`).
Train and test are split by level signature, so no level (or a copy of it) is on both sides.
"""

from __future__ import annotations

import base64
import csv
import hashlib
import io
import json
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Final

from chaingeo.core.files import atomic_write
from chaingeo.core.level import Level
from chaingeo.envs.actions.types import cells_text
from chaingeo.envs.demos import plan_texts
from chaingeo.generator.questions import LETTERS, Question
from chaingeo.generator.questions.model import CELLS_FIELD
from chaingeo.generator.questions.views import recipe_pieces, recipes, solved

#: One view's size in the question picture (3 x 2 views).
VIEW_SIZE: Final = 256
#: Levels whose signature hashes below this share of the range are the test split.
TEST_SHARE: Final = 0.3
SAME: Final = "same-assembly"
HINT: Final = "Answer with the option's letter only."
TSV_COLUMNS: Final = (
    "index",
    "image",
    "question",
    "A",
    "B",
    "C",
    "D",
    "answer",
    "category",
    "level",
    "state",
    "proof",
    "split",
)


def _line(value: Mapping[str, Any]) -> str:
    """One JSON line: sorted keys, no spaces, ASCII (the same bytes on any machine)."""
    return json.dumps(value, sort_keys=True, separators=(",", ":"), ensure_ascii=True)


def split_of(signature: str) -> str:
    """``test`` or ``train``, from the level's signature alone (copies land together)."""
    h = int(hashlib.sha256(signature.encode("ascii")).hexdigest()[:8], 16)
    return "test" if h < TEST_SHARE * 0x1_0000_0000 else "train"


def _fill(text: str, cells: Sequence[Sequence[int]] | None) -> str:
    return text.replace(CELLS_FIELD, cells_text(cells)) if cells is not None else text


@dataclass(frozen=True)
class Shown:
    """A question ready to ask: every text final, the picture's key, the proof."""

    id: str
    category: str
    level: str
    split: str
    state: tuple[str, ...]
    question: str
    options: tuple[str, ...]
    answer: str
    proof: Mapping[str, Any]
    image: str  # the picture's file name (one per level state)

    def prompt(self, hint: bool = True) -> str:
        lines = [self.question, *(f"{k}. {v}" for k, v in zip(LETTERS, self.options, strict=True))]
        return "\n".join([*lines, HINT] if hint else lines)

    def to_json(self) -> dict[str, Any]:
        return {
            "id": self.id,
            "category": self.category,
            "level": self.level,
            "split": self.split,
            "state": list(self.state),
            "question": self.question,
            "options": dict(zip(LETTERS, self.options, strict=True)),
            "answer": self.answer,
            "proof": dict(self.proof),
            "image": self.image,
        }

    @staticmethod
    def from_json(obj: Mapping[str, Any]) -> Shown:
        opts = obj["options"]
        return Shown(
            str(obj["id"]),
            str(obj["category"]),
            str(obj["level"]),
            str(obj["split"]),
            tuple(obj["state"]),
            str(obj["question"]),
            tuple(opts[k] for k in LETTERS),
            str(obj["answer"]),
            obj["proof"],
            str(obj["image"]),
        )


def image_name(level: str, step: int) -> str:
    return f"{level}-s{step:03d}.png"


def present(q: Question, level: Level) -> Shown:
    """The question's final texts (cells 1-based) and the state as action texts; a
    same-assembly question's options name its pictures by letter."""
    prompt = _fill(q.prompt, q.prompt_cells)
    options = tuple(_fill(o.text, o.cells) for o in q.options)
    image = image_name(q.level, q.step)
    if q.category == SAME:
        options = tuple(f"picture {k}" for k in LETTERS)
        image = f"{q.level}-{q.id}.png"
    return Shown(
        id=q.id,
        category=q.category,
        level=q.level,
        split=split_of(q.signature),
        state=tuple(plan_texts(level)[: q.step]),
        question=prompt,
        options=options,
        answer=q.letter,
        proof=q.proof,
        image=image,
    )


def assembly_picture(q: Question, level: Level, size: int = VIEW_SIZE) -> bytes:
    """A same-assembly question's picture: the solved level on top, its four options (each
    drawn from its recipe, labelled A-D) below, every one from the iso corner."""
    from PIL import Image

    from chaingeo.pictures.raster import png_bytes
    from chaingeo.pictures.scene_kernel import render_arrays

    rgb = {p.name: p.rgb for p in level.pieces}

    def draw(pieces: Mapping[str, Any], title: str) -> Any:
        every = [c for s in pieces.values() for c in s.cells]
        lo = [-min(c[i] for c in every) for i in range(3)]
        scene = {n: (s.translate(lo), rgb[n]) for n, s in pieces.items()}
        return Image.fromarray(render_arrays(scene, None, ("iso",), size, title)["iso"])

    sheet = Image.new("RGB", (4 * size, 2 * size), (255, 255, 255))
    sheet.paste(draw(solved(level), "THE SOLVED LEVEL"), (3 * size // 2, 0))
    for i, recipe in enumerate(recipes(q)):
        sheet.paste(draw(recipe_pieces(level, recipe), f"PICTURE {LETTERS[i]}"), (i * size, size))
    return png_bytes(sheet)


def state_picture(level: Level, step: int, size: int = VIEW_SIZE) -> bytes:
    """The state after ``step`` actions of the stored solution, as an agent sees it: the four
    views and the tray (stacking) or the target (puzzles), in one 3 x 2 PNG."""
    from PIL import Image

    from chaingeo.envs.machines import new_state
    from chaingeo.envs.observation import state_images
    from chaingeo.pictures.raster import png_bytes

    state = new_state(level)
    for text in plan_texts(level)[:step]:
        state.step_text(text)
    images = list(state_images(state, size).values())
    sheet = Image.new("RGB", (3 * size, 2 * size), (255, 255, 255))
    for i, img in enumerate(images[:6]):
        sheet.paste(img.convert("RGB").resize((size, size)), ((i % 3) * size, (i // 3) * size))
    return png_bytes(sheet)


def write_questions(
    questions: Sequence[Question], levels: Mapping[str, Level], out: Path, pictures: bool = True
) -> list[Shown]:
    """``out/questions.jsonl`` (canonical, one question a line) and ``out/images/*.png`` (one
    per state asked about); returns the questions as shown."""
    shown = [present(q, levels[q.level]) for q in questions]
    lines = "".join(_line(s.to_json()) + "\n" for s in shown)
    out.mkdir(parents=True, exist_ok=True)
    atomic_write(out / "questions.jsonl", lines.encode("utf-8"))
    if pictures:
        (out / "images").mkdir(exist_ok=True)
        states = sorted({(q.level, q.step) for q in questions if q.category != SAME})
        for lv, step in states:
            atomic_write(out / "images" / image_name(lv, step), state_picture(levels[lv], step))
        for q, s in zip(questions, shown, strict=True):
            if q.category == SAME:
                atomic_write(out / "images" / s.image, assembly_picture(q, levels[q.level]))
    return shown


def read_questions(path: Path) -> list[Shown]:
    """The questions of a ``questions.jsonl`` written by :func:`write_questions`."""
    with path.open(encoding="utf-8") as f:
        return [Shown.from_json(json.loads(line)) for line in f if line.strip()]


def write_vlmeval_tsv(shown: Iterable[Shown], images: Path, path: Path) -> int:
    """VLMEvalKit's custom multiple-choice TSV: ``image`` is the PNG in base64 the first time a
    picture appears, later the ``index`` of that row (VLMEvalKit resolves such references)."""
    first: dict[str, int] = {}
    buf = io.StringIO()
    w = csv.writer(buf, delimiter="\t", lineterminator="\n", quoting=csv.QUOTE_MINIMAL)
    w.writerow(TSV_COLUMNS)
    n = 0
    for i, s in enumerate(shown):
        if s.image in first:
            image = str(first[s.image])
        else:
            first[s.image] = i
            image = base64.b64encode((images / s.image).read_bytes()).decode("ascii")
        state = "\n".join(s.state)
        proof = _line(dict(s.proof))
        w.writerow(
            [i, image, s.question, *s.options, s.answer, s.category, s.level, state, proof, s.split]
        )
        n += 1
    atomic_write(path, buf.getvalue().encode("utf-8"))
    return n


LMMS_YAML: Final = """\
# lmms-eval task: CHAIN-geo questions with proven answers (written by `chain questions`).
task: chaingeo_questions
dataset_path: json
dataset_kwargs:
  data_files:
    test: {data}
test_split: test
output_type: generate_until
doc_to_visual: !function utils.doc_to_visual
doc_to_text: !function utils.doc_to_text
doc_to_target: answer
generation_kwargs:
  max_new_tokens: 16
  temperature: 0
  do_sample: false
process_results: !function utils.process_results
metric_list:
  - metric: accuracy
    aggregation: mean
    higher_is_better: true
metadata:
  version: 1.0
"""

LMMS_UTILS: Final = '''\
"""lmms-eval hooks for CHAIN-geo questions: the picture, the prompt, exact-letter scoring."""

import base64
import io
import re

from PIL import Image


def doc_to_visual(doc):
    return [Image.open(io.BytesIO(base64.b64decode(doc["image"]))).convert("RGB")]


def doc_to_text(doc, lmms_eval_specific_kwargs=None):
    options = "\\n".join(f"{k}. {doc[k]}" for k in "ABCD")
    return f"{doc['question']}\\n{options}\\nAnswer with the option's letter only."


def parse_letter(text):
    found = re.search(r"\\b([ABCD])\\b", str(text).strip().upper())
    return found.group(1) if found else ""


def process_results(doc, results):
    return {"accuracy": float(parse_letter(results[0]) == doc["answer"])}
'''


def write_lmms_task(shown: Iterable[Shown], images: Path, folder: Path) -> int:
    """An lmms-eval task folder: ``chaingeo_questions.yaml``, ``utils.py`` and the test split
    as JSON lines (pictures inline in base64)."""
    folder.mkdir(parents=True, exist_ok=True)
    rows = []
    for s in shown:
        if s.split != "test":
            continue
        png = base64.b64encode((images / s.image).read_bytes()).decode("ascii")
        row = {
            "id": s.id,
            "image": png,
            "question": s.question,
            "answer": s.answer,
            "category": s.category,
            "level": s.level,
            **dict(zip(LETTERS, s.options, strict=True)),
        }
        rows.append(_line(row) + "\n")
    data = folder / "chaingeo_questions.jsonl"
    atomic_write(data, "".join(rows).encode("utf-8"))
    # lmms-eval hands data_files to datasets.load_dataset, which reads them from the working
    # directory: the file is named by its absolute path
    yaml = LMMS_YAML.format(data=json.dumps(str(data.resolve())))
    atomic_write(folder / "chaingeo_questions.yaml", yaml.encode())
    atomic_write(folder / "utils.py", LMMS_UTILS.encode())
    return len(rows)


#: Bytes per Parquet shard of the ``questions`` configuration.
HF_SHARD_BYTES: Final = 256 * 1024 * 1024
HF_CARD: Final = """---
pretty_name: "CHAIN-geo questions"
task_categories:
- visual-question-answering
configs:
- config_name: questions
  data_files:
{files}---

# CHAIN-geo questions

Multiple-choice questions about interlocking puzzles and 3D packing, every answer proven by
exact solvers (`chain questions`); `proof` holds the facts that make it right. Train and test
are split by level signature.
"""


def write_hf_questions(shown: Sequence[Shown], images: Path, folder: Path) -> dict[str, int]:
    """The ``questions`` configuration of the Hugging Face dataset export, one Parquet set per
    split (:func:`chaingeo.envs.dataset.write_config`), and a card when the folder has none
    (`chain export-dataset` into the same folder writes the full card, listing it)."""
    from chaingeo.envs.dataset import QUESTIONS, write_config

    counts: dict[str, int] = {}
    for split in ("train", "test"):
        rows = (_hf_row(s, images) for s in shown if s.split == split)
        counts[split], _ = write_config(rows, folder, QUESTIONS, split, HF_SHARD_BYTES)
    card = folder / "README.md"
    if not card.exists():
        files = "".join(
            f"  - split: {k}\n    path: {QUESTIONS}/{k}-*.parquet\n" for k, n in counts.items() if n
        )
        atomic_write(card, HF_CARD.format(files=files).encode("utf-8"))
    return counts


def _hf_row(s: Shown, images: Path) -> dict[str, Any]:
    return {
        "id": s.id,
        "category": s.category,
        "level": s.level,
        "question": s.question,
        **dict(zip(LETTERS, s.options, strict=True)),
        "answer": s.answer,
        "state": list(s.state),
        "proof": _line(dict(s.proof)),
        "images": [{"bytes": (images / s.image).read_bytes(), "path": s.image}],
    }
