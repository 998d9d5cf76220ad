from __future__ import annotations

import copy
import json
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from chaingeo.core.formats.chain_json import (
    export_chain_stacking,
    import_chain_stacking,
    read_chain_stacking,
)
from chaingeo.core.geometry import ROTATIONS, Shape, puzzle_signature
from chaingeo.core.level import (
    Level,
    LevelError,
    content_hash,
    level_bytes,
    level_set_hash,
    load_level,
    parse_level,
    save_level,
    stacking_level,
)
from chaingeo.core.piecesets import BEDLAM_SOLUTION
from chaingeo.core.rules import StackingRules


def bedlam_level() -> Level:
    return stacking_level("bedlam-known", "hard", (4, 4, 4), list(BEDLAM_SOLUTION.values()))


def puzzle_json() -> dict[str, Any]:
    """Three pieces: blue stops red moving +x, green lies on red and blue."""
    pieces = {
        "red": [[0, 0, 0], [1, 0, 0], [2, 0, 0]],
        "blue": [[0, 1, 0], [1, 1, 0], [2, 1, 0], [3, 1, 0], [3, 0, 0]],
        "green": [[0, 0, 1], [1, 0, 1], [2, 0, 1], [3, 0, 1]],
    }
    shapes = [Shape(v) for v in pieces.values()]
    return {
        "format": "chain-level/1",
        "id": "lock-3",
        "family": "puzzle",
        "difficulty": "easy",
        "goal": "disassemble",
        "box": None,
        "pieces": [
            {"name": "red", "rgb": "#e6194b", "voxels": pieces["red"]},
            {"name": "blue", "rgb": "#4363d8", "voxels": pieces["blue"]},
            {"name": "green", "rgb": "#3cb44b", "voxels": pieces["green"]},
        ],
        "solution": {
            "moves": [
                {"pieces": ["green"], "direction": "+z", "distance": None},
                {"pieces": ["red"], "direction": "-x", "distance": None},
            ]
        },
        "optimal_steps": 2,
        "max_steps": 30,
        "rules": {"max_group": None},
        "provenance": {
            "generator": "manual",
            "version": "1",
            "seed": None,
            "index": None,
            "signature": puzzle_signature(shapes),
        },
        "stats": {},
    }


def test_stacking_round_trip_is_byte_identical(tmp_path: Path) -> None:
    level = bedlam_level()
    path = save_level(level, tmp_path / "a.json")
    again = load_level(path)
    assert again == level
    assert level_bytes(again) == path.read_bytes()
    assert content_hash(again) == content_hash(level)
    assert level.optimal_steps == 13 and level.max_steps >= 30


def test_an_unchanged_file_loads_once_and_a_changed_one_again(tmp_path: Path) -> None:
    """The same Level object for a file read before and unchanged since; a file rewritten
    (another level id, so other bytes) or a bad file in its place is read again."""
    path = save_level(bedlam_level(), tmp_path / "a.json")
    first = load_level(path)
    assert load_level(path) is first and load_level(str(path)) is first
    data = json.loads(path.read_text())
    data["id"] = "bedlam-renamed"
    path.write_text(json.dumps(data))
    assert load_level(path).id == "bedlam-renamed"
    path.write_text("{")
    with pytest.raises(LevelError):
        load_level(path)
    path.unlink()
    with pytest.raises(LevelError, match=r"a\.json"):
        load_level(path)


def test_puzzle_level_loads_and_round_trips(tmp_path: Path) -> None:
    level = parse_level(puzzle_json(), "lock")
    assert level.optimal_steps == 2
    path = save_level(level, tmp_path / "lock.json")
    assert load_level(path) == level
    assert path.read_bytes() == level_bytes(load_level(path))


def test_assemble_goal_is_the_reversed_disassembly() -> None:
    data = puzzle_json()
    data["goal"] = "assemble"
    data["solution"]["moves"] = [
        {"pieces": ["red"], "direction": "+x", "distance": None},
        {"pieces": ["green"], "direction": "-z", "distance": None},
    ]
    assert parse_level(data).goal == "assemble"


