"""``chain export-dataset``: levels and demonstrations as a Hugging Face dataset folder."""

from __future__ import annotations

import io
import json
from pathlib import Path
from typing import Any

import pytest
from PIL import Image

from chaingeo.cli.main import main
from chaingeo.core.level import Level, load_level
from chaingeo.core.suite import suite_folder
from chaingeo.envs.dataset import DEMONSTRATIONS, LEVELS, export_dataset
from chaingeo.envs.demos import demonstration, plan_texts

pq = pytest.importorskip("pyarrow.parquet")
yaml = pytest.importorskip("yaml")  # comes with datasets and distributed

IDS = ("stacking-2x2x2-easy-s101-000000", "puzzle-easy-07-burr3")
SIZE = 128


def shipped(level_id: str) -> Level:
    family = level_id.split("-", 1)[0]
    return load_level(suite_folder() / family / f"{level_id}.json")


@pytest.fixture(scope="module")
def levels() -> list[Level]:
    return [shipped(i) for i in IDS]


@pytest.fixture(scope="module")
def exported(tmp_path_factory: pytest.TempPathFactory, levels: list[Level]) -> Path:
    out = tmp_path_factory.mktemp("ds")
    assert main(["export-dataset", *IDS, "--out", str(out), "--image-size", str(SIZE)]) == 0
    return out


def files(folder: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()
    }


def rows(folder: Path, config: str) -> list[dict[str, Any]]:
    out: list[dict[str, Any]] = []
    for path in sorted((folder / config).glob("test-*.parquet")):
        out += pq.read_table(path).to_pylist()
    return out


def test_same_levels_in_any_order_give_the_same_bytes(
    exported: Path, tmp_path: Path, levels: list[Level]
) -> None:
    argv = ["export-dataset", *reversed(IDS), "--out", str(tmp_path), "--image-size", "128"]
    assert main(argv) == 0
    assert files(tmp_path) == files(exported)
    names = sorted(files(exported))
    assert names == [
        "README.md",
        "demonstrations/test-00000-of-00001.parquet",
        "levels/test-00000-of-00001.parquet",
    ]


def test_level_rows_hold_the_level_its_plan_and_its_pictures(
    exported: Path, levels: list[Level]
) -> None:
    got = rows(exported, LEVELS)
    assert [r["id"] for r in got] == sorted(IDS)
    for row in got:
        level = next(lv for lv in levels if lv.id == row["id"])
        assert row["plan"] == plan_texts(level) and row["optimal_steps"] == level.optimal_steps
        assert json.loads(row["level_json"]) == level.to_json()
        assert row["box"] == (list(level.box) if level.box else None)
        assert [p["voxels"] for p in row["pieces"]] == [
            [list(c) for c in p.shape.cells] for p in level.pieces
        ]
        extra = "tray" if level.family == "stacking" else "target"
        assert row["image_names"][:5] == ["front", "side", "top", "iso", extra]
        assert len(row["images"]) == len(row["image_names"]) == 7
        for im in row["images"][:5]:
            assert Image.open(io.BytesIO(im["bytes"])).size == (SIZE, SIZE)
    meta = json.loads(pq.read_schema(exported / LEVELS / "test-00000-of-00001.parquet")
                      .metadata[b"huggingface"])  # fmt: skip
    assert meta["info"]["features"]["images"] == [{"_type": "Image"}]


def test_demonstrations_are_the_plan_as_chat_turns_with_the_views_shown(
    exported: Path, levels: list[Level]
) -> None:
    got = rows(exported, DEMONSTRATIONS)
    assert len(got) == sum(lv.optimal_steps for lv in levels)
    for level in levels:
        mine = [r for r in got if r["level_id"] == level.id]
        plain = list(demonstration(level))  # what ``chain demos`` writes
        assert [r["action"] for r in mine] == plan_texts(level)
        for row, record in zip(mine, plain, strict=True):
            user, assistant = row["messages"]
            assert user["role"] == "user" and assistant["role"] == "assistant"
            assert assistant["content"] == [{"type": "text", "text": record["action"]}]
            *pictures, text = user["content"]
            assert [c["type"] for c in pictures] == ["image"] * len(row["images"]) == ["image"] * 5
            views = ", ".join(row["image_names"])
            assert text["text"] == f"{record['observation']}\n\nViews: {views}"
        assert [r["reward"] for r in mine][-1] == 1.0 and mine[-1]["terminated"]
        # The first step shows the start state: the very pictures of the level's row.
        (start,) = [r for r in rows(exported, LEVELS) if r["id"] == level.id]
        assert [im["bytes"] for im in mine[0]["images"]] == [
            im["bytes"] for im in start["images"][:5]
        ]


