"""Levels and demonstrations as a Hugging Face ``datasets`` folder (Parquet shards and a card).

Two configurations, each one Parquet file per shard under its own folder:

* ``levels/SPLIT-XXXXX-of-YYYYY.parquet``: one row per level (its fields, the optimal plan as
  action texts, the level file itself, the split signature, the pictures of its start state and
  of the solved level);
* ``demonstrations/...``: one row per step of every level's optimal plan replayed through the
  environment (:func:`chaingeo.envs.demos.demonstration`): the observation text and pictures
  in, the canonical action text out, as chat messages (TRL's ``messages`` + ``images`` layout).

Pictures are the Hub's ``Image`` feature, ``{"bytes": PNG, "path": name}``; the features ride in
the Parquet schema's ``huggingface`` metadata, so ``datasets.load_dataset(DIR, CONFIG)``
decodes them. Writing needs only ``pyarrow`` (the ``dataset`` extra). The same levels give the
same bytes: rows are sorted by level id, pictures are canonical PNGs, and the writer stores no
time.
"""

from __future__ import annotations

import importlib
import json
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Final

from chaingeo.core import limits
from chaingeo.core.errors import ChainGeoError
from chaingeo.core.level import Level, level_bytes
from chaingeo.core.limits import LimitError
from chaingeo.envs.demos import demonstration, plan_texts
from chaingeo.envs.machines import new_state
from chaingeo.envs.observation import render_state
from chaingeo.pictures.pictures import level_pictures

LEVELS: Final = "levels"
DEMONSTRATIONS: Final = "demonstrations"
CONFIGS: Final = (LEVELS, DEMONSTRATIONS)
#: Multiple-choice questions with proven answers (`chain questions --hf DIR`), a configuration
#: of its own beside the two above; the card lists it when its shards are there.
QUESTIONS: Final = "questions"
#: Rows per Parquet row group: small groups keep a reader's memory low on picture columns.
ROW_GROUP_ROWS: Final = 64
SPLIT_NAMES: Final = frozenset({"train", "validation", "test"})

_STRING: Final = {"dtype": "string", "_type": "Value"}
_INT: Final = {"dtype": "int64", "_type": "Value"}
_IMAGES: Final = [{"_type": "Image"}]
_CONTENT: Final = [{"type": _STRING, "text": _STRING}]
#: The Hub's features of each configuration (lists written as one-item lists, which every
#: ``datasets`` version reads).
FEATURES: Final[dict[str, dict[str, Any]]] = {
    LEVELS: {
        "id": _STRING,
        "family": _STRING,
        "difficulty": _STRING,
        "goal": _STRING,
        "box": [_INT],
        "optimal_steps": _INT,
        "max_steps": _INT,
        "pieces": [{"name": _STRING, "rgb": _STRING, "voxels": [[_INT]]}],
        "plan": [_STRING],
        "signature": _STRING,
        "level_json": _STRING,
        "image_names": [_STRING],
        "images": _IMAGES,
    },
    DEMONSTRATIONS: {
        "level_id": _STRING,
        "family": _STRING,
        "difficulty": _STRING,
        "step": _INT,
        "steps": _INT,
        "messages": [{"role": _STRING, "content": _CONTENT}],
        "image_names": [_STRING],
        "images": _IMAGES,
        "action": _STRING,
        "reward": {"dtype": "float64", "_type": "Value"},
        "terminated": {"dtype": "bool", "_type": "Value"},
        "feedback": _STRING,
    },
    QUESTIONS: {
        "id": _STRING,
        "category": _STRING,
        "level": _STRING,
        "question": _STRING,
        "A": _STRING,
        "B": _STRING,
        "C": _STRING,
        "D": _STRING,
        "answer": _STRING,
        "state": [_STRING],
        "proof": _STRING,
        "images": _IMAGES,
    },
}


class DatasetError(ChainGeoError, ValueError):
    """The export cannot be made (bad levels, options past a limit, pyarrow missing)."""


@dataclass
class ExportSummary:
    """What an export wrote: rows and shard files per configuration."""

    split: str
    rows: dict[str, int] = field(default_factory=dict)
    files: dict[str, list[Path]] = field(default_factory=dict)
    bytes: int = 0


def _pyarrow() -> Any:
    """``pyarrow`` and ``pyarrow.parquet`` (the ``dataset`` extra), untyped."""
    try:
        return importlib.import_module("pyarrow"), importlib.import_module("pyarrow.parquet")
    except ImportError:
        raise DatasetError(
            "exporting a dataset needs pyarrow: pip install 'chaingeo[dataset]'"
        ) from None