def test_level_set_hash_ignores_order() -> None:
    a, b = bedlam_level(), parse_level(puzzle_json())
    assert level_set_hash([a, b]) == level_set_hash([b, a]) != level_set_hash([a])


@given(st.sampled_from(ROTATIONS), st.integers(0, 1000))
def test_verified_level_stays_verified_after_serialisation(r: Any, salt: int) -> None:
    # Hand the pieces out in an arbitrary rotation: the level still verifies after a round trip.
    placements = list(BEDLAM_SOLUTION.values())
    handed = [p.rotate(r).normalized() for p in placements]
    level = stacking_level(
        f"bedlam-{salt}", "hard", (4, 4, 4), placements, handed=handed, seed=salt
    )
    assert parse_level(json.loads(level_bytes(level))) == level


def test_drop_rules_need_a_drop_order() -> None:
    # Two 1x1x2 columns side by side and a 2x1x1 lid: under drop rules the lid goes last.
    placements = [
        Shape([(0, 0, 2), (1, 0, 2)]),
        Shape([(0, 0, 0), (0, 0, 1)]),
        Shape([(1, 0, 0), (1, 0, 1)]),
    ]
    level = stacking_level("drop", "easy", (2, 1, 3), placements, rules=StackingRules("drop"))
    assert level.solution.order[-1] == "red"  # type: ignore[union-attr]


def _mutations() -> list[tuple[str, str, Any]]:
    """(description, expected field prefix, mutation) for every kind of bad stacking file."""

    def drop(key: str) -> Any:
        return lambda d: d.pop(key)

    def setp(path: list[Any], value: Any) -> Any:
        def f(d: dict[str, Any]) -> None:
            obj = d
            for k in path[:-1]:
                obj = obj[k]
            obj[path[-1]] = value

        return f

    return [
        ("missing field", "optimal_steps", drop("optimal_steps")),
        ("missing pieces", "pieces", drop("pieces")),
        ("bad format", "format", setp(["format"], "chain-level/0")),
        ("bad family", "family", setp(["family"], "jigsaw")),
        ("bad difficulty", "difficulty", setp(["difficulty"], "medium")),
        ("wrong goal", "goal", setp(["goal"], "disassemble")),
        ("box wrong type", "box", setp(["box"], "4x4x4")),
        ("box zero", "box[2]", setp(["box", 2], 0)),
        ("steps wrong type", "optimal_steps", setp(["optimal_steps"], "13")),
        ("steps bool", "max_steps", setp(["max_steps"], True)),
        ("budget too small", "max_steps", setp(["max_steps"], 5)),
        ("optimal differs from plan", "optimal_steps", setp(["optimal_steps"], 12)),
        ("voxel not a triple", "pieces[0].voxels[0]", setp(["pieces", 0, "voxels", 0], [0, 0])),
        ("duplicate colour", "pieces[1].rgb", setp(["pieces", 1, "rgb"], "#e6194b")),
        ("bad colour", "pieces[1].rgb", setp(["pieces", 1, "rgb"], "red")),
        ("duplicate name", "pieces[1].name", setp(["pieces", 1, "name"], "red")),
        (
            "disconnected piece",
            "pieces[0].voxels",
            setp(["pieces", 0, "voxels"], [[0, 0, 0], [2, 0, 0], [0, 1, 0], [0, 2, 0], [0, 3, 0]]),
        ),
        (
            "placement out of box",
            "solution.placements.red",
            setp(
                ["solution", "placements", "red"],
                [[4, 0, 0], [4, 1, 0], [4, 1, 1], [5, 1, 0], [6, 1, 0]],
            ),
        ),
        (
            "placement not the piece",
            "solution.placements.red",
            setp(
                ["solution", "placements", "red"],
                [[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0], [0, 1, 0]],
            ),
        ),
        (
            "missing placement",
            "solution.placements",
            lambda d: d["solution"]["placements"].pop("red"),
        ),
        ("order incomplete", "solution.order", lambda d: d["solution"]["order"].pop()),
        ("signature wrong", "provenance.signature", setp(["provenance", "signature"], "0" * 40)),
        ("unknown rule", "rules.gravity", setp(["rules", "gravity"], True)),
        ("stats not an object", "stats", setp(["stats"], [])),
    ]


