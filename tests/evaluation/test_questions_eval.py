"""`chain questions` end to end: the files VLMEvalKit and lmms-eval read (loaded their way), the
same bytes twice, and `chain eval --questions` with its baselines and a model over HTTP."""

from __future__ import annotations

import base64
import importlib
import importlib.util
import io
import json
import threading
from collections.abc import Iterator
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any

import pytest
import yaml  # type: ignore[import-untyped]
from PIL import Image

from chaingeo.cli.main import main
from chaingeo.evaluation.question_eval import (
    ModelAnswerer,
    parse_letter,
    wilson,
)
from chaingeo.evaluation.question_files import TSV_COLUMNS, read_questions
from tests.support.shipped import shipped

IDS = ["puzzle-easy-07-burr3", "stacking-2x2x3-easy-s103-000000", "stacking-2x3x3-mid-s108-000000"]
needs_suite = pytest.mark.skipif(not shipped(), reason="the shipped suite is not installed")


@pytest.fixture(scope="module")
def written(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("q") / "out"
    assert main(["questions", *IDS, "--out", str(out), "--seed", "5", "--hf", str(out / "hf")]) == 0
    return out


@needs_suite
def test_same_bytes_twice(written: Path, tmp_path: Path) -> None:
    again = tmp_path / "again"
    assert main(["questions", *IDS, "--out", str(again), "--seed", "5"]) == 0
    for name in ("questions.jsonl", "questions.tsv"):
        assert (written / name).read_bytes() == (again / name).read_bytes()
    pics = sorted(p.name for p in (written / "images").iterdir())
    assert pics == sorted(p.name for p in (again / "images").iterdir())
    for p in pics:
        assert (written / "images" / p).read_bytes() == (again / "images" / p).read_bytes()


@needs_suite
def test_tsv_loads_as_vlmevalkit_loads_it(written: Path) -> None:
    """pandas reads the TSV as VLMEvalKit's ``load`` does; an image shorter than 65 characters
    is the index of the row holding it (VLMEvalKit's ImageBaseDataset resolves it so)."""
    pd = pytest.importorskip("pandas")
    data = pd.read_csv(written / "questions.tsv", sep="\t")
    assert tuple(data.columns) == TSV_COLUMNS
    data["index"] = [str(x) for x in data["index"]]
    image_map = {k: str(v) for k, v in zip(data["index"], data["image"], strict=True)}
    for k, v in list(image_map.items()):
        if len(v) <= 64:
            assert v in image_map and len(image_map[v]) > 64
            image_map[k] = image_map[v]
    for k in data["index"]:
        img = Image.open(io.BytesIO(base64.b64decode(image_map[k])))
        assert img.format == "PNG" and img.size[0] > 100
    assert set(data["answer"]) <= set("ABCD")
    shown = read_questions(written / "questions.jsonl")
    for (_, row), q in zip(data.iterrows(), shown, strict=True):
        assert row["question"] == q.question and row["answer"] == q.answer
        assert row["level"] == q.level and row["category"] == q.category
        assert json.loads(row["proof"]) == q.proof
        state = "" if pd.isna(row["state"]) else row["state"]
        assert state == "\n".join(q.state)


@needs_suite
def test_vlmevalkit_own_loader(written: Path) -> None:
    if importlib.util.find_spec("vlmeval") is None:
        pytest.skip("VLMEvalKit is not on PyPI (installed from its git repository, no network)")
    load = importlib.import_module("vlmeval.smp").load
    assert len(load(str(written / "questions.tsv"))) == len(
        read_questions(written / "questions.jsonl")
    )


def _hooks(folder: Path) -> Any:
    spec = importlib.util.spec_from_file_location("chaingeo_lmms_utils", folder / "utils.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@needs_suite
def test_lmms_eval_task_loads_with_datasets_and_its_hooks(written: Path) -> None:
    """The YAML's ``!function`` hooks resolve in utils.py, the data loads through
    ``datasets.load_dataset`` as lmms-eval calls it, and the hooks score the proven answer 1."""
    datasets = pytest.importorskip("datasets")
    folder = written / "lmms-eval"
    hooks = _hooks(folder)

    class Loader(yaml.SafeLoader):  # type: ignore[misc]
        pass

    Loader.add_constructor(
        "!function", lambda ld, node: getattr(hooks, ld.construct_scalar(node).split(".")[-1])
    )
    config = yaml.load((folder / "chaingeo_questions.yaml").read_text(), Loader=Loader)
    ds = datasets.load_dataset(config["dataset_path"], **config["dataset_kwargs"])[
        config["test_split"]
    ]
    assert len(ds) >= 1
    for doc in ds:
        assert config["doc_to_visual"](doc)[0].size[0] > 100
        text = config["doc_to_text"](doc)
        assert doc["question"] in text and "D. " in text
        assert config["process_results"](doc, [doc["answer"]]) == {"accuracy": 1.0}
        wrong = next(x for x in "ABCD" if x != doc["answer"])
        assert config["process_results"](doc, [f"The answer is {wrong}."]) == {"accuracy": 0.0}
    if importlib.util.find_spec("lmms_eval") is None:
        pytest.skip("lmms-eval itself needs torch, transformers and ~50 packages; not installed")
    load_yaml_config = importlib.import_module("lmms_eval.utils").load_yaml_config
    assert load_yaml_config(str(folder / "chaingeo_questions.yaml"))["task"] == "chaingeo_questions"


def test_wilson_and_letters() -> None:
    lo, hi = wilson(5, 10)
    assert lo < 0.5 < hi and abs((lo + hi) / 2 - 0.5) < 1e-12
    assert wilson(0, 0) == (0.0, 1.0)
    assert wilson(10, 10)[1] == pytest.approx(1.0)
    assert parse_letter("B") == "B"
    assert parse_letter("(C) red") == "C"
    assert parse_letter("I think the answer is D because") == "D"
    assert parse_letter("A piece moves; option B") == "A"
    assert parse_letter("none") == ""


@needs_suite
def test_eval_questions_table_with_baselines(
    written: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = written / "questions.jsonl"
    assert main(["eval", "--questions", str(path), "--split", "all", "--agent", "oracle"]) == 0
    out = capsys.readouterr().out
    assert "| category | n | oracle | random | most frequent |" in out
    n = len(read_questions(path))
    assert f"| all | {n} | 100.0 [" in out


class _Chat(BaseHTTPRequestHandler):
    seen: list[dict[str, Any]] = []  # noqa: RUF012

    def log_message(self, format: str, *args: Any) -> None:
        pass

    def do_POST(self) -> None:
        body = json.loads(self.rfile.read(int(self.headers["Content-Length"])))
        _Chat.seen.append(body)
        text = body["messages"][0]["content"][0]["text"]
        letter = "A" if len(body["messages"][0]["content"]) > 1 else "B"  # pictures: A
        message = {"role": "assistant", "content": f"{letter} ({len(text)})"}
        answer = {
            "id": "x",
            "object": "chat.completion",
            "model": body["model"],
            "choices": [{"index": 0, "finish_reason": "stop", "message": message}],
            "usage": {"prompt_tokens": 1, "completion_tokens": 1, "total_tokens": 2},
        }
        data = json.dumps(answer).encode()
        self.send_response(200)
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(data)))
        self.end_headers()
        self.wfile.write(data)


@pytest.fixture
def server() -> Iterator[str]:
    httpd = ThreadingHTTPServer(("127.0.0.1", 0), _Chat)
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{httpd.server_address[1]}/v1"
    finally:
        httpd.shutdown()


@needs_suite
def test_model_asked_with_and_without_pictures(written: Path, server: str) -> None:
    shown = read_questions(written / "questions.jsonl")[:3]
    png = (written / "images" / shown[0].image).read_bytes()
    with_pictures = ModelAnswerer({"model": "m", "base_url": server}, pictures=True)
    text_only = ModelAnswerer({"model": "m", "base_url": server}, pictures=False)
    assert parse_letter(with_pictures.answer(shown[0], png)) == "A"
    assert parse_letter(text_only.answer(shown[0], png)) == "B"
    sent = _Chat.seen[-2]["messages"][0]["content"]
    assert sent[1]["image_url"]["url"].startswith("data:image/png;base64,")
    assert text_only.label == "m (text only)"


@needs_suite
def test_hf_questions_config_loads(written: Path, tmp_path: Path) -> None:
    """The Hub's loader reads the ``questions`` configuration; splits follow the signatures."""
    datasets = pytest.importorskip("datasets")
    got = datasets.load_dataset(str(written / "hf"), "questions", cache_dir=str(tmp_path))
    shown = {q.id: q for q in read_questions(written / "questions.jsonl")}
    assert sum(len(got[k]) for k in got) == len(shown)
    for split in got:
        for row in got[split]:
            q = shown[row["id"]]
            assert q.split == split and row["answer"] == q.answer
            assert row["images"][0].size[0] > 100 and json.loads(row["proof"]) == q.proof
    levels = {split: {row["level"] for row in got[split]} for split in got}
    assert not (levels.get("train", set()) & levels.get("test", set()))


@needs_suite
@pytest.mark.slow
def test_same_bytes_under_any_hash_seed(tmp_path: Path) -> None:
    """Two processes with different PYTHONHASHSEED write the same questions and TSV."""
    import os
    import subprocess
    import sys

    outs = []
    for seed in ("1", "2"):
        out = tmp_path / seed
        env = {**os.environ, "PYTHONHASHSEED": seed}
        cmd = [sys.executable, "-m", "chaingeo.cli.main", "questions", *IDS, "--out", str(out)]
        subprocess.run(cmd, check=True, env=env, capture_output=True)
        outs.append(out)
    for name in ("questions.jsonl", "questions.tsv"):
        assert (outs[0] / name).read_bytes() == (outs[1] / name).read_bytes()