def check_export(levels: Sequence[Level], split: str, image_size: int) -> None:
    """Every bound of an export, before any picture is drawn."""
    if split not in SPLIT_NAMES:
        raise DatasetError(f"split {split!r} is not one of {sorted(SPLIT_NAMES)}")
    if not levels:
        raise DatasetError("no levels to export")
    if len(levels) > limits.MAX_DATASET_LEVELS:
        raise LimitError(f"{len(levels)} levels; at most {limits.MAX_DATASET_LEVELS} per export")
    steps = sum(lv.optimal_steps for lv in levels)
    if steps > limits.MAX_DATASET_STEPS:
        raise LimitError(f"{steps} plan steps; at most {limits.MAX_DATASET_STEPS} per export")
    if not 128 <= image_size <= limits.MAX_DATASET_IMAGE_SIZE:
        raise LimitError(
            f"image size {image_size}; from 128 to {limits.MAX_DATASET_IMAGE_SIZE} pixels"
        )
    ids = [lv.id for lv in levels]
    twice = sorted({i for i in ids if ids.count(i) > 1})
    if twice:
        raise DatasetError(f"level ids given twice: {', '.join(twice[:5])}")


# ---------------------------------------------------------------------------------------------
# Rows
# ---------------------------------------------------------------------------------------------


def _image(png: bytes, path: str) -> dict[str, Any]:
    return {"bytes": png, "path": path}


def level_row(level: Level, image_size: int, signature: str) -> dict[str, Any]:
    """The ``levels`` row of one level: start-state views, then the solved level's pictures."""
    views = render_state(new_state(level), image_size)
    views.update({f"solved-{k}": v for k, v in sorted(level_pictures(level).items())})
    return {
        "id": level.id,
        "family": level.family,
        "difficulty": level.difficulty,
        "goal": level.goal,
        "box": list(level.box) if level.box is not None else None,
        "optimal_steps": level.optimal_steps,
        "max_steps": level.max_steps,
        "pieces": [
            {"name": p.name, "rgb": p.rgb, "voxels": [list(c) for c in p.shape.cells]}
            for p in level.pieces
        ],
        "plan": plan_texts(level),
        "signature": signature,
        "level_json": level_bytes(level).decode("utf-8"),
        "image_names": list(views),
        "images": [_image(png, f"{level.id}/{name}.png") for name, png in views.items()],
    }


def demonstration_rows(level: Level, image_size: int) -> Iterator[dict[str, Any]]:
    """The ``demonstrations`` rows of one level: one chat turn pair per step of its plan."""
    for record in demonstration(level, picture_size=image_size):
        pictures: dict[str, bytes] = record["images"]
        prefix = f"{level.id}/step-{record['step']:04d}"
        user = [{"type": "image", "text": None} for _ in pictures]
        user.append({"type": "text", "text": record["observation"]})
        yield {
            "level_id": level.id,
            "family": level.family,
            "difficulty": level.difficulty,
            "step": record["step"],
            "steps": level.optimal_steps,
            "messages": [
                {"role": "user", "content": user},
                {"role": "assistant", "content": [{"type": "text", "text": record["action"]}]},
            ],
            "image_names": list(pictures),
            "images": [_image(png, f"{prefix}-{n}.png") for n, png in pictures.items()],
            "action": record["action"],
            "reward": float(record["reward"]),
            "terminated": bool(record["terminated"]),
            "feedback": record["feedback"],
        }


def _row_bytes(row: dict[str, Any]) -> int:
    """About how many bytes a row adds to a shard: its pictures and its longest texts."""
    pictures = sum(len(im["bytes"]) for im in row["images"])
    texts = len(row.get("level_json", "")) + sum(
        len(c["text"] or "") for m in row.get("messages", []) for c in m["content"]
    )
    return pictures + texts


# ---------------------------------------------------------------------------------------------
# Writing
# ---------------------------------------------------------------------------------------------


def schema(config: str) -> Any:
    """The Arrow schema of a configuration, with the Hub's features in its metadata."""
    pa, _ = _pyarrow()

    def arrow(feature: Any) -> Any:
        if isinstance(feature, list):
            return pa.list_(arrow(feature[0]))
        if feature.get("_type") == "Image":
            return pa.struct([("bytes", pa.binary()), ("path", pa.string())])
        if feature.get("_type") == "Value":
            return {"string": pa.string(), "int64": pa.int64(), "float64": pa.float64(),
                    "bool": pa.bool_()}[feature["dtype"]]  # fmt: skip
        return pa.struct([(k, arrow(v)) for k, v in feature.items()])

    features = FEATURES[config]
    meta = json.dumps({"info": {"features": features}}, sort_keys=True)
    return pa.schema([(k, arrow(v)) for k, v in features.items()], metadata={"huggingface": meta})