@pytest.mark.parametrize(("what", "fld", "mutate"), _mutations(), ids=[m[0] for m in _mutations()])
def test_bad_stacking_files_give_a_level_error(
    tmp_path: Path, what: str, fld: str, mutate: Any
) -> None:
    data = json.loads(level_bytes(bedlam_level()))
    mutate(data)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data))
    with pytest.raises(LevelError) as err:
        load_level(path)
    assert err.value.field.startswith(fld), (what, str(err.value))
    assert str(path) in str(err.value)


@pytest.mark.parametrize(
    ("what", "fld", "mutate"),
    [
        ("overlap", "pieces", lambda d: d["pieces"][2]["voxels"].append([0, 0, 0])),
        (
            "illegal move",
            "solution.moves",
            lambda d: d["solution"]["moves"][1].update(direction="+x"),
        ),
        (
            "unknown piece",
            "solution.moves[0].pieces",
            lambda d: d["solution"]["moves"][0].update(pieces=["pink"]),
        ),
        (
            "bad direction",
            "solution.moves[0].direction",
            lambda d: d["solution"]["moves"][0].update(direction="up"),
        ),
        (
            "zero distance",
            "solution.moves[0].distance",
            lambda d: d["solution"]["moves"][0].update(distance=0),
        ),
        ("not separated", "solution.moves", lambda d: d["solution"]["moves"].pop()),
        ("box on a puzzle", "box", lambda d: d.update(box=[1, 1, 1])),
        (
            "group too big",
            "solution.moves[0].pieces",
            lambda d: (
                d["rules"].update(max_group=1),
                d["solution"]["moves"][0].update(pieces=["green", "red"]),
            ),
        ),
    ],
)
def test_bad_puzzle_files_give_a_level_error(what: str, fld: str, mutate: Any) -> None:
    data = puzzle_json()
    mutate(data)
    with pytest.raises(LevelError) as err:
        parse_level(data, "p.json")
    assert err.value.field.startswith(fld), (what, str(err.value))


@pytest.mark.parametrize(
    "content", [b"", b"{", b"\xff\xfe", b"[]", b"null", b'{"format": "chain-level/1"}']
)
def test_unreadable_files_give_a_level_error(tmp_path: Path, content: bytes) -> None:
    path = tmp_path / "x.json"
    path.write_bytes(content)
    with pytest.raises(LevelError):
        load_level(path)


def test_missing_file_gives_a_level_error(tmp_path: Path) -> None:
    with pytest.raises(LevelError, match="cannot read"):
        load_level(tmp_path / "nope.json")


def test_original_chain_format_round_trip(tmp_path: Path) -> None:
    level = bedlam_level()
    data = export_chain_stacking(level)
    assert data["box"] == [4, 4, 4] and len(data["pieces"]) == 13
    again = import_chain_stacking(copy.deepcopy(data), "bedlam-known", "hard")
    assert export_chain_stacking(again) == data
    path = tmp_path / "orig.json"
    path.write_text(json.dumps(data))
    read = read_chain_stacking(path)
    assert [p.chain_id for p in read.pieces] == [str(i) for i in range(13)]
    assert "chain_ids" not in read.stats  # the ids live on the pieces


@pytest.mark.parametrize(
    "data",
    [
        [],
        {"box": [4, 4], "pieces": [[[0, 0, 0]]]},
        {"box": [1, 1, 1], "pieces": []},
        {"box": [1, 1, 1], "pieces": [[[0, 0]]]},
        {"box": [1, 1, 2], "pieces": [[[0, 0, 0]]]},
        {"box": [1, 1, 2], "pieces": [[[0, 0, 0]], [[0, 0, 0]]]},
    ],
)
def test_bad_original_format_gives_a_level_error(data: Any) -> None:
    with pytest.raises(LevelError):
        import_chain_stacking(data, "x")
