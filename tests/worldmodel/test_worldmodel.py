"""chain worldmodel: the reference image, the prompt and the ground-truth video of a level."""

from __future__ import annotations

import hashlib
import io
import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from chaingeo.cli.main import main
from chaingeo.core.level import load_level
from chaingeo.worldmodel.prompt import worldmodel_prompt, write_worldmodel
from chaingeo.worldmodel.video import VideoError, plan_video
from tests.support.paths import LEVELS

TURNS = LEVELS / "puzzle" / "puzzle-easy-01-luban-3-piece.json"
ASSEMBLE = LEVELS / "puzzle" / "puzzle-easy-07-burr3.json"
STACK = LEVELS / "stacking" / "stacking-2x2x3-easy-s103-000000.json"


def test_prompt_states_the_rules_and_this_levels_pieces_and_goal() -> None:
    for path, goal in ((ASSEMBLE, "Put them together"), (STACK, "pack all 3 pieces")):
        level = load_level(path)
        text = worldmodel_prompt(level)
        assert goal in text
        for p in level.pieces:
            assert f"- {p.name} ({p.rgb}): {len(p.shape)} cubes" in text
        for rule in (
            "rigid",
            "never pass through",
            "teleports",
            "sliding along one of the three axes",
            "Add nothing, remove nothing, resize nothing",
        ):
            assert rule in text
        assert "quarter turn" not in text
    turning = worldmodel_prompt(load_level(TURNS))
    assert "key piece" in turning and "quarter turn (90 degrees)" in turning


def test_files_are_the_first_frame_the_prompt_and_the_video(tmp_path: Path) -> None:
    level = load_level(ASSEMBLE)
    files = write_worldmodel(level, tmp_path / "a", "gif", 128)
    # the command writes the same bytes (the same level gives the same files)
    args = ["worldmodel", str(ASSEMBLE), "--out", str(tmp_path / "b"), "--format", "gif"]
    assert main([*args, "--size", "128"]) == 0
    assert sorted(p.name for p in (tmp_path / "b").iterdir()) == sorted(
        p.name for p in files.values()
    )
    for path in files.values():
        assert path.read_bytes() == (tmp_path / "b" / path.name).read_bytes(), path.name
    first = plan_video(level, None, 128).frames[0]
    ref = Image.open(io.BytesIO(files["reference"].read_bytes())).convert("RGB")
    assert np.array_equal(np.asarray(ref), np.asarray(first))
    manifest = json.loads(files["manifest"].read_text(encoding="utf-8"))
    assert manifest["level"] == level.id
    for role in ("reference", "prompt", "ground_truth"):
        entry = manifest["files"][role]
        data = (tmp_path / "a" / entry["name"]).read_bytes()
        assert hashlib.sha256(data).hexdigest() == entry["sha256"]
    with pytest.raises(VideoError, match="unknown video format"):
        write_worldmodel(level, tmp_path / "c", "avi", 128)