def test_the_card_has_the_hubs_header_and_lists_every_split(exported: Path, tmp_path: Path) -> None:
    out = tmp_path / "both"
    argv = ["export-dataset", IDS[0], "--out", str(out), "--image-size", "128"]
    assert main([*argv, "--split", "train"]) == 0
    assert main(["export-dataset", IDS[1], "--out", str(out), "--image-size", "128"]) == 0
    text = (out / "README.md").read_text(encoding="utf-8")
    head = yaml.safe_load(text.split("---\n")[1])
    assert head["license"] == "mit" and head["size_categories"] == ["n<1K"]
    assert {"pretty_name", "task_categories"} <= set(head)
    configs = {c["config_name"]: c["data_files"] for c in head["configs"]}
    assert configs[LEVELS] == [
        {"split": "test", "path": "levels/test-*.parquet"},
        {"split": "train", "path": "levels/train-*.parquet"},
    ]
    assert set(configs) == {LEVELS, DEMONSTRATIONS}
    card = (exported / "README.md").read_text(encoding="utf-8")
    assert "## Tiers" in card and "## Baselines" in card and "| greedy |" in card


def test_shards_split_by_size_and_keep_the_order(tmp_path: Path, levels: list[Level]) -> None:
    summary = export_dataset(levels, tmp_path, image_size=SIZE, shard_bytes=1)
    names = [f.name for f in summary.files[DEMONSTRATIONS]]
    total = sum(lv.optimal_steps for lv in levels)
    assert names == [f"test-{i:05d}-of-{total:05d}.parquet" for i in range(total)]
    assert [r["step"] for r in rows(tmp_path, DEMONSTRATIONS)] == [1, 2, 3, 1, 2]
    export_dataset(levels[:1], tmp_path, image_size=SIZE)  # older shards of the split go
    assert len(list((tmp_path / DEMONSTRATIONS).glob("test-*"))) == 1


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        ([IDS[0], "--image-size", "4096"], "image size 4096"),
        ([IDS[0], "--image-size", "64"], "image size 64"),
        ([IDS[0], IDS[0]], "given twice"),
        (["no-such-level"], "no-such-level"),
    ],
)
def test_bad_exports_are_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: list[str], message: str
) -> None:
    assert main(["export-dataset", *extra, "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("chain export-dataset: error: ") and message in err
    assert len(err.strip().splitlines()) == 1 and not (tmp_path / "README.md").exists()


def test_load_dataset_round_trips_both_configs(exported: Path, tmp_path: Path) -> None:
    datasets = pytest.importorskip("datasets")
    levels = datasets.load_dataset(str(exported), LEVELS, cache_dir=str(tmp_path))["test"]
    assert levels.num_rows == 2 and isinstance(levels.features["images"].feature, datasets.Image)
    first = levels[0]
    assert first["id"] == sorted(IDS)[0] and first["images"][0].size == (SIZE, SIZE)
    assert first == {**rows(exported, LEVELS)[0], "images": first["images"]}
    demos = datasets.load_dataset(str(exported), DEMONSTRATIONS, cache_dir=str(tmp_path))["test"]
    assert demos["action"] == [r["action"] for r in rows(exported, DEMONSTRATIONS)]
    assert demos[0]["images"][4].size == (SIZE, SIZE)


def test_the_step_bound_is_checked_before_any_picture_is_drawn(
    tmp_path: Path, levels: list[Level], monkeypatch: pytest.MonkeyPatch
) -> None:
    from chaingeo.core import limits
    from chaingeo.core.limits import LimitError

    monkeypatch.setattr(limits, "MAX_DATASET_STEPS", 4)
    with pytest.raises(LimitError, match="5 plan steps; at most 4"):
        export_dataset(levels, tmp_path / "out", image_size=SIZE)
    assert not (tmp_path / "out").exists()


@pytest.mark.slow
def test_the_whole_shipped_suite_exports_and_loads(tmp_path: Path) -> None:
    datasets = pytest.importorskip("datasets")
    from chaingeo.core.level import load_levels
    from chaingeo.generator.signature import level_signature

    suite = load_levels(suite_folder())
    assert main(["export-dataset", "--out", str(tmp_path), "--image-size", "128"]) == 0
    got = datasets.load_dataset(str(tmp_path), LEVELS, cache_dir=str(tmp_path / "c"))["test"]
    assert got["id"] == sorted(lv.id for lv in suite)
    by_id = {lv.id: lv for lv in suite}
    assert got["signature"] == [level_signature(by_id[i]) for i in got["id"]]
    demos = datasets.load_dataset(str(tmp_path), DEMONSTRATIONS, cache_dir=str(tmp_path / "c"))
    assert demos["test"].num_rows == sum(lv.optimal_steps for lv in suite)