class _ShardWriter:
    """Rows into numbered temporary shards, one row group of :data:`ROW_GROUP_ROWS` at a time
    (memory holds one group, not a shard); a new shard once ``shard_bytes`` are reached."""

    def __init__(self, target: Path, config: str, split: str, shard_bytes: int) -> None:
        self.pa, self.pq = _pyarrow()
        self.schema = schema(config)
        self.target, self.split, self.shard_bytes = target, split, shard_bytes
        self.parts: list[Path] = []
        self.writer: Any = None
        self.group: list[dict[str, Any]] = []
        self.size = 0

    def add(self, row: dict[str, Any]) -> None:
        size = _row_bytes(row)
        if self.writer is not None and self.size + size > self.shard_bytes:
            self._flush()
            self.writer.close()
            self.writer = None
        if self.writer is None:
            self._open()
        self.group.append(row)
        self.size += size
        if len(self.group) >= ROW_GROUP_ROWS:
            self._flush()

    def _open(self) -> None:
        part = self.target / f".{self.split}-{len(self.parts):05d}.parquet.tmp"
        self.parts.append(part)
        self.size = 0
        self.writer = self.pq.ParquetWriter(
            part,
            self.schema,
            compression="zstd",
            compression_level=3,
            use_dictionary=False,
            write_statistics=False,
            version="2.6",
            data_page_version="1.0",
            store_schema=True,
        )

    def _flush(self) -> None:
        if self.group:
            table = self.pa.Table.from_pylist(self.group, schema=self.schema)
            self.writer.write_table(table, row_group_size=ROW_GROUP_ROWS)
            self.group = []

    def close(self) -> list[Path]:
        """Finish the last shard (an empty one when there were no rows); the temporary files."""
        if self.writer is None:
            self._open()
        self._flush()
        self.writer.close()
        return self.parts

    def abort(self) -> None:
        """Close and remove the temporary shards (a row failed to build)."""
        if self.writer is not None:
            self.writer.close()
        for part in self.parts:
            part.unlink(missing_ok=True)


def write_config(
    rows: Iterable[dict[str, Any]], folder: Path, config: str, split: str, shard_bytes: int
) -> tuple[int, list[Path]]:
    """Write ``rows`` as the shards of ``folder/config/split-*.parquet``; the split's older
    shards are replaced only once every new one is written. Returns the row count and files."""
    target = folder / config
    target.mkdir(parents=True, exist_ok=True)
    writer = _ShardWriter(target, config, split, shard_bytes)
    count = 0
    try:
        for row in rows:
            writer.add(row)
            count += 1
    except BaseException:
        writer.abort()
        raise
    parts = writer.close()
    files = [target / f"{split}-{i:05d}-of-{len(parts):05d}.parquet" for i in range(len(parts))]
    for old in set(target.glob(f"{split}-*.parquet")) - set(files):
        old.unlink()
    for part, final in zip(parts, files, strict=True):
        part.replace(final)
    return count, files


def export_dataset(
    levels: Iterable[Level],
    out: str | Path,
    *,
    split: str = "test",
    image_size: int = 512,
    signatures: dict[str, str] | None = None,
    shard_bytes: int = limits.MAX_DATASET_SHARD_BYTES,
) -> ExportSummary:
    """Write both configurations of ``levels`` into ``out`` (see the module docstring);
    ``signatures``: level id -> split signature (``chaingeo.generator.signature``), "" where absent.
    The card is written separately (:mod:`chaingeo.envs.dataset_card`)."""
    ordered = sorted(levels, key=lambda lv: lv.id)
    check_export(ordered, split, image_size)
    if not 0 < shard_bytes <= limits.MAX_DATASET_SHARD_BYTES:
        raise LimitError(f"shard size {shard_bytes}; at most {limits.MAX_DATASET_SHARD_BYTES}")
    _pyarrow()
    folder = Path(out)
    sigs = signatures or {}
    level_rows = (level_row(lv, image_size, sigs.get(lv.id, "")) for lv in ordered)
    step_rows = (row for lv in ordered for row in demonstration_rows(lv, image_size))
    summary = ExportSummary(split)
    for config, rows in ((LEVELS, level_rows), (DEMONSTRATIONS, step_rows)):
        count, files = write_config(rows, folder, config, split, shard_bytes)
        summary.rows[config] = count
        summary.files[config] = files
        summary.bytes += sum(f.stat().st_size for f in files)
    return summary


def splits_on_disk(folder: Path, config: str) -> list[str]:
    """The splits of a configuration with shards in ``folder`` (the card lists them all)."""
    names = {p.name.split("-", 1)[0] for p in (folder / config).glob("*-of-*.parquet")}
    return sorted(names & SPLIT_NAMES)
