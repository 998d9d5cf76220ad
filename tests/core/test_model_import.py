"""CHAIN's own URDF/OBJ models imported exactly (skipped when ../shared/chain-models is absent),
plus small synthetic models written here, which pin the refusals and the snapping down."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from chaingeo.cli.main import main
from chaingeo.core.colors import PALETTE
from chaingeo.core.formats.mesh_lattice import rpy_matrix
from chaingeo.core.formats.models import (
    LICENCE,
    ImportedModel,
    ModelImportError,
    import_model,
    model_puzzle_level,
    model_stacking_level,
)
from chaingeo.core.kinematics import replay_disassembly
from chaingeo.core.level import LevelError, level_bytes, load_level, save_level
from chaingeo.solvers.cover.packings import first_packing
from chaingeo.solvers.limits import SearchLimits
from chaingeo.solvers.motion.disassemble import Analysis, analyze_assembly
from tests.support.shared_files import MODELS, needs_models

#: What each model must give: kind and cells per part (in part order), or the refusal.
EXPECTED: dict[str, tuple[str, list[int]] | str] = {
    "3x3-stacking-puzzle": ("stacking", [3, 4, 4, 4, 4, 4, 4]),
    "interlocking-cube-puzzle": ("puzzle", [136, 136, 20, 20, 20, 20, 26, 26, 22, 28, 28, 30]),
    "liliput": ("puzzle", [42, 12, 10]),
    "luban-15-piece": ("puzzle", [18, 34, 34, 34, 36, 36, 36, 36, 36, 36, 20, 20, 20, 20, 20]),
    "luban-3-piece": ("puzzle", [34, 36, 34]),
    "luban-6-piece": ("puzzle", [32, 33, 33, 32, 30, 40]),
    "luban-diagonal-6-piece": "refused",
    "luban-separate-pieces": ("puzzle", [28] * 11 + [26]),
    "tangled-nails": "refused",
    "three-plate-burr-puzzle": ("puzzle", [42, 48, 44]),
}
#: Needs a rotation to come apart (rotations are not moves here).
NEEDS_ROTATION = {"luban-3-piece"}
LIMITS = SearchLimits(max_states=200_000, seconds=60.0, max_total_states=2_000_000)


@pytest.fixture(scope="module")
def imported() -> dict[str, ImportedModel | ModelImportError]:
    assert MODELS is not None
    out: dict[str, ImportedModel | ModelImportError] = {}
    for name in EXPECTED:
        try:
            out[name] = import_model(MODELS / name)
        except ModelImportError as e:
            out[name] = e
    return out


@pytest.fixture(scope="module")
def analyses(imported: dict[str, ImportedModel | ModelImportError]) -> dict[str, Analysis]:
    return {
        name: analyze_assembly(m.shapes, limits=LIMITS, optimal=True)
        for name, m in imported.items()
        if isinstance(m, ImportedModel) and m.kind == "puzzle"
    }


def test_every_model_is_listed() -> None:
    if MODELS is None:
        pytest.skip("../shared/chain-models is not present")
    assert sorted(p.name for p in MODELS.iterdir() if p.is_dir()) == sorted(EXPECTED)


@needs_models
@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_model_imports_or_is_refused(
    name: str, imported: dict[str, ImportedModel | ModelImportError]
) -> None:
    got, want = imported[name], EXPECTED[name]
    if want == "refused":
        assert isinstance(got, ModelImportError) and isinstance(got, LevelError)
        assert got.field == "lattice" and "faces along x, y or z" in got.reason
        return
    assert isinstance(got, ImportedModel) and not isinstance(want, str), got
    kind, cells = want
    assert got.kind == kind
    assert [len(p.shape) for p in got.parts] == cells
    assert got.fit.rms <= 0.08 and got.fit.unit > 0
    assert all(p.shape.is_connected() for p in got.parts)
    names = [p.name for p in got.parts]
    assert len(set(names)) == len(names) and set(names) <= {c.name for c in PALETTE}
    if kind == "puzzle":
        owner: set[tuple[int, int, int]] = set()
        for p in got.parts:
            assert owner.isdisjoint(p.shape.cell_set)
            owner |= p.shape.cell_set


@needs_models
@pytest.mark.parametrize("name", sorted(k for k, v in EXPECTED.items() if v != "refused"))
def test_level_validates_round_trips_and_replays(
    name: str,
    imported: dict[str, ImportedModel | ModelImportError],
    analyses: dict[str, Analysis],
    tmp_path: Path,
) -> None:
    model = imported[name]
    assert isinstance(model, ImportedModel)
    if model.kind == "stacking":
        assert model.box == (3, 3, 3)
        sol = first_packing(model.shapes, model.box, reflections=False)
        assert sol is not None
        level = model_stacking_level(model, dict(sol.placements), difficulty="hard")
    else:
        a = analyses[name]
        if name in NEEDS_ROTATION:
            assert not a.disassemblable
            return
        assert a.disassemblable and a.optimal_steps == len(a.plan)
        final = replay_disassembly(model.shapes, a.plan)  # the reference kinematics
        assert final.is_separated()
        level = model_puzzle_level(model, a.plan, difficulty="mid")
        assemble = model_puzzle_level(model, a.plan, goal="assemble", difficulty="mid")
        assert assemble.optimal_steps == level.optimal_steps
    path = save_level(level, tmp_path / f"{level.id}.json")
    again = load_level(path)
    assert level_bytes(again) == level_bytes(level) == path.read_bytes()
    assert name in level.provenance.generator and LICENCE in level.provenance.generator
    source = level.stats["source"]
    assert source["model"] == name and source["licence"] == "Apache-2.0"
    assert source["copyright"] == "the CHAIN authors"


@needs_models
def test_clearance_parts_are_snapped_and_reported(
    imported: dict[str, ImportedModel | ModelImportError],
) -> None:
    model = imported["luban-15-piece"]
    assert isinstance(model, ImportedModel)
    moved = model.moved_parts(0.1)
    assert moved and all(max(abs(v) for v in m) < 0.3 for m in moved.values())
    assert model.summary()["moved_units"]


@needs_models
def test_outer_corner_cells_are_decided_and_reported(
    imported: dict[str, ImportedModel | ModelImportError],
) -> None:
    cube = imported["interlocking-cube-puzzle"]
    assert isinstance(cube, ImportedModel)
    assert sum(len(p.decided) for p in cube.parts) == 8  # the cut corners of the end plates
    assert sum(len(p.shape) for p in cube.parts) == 8**3  # so the cube is whole


@needs_models
def test_colours_follow_the_materials(
    imported: dict[str, ImportedModel | ModelImportError],
) -> None:
    lock = imported["luban-6-piece"]
    assert isinstance(lock, ImportedModel)
    names = {p.part: p.name for p in lock.parts}
    assert names["obj_1"] == "orange" and names["obj_4"] == "yellow"  # orange and yellow URDFs


@needs_models
def test_import_is_deterministic(imported: dict[str, ImportedModel | ModelImportError]) -> None:
    assert MODELS is not None
    first = imported["luban-6-piece"]
    assert isinstance(first, ImportedModel)
    assert import_model(MODELS / "luban-6-piece").summary() == first.summary()


@needs_models
def test_command_writes_a_level_or_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert MODELS is not None
    out = tmp_path / "levels"
    out.mkdir()
    assert main(["import", str(MODELS / "luban-6-piece"), "--out", str(out)]) == 0
    written = sorted(out.iterdir())
    assert [p.name for p in written] == ["chain-luban-6-piece.json"]
    assert load_level(written[0]).stats["source"]["model"] == "luban-6-piece"
    for refused in ("tangled-nails", "luban-3-piece"):
        assert main(["import", str(MODELS / refused), "--out", str(out)]) == 2
        assert "error" in capsys.readouterr().err
    assert sorted(out.iterdir()) == written


@needs_models
@pytest.mark.slow
def test_report_lists_every_model(capsys: pytest.CaptureFixture[str]) -> None:
    assert MODELS is not None
    assert main(["import", str(MODELS), "--report", "--json"]) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    assert {r["model"] for r in rows} == set(EXPECTED)
    for r in rows:
        assert (r["result"] == "refused") == (EXPECTED[r["model"]] == "refused")


# ---------------------------------------------------------------------------------------------
# Synthetic models: prisms written as URDF + OBJ
# ---------------------------------------------------------------------------------------------


def _prism_obj(polygon: list[tuple[float, float]], z0: float, z1: float) -> str:
    """A closed prism over a convex counter-clockwise polygon, faces pointing outwards."""
    n = len(polygon)
    lines = [f"v {x} {y} {z0}" for x, y in polygon] + [f"v {x} {y} {z1}" for x, y in polygon]
    for i in range(1, n - 1):
        lines.append(f"f 1 {i + 2} {i + 1}")
        lines.append(f"f {n + 1} {n + i + 1} {n + i + 2}")
    for i in range(n):
        j = (i + 1) % n
        lines.append(f"f {i + 1} {j + 1} {n + j + 1}")
        lines.append(f"f {i + 1} {n + j + 1} {n + i + 1}")
    return "\n".join(lines) + "\n"


def _write_part(
    root: Path,
    name: str,
    prisms: list[tuple[list[tuple[float, float]], float, float]],
    *,
    xyz: str = "0 0 0",
    rpy: str = "0 0 0",
    scale: float = 0.1,
    rgba: str = "1 0 0 1",
) -> None:
    (root / name / "urdf").mkdir(parents=True)
    (root / name / "meshes" / "obj").mkdir(parents=True)
    text = "".join(_prism_obj(p, z0, z1) for p, z0, z1 in prisms)
    (root / name / "meshes" / "obj" / f"{name}.obj").write_text(text)
    (root / name / "urdf" / f"{name}.urdf").write_text(
        f'<robot name="{name}"><link name="{name}_link"><visual>'
        f'<origin xyz="{xyz}" rpy="{rpy}"/><material name="m"/><geometry>'
        f'<mesh filename="../meshes/obj/{name}.obj" scale="{scale} {scale} {scale}"/>'
        f'</geometry></visual></link><material name="m"><color rgba="{rgba}"/></material>'
        "</robot>"
    )


def _box(x0: float, x1: float, y0: float, y1: float) -> list[tuple[float, float]]:
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]


def test_clearance_is_snapped_to_the_tightest_contact(tmp_path: Path) -> None:
    _write_part(tmp_path, "a", [(_box(0, 2, 0, 1), 0, 1)], rgba="0.902 0.098 0.294 1")
    # 0.28 units of clearance between the parts
    _write_part(tmp_path, "b", [(_box(2.28, 3.28, 0, 2), 0, 1)], rgba="0.263 0.388 0.847 1")
    model = import_model(tmp_path)
    a, b = model.parts
    assert (a.name, b.name) == ("red", "blue")
    assert len(a.shape) == 2 and len(b.shape) == 2
    assert a.shape.contact(b.shape) == 1
    moved = model.moved_parts(0.0)
    assert moved["b"][0] - moved["a"][0] == pytest.approx(-0.28, abs=1e-6)  # the gap, closed


def test_turned_parts_are_placed_exactly(tmp_path: Path) -> None:
    assert (rpy_matrix(1.5708, 0, 0) == [[1, 0, 0], [0, 0, -1], [0, 1, 0]]).all()
    _write_part(tmp_path, "a", [(_box(0, 3, 0, 1), 0, 1)], rpy="0 0 1.57080")
    model = import_model(tmp_path, "puzzle")
    assert model.parts[0].shape.extent == (1, 3, 1)  # the x-stick now lies along y


def test_a_cell_split_across_two_parts_is_refused(tmp_path: Path) -> None:
    # a diagonal cut through one cell shared by both parts: neither can have it
    _write_part(tmp_path, "a", [([(0, 0), (2, 0), (2, 1), (1, 2), (0, 2)], 0, 2)])
    _write_part(tmp_path, "b", [([(2, 1), (3, 1), (3, 3), (1, 3), (1, 2)], 0, 2)])
    with pytest.raises(ModelImportError, match="ambiguous cell") as err:
        import_model(tmp_path)
    assert err.value.field.startswith("parts.")


def test_missing_folder_is_a_typed_error(tmp_path: Path) -> None:
    with pytest.raises(ModelImportError, match="no such model folder"):
        import_model(tmp_path / "nothing")
    with pytest.raises(ModelImportError, match="urdf"):
        import_model(tmp_path)
