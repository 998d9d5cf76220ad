"""Hostile model folders for ``chain import`` (issue #21, item 11): mesh paths that leave the
folder, broken or oversized OBJ files, malformed URDF numbers. Each is one
:class:`ModelImportError` naming the part and the file, decided before any mesh is parsed where
the problem is the path or the size, and never a traceback. Small synthetic models only."""

from __future__ import annotations

import os
import random
from pathlib import Path
from typing import Any

import pytest
import trimesh

from chaingeo.cli.main import main
from chaingeo.core import limits
from chaingeo.core.formats.models import ModelImportError, import_model

_CORNERS = [(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)]
#: A unit cube (scaled by 0.1 in the URDF), faces outwards.
CUBE = "".join(f"v {x} {y} {z}\n" for x, y, z in _CORNERS) + "".join(
    f"f {a} {b} {c}\n"
    for a, b, c in [(1, 3, 4), (1, 4, 2), (5, 6, 8), (5, 8, 7), (1, 2, 6), (1, 6, 5),
                    (2, 4, 8), (2, 8, 6), (4, 3, 7), (4, 7, 8), (3, 1, 5), (3, 5, 7)]
)  # fmt: skip


def grid_box(lo: tuple[int, int, int], hi: tuple[int, int, int], n: int, first: int) -> list[str]:
    """OBJ lines of a box, each face an ``n`` by ``n`` grid of quads split in two (``12 n**2``
    triangles, faces outwards); its vertices are numbered from ``first``."""
    lines: list[str] = []
    faces: list[str] = []
    for axis in range(3):
        for high in (False, True):
            u, v = ((axis + 2) % 3, (axis + 1) % 3) if high else ((axis + 1) % 3, (axis + 2) % 3)
            base = first + len(lines)
            for i in range(n + 1):
                for j in range(n + 1):
                    p = [0.0, 0.0, 0.0]
                    p[axis] = hi[axis] if high else lo[axis]
                    p[u] = lo[u] + (hi[u] - lo[u]) * i / n
                    p[v] = lo[v] + (hi[v] - lo[v]) * j / n
                    lines.append(f"v {p[0]} {p[1]} {p[2]}")
            for i in range(n):
                for j in range(n):
                    a = base + i * (n + 1) + j
                    b, c, d = a + n + 1, a + n + 2, a + 1
                    faces += [f"f {a} {b} {c}", f"f {a} {c} {d}"]
    return lines + faces


def staircase(steps: int, n: int) -> str:
    """``steps`` columns side by side along x, column k ``k + 1`` units high and ``steps``
    deep: a plane at every unit, so the lattice unit is 1 (from x = 1 on, beside ``a``)."""
    out: list[str] = []
    vertices = 0
    for k in range(steps):
        box = grid_box((k + 1, 0, 0), (k + 2, steps, k + 1), n, vertices + 1)
        vertices += sum(1 for line in box if line.startswith("v"))
        out += box
    return "\n".join(out) + "\n"


def write_model(
    root: Path,
    *,
    filename: str = "../meshes/obj/a.obj",
    obj: str | bytes = CUBE,
    rgba: str = "1 0 0 1",
    xyz: str = "0 0 0",
    urdf: bytes | None = None,
) -> Path:
    """A model folder with one part ``a`` (``a/urdf/a.urdf`` naming ``filename``)."""
    (root / "a" / "urdf").mkdir(parents=True)
    (root / "a" / "meshes" / "obj").mkdir(parents=True)
    data = obj.encode() if isinstance(obj, str) else obj
    (root / "a" / "meshes" / "obj" / "a.obj").write_bytes(data)
    text = (
        f'<robot name="a"><link name="a"><visual><origin xyz="{xyz}" rpy="0 0 0"/>'
        f'<material name="m"/><geometry><mesh filename="{filename}" scale="0.1 0.1 0.1"/>'
        f'</geometry></visual></link><material name="m"><color rgba="{rgba}"/></material>'
        "</robot>"
    )
    (root / "a" / "urdf" / "a.urdf").write_bytes(urdf if urdf is not None else text.encode())
    return root


def write_part(root: Path, name: str, obj: str, rgba: str) -> None:
    """Another part ``name`` beside ``a`` (same layout)."""
    (root / name / "urdf").mkdir(parents=True)
    (root / name / "meshes" / "obj").mkdir(parents=True)
    (root / name / "meshes" / "obj" / f"{name}.obj").write_text(obj)
    (root / name / "urdf" / f"{name}.urdf").write_text(
        f'<robot name="{name}"><link name="{name}"><visual><material name="m"/><geometry>'
        f'<mesh filename="../meshes/obj/{name}.obj" scale="0.1 0.1 0.1"/></geometry></visual>'
        f'</link><material name="m"><color rgba="{rgba}"/></material></robot>'
    )


@pytest.fixture
def no_parsing(monkeypatch: pytest.MonkeyPatch) -> None:
    """Fail the test if trimesh is asked to parse anything."""

    def refuse(*args: Any, **kwargs: Any) -> None:
        raise AssertionError("a mesh was parsed")

    monkeypatch.setattr(trimesh, "load", refuse)


def _refusal(model: Path) -> ModelImportError:
    with pytest.raises(ModelImportError) as err:
        import_model(model)
    assert err.value.source == str(model)
    assert err.value.field.startswith("a/urdf/a.urdf"), err.value  # the part and its URDF
    return err.value


# ---------------------------------------------------------------------------------------------
# Paths
# ---------------------------------------------------------------------------------------------


def _outside(tmp_path: Path) -> Path:
    secret = tmp_path / "outside" / "secret.obj"
    secret.parent.mkdir()
    secret.write_text(CUBE)  # a valid mesh: only the path may refuse it
    return secret


@pytest.mark.usefixtures("no_parsing")
def test_mesh_path_up_and_out_is_refused_unopened(tmp_path: Path) -> None:
    _outside(tmp_path)
    model = write_model(tmp_path / "m", filename="../../../../outside/secret.obj")
    assert "leads outside the model folder" in _refusal(model).reason
    passwd = write_model(tmp_path / "p", filename="../" * 40 + "etc/passwd")
    assert "leads outside the model folder" in _refusal(passwd).reason


@pytest.mark.usefixtures("no_parsing")
def test_absolute_mesh_path_is_refused_unopened(tmp_path: Path) -> None:
    secret = _outside(tmp_path)
    model = write_model(tmp_path / "m", filename=str(secret))
    assert "an absolute path" in _refusal(model).reason


@pytest.mark.usefixtures("no_parsing")
def test_symlink_out_of_the_folder_is_refused_unopened(tmp_path: Path) -> None:
    secret = _outside(tmp_path)
    model = write_model(tmp_path / "m", filename="../meshes/obj/link.obj")
    os.symlink(secret, model / "a" / "meshes" / "obj" / "link.obj")
    assert "leads outside the model folder" in _refusal(model).reason
    # a whole part folder that is a link elsewhere: its URDF is outside too
    other = write_model(tmp_path / "elsewhere")
    (tmp_path / "n").mkdir()
    os.symlink(other / "a", tmp_path / "n" / "a")
    assert "leads outside" in _refusal(tmp_path / "n").reason


@pytest.mark.usefixtures("no_parsing")
@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
def test_fifo_named_as_a_mesh_is_never_opened(tmp_path: Path) -> None:
    """Opening a FIFO blocks until someone writes to it: only regular files are read."""
    model = write_model(tmp_path, filename="../meshes/obj/pipe.obj")
    os.mkfifo(model / "a" / "meshes" / "obj" / "pipe.obj")
    assert _refusal(model).reason == "mesh '../meshes/obj/pipe.obj': not a regular file"


def test_refusal_is_one_line_from_the_command(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    model = write_model(tmp_path / "m", filename="../" * 40 + "etc/passwd")
    assert main(["import", str(model)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "a/urdf/a.urdf visual[0]" in err and "etc/passwd" in err


# ---------------------------------------------------------------------------------------------
# Sizes: refused before parsing
# ---------------------------------------------------------------------------------------------


@pytest.mark.usefixtures("no_parsing")
def test_oversized_mesh_file_is_refused_unread(tmp_path: Path) -> None:
    model = write_model(tmp_path, obj=CUBE + "#" * limits.MAX_MESH_BYTES)
    assert f"at most {limits.MAX_MESH_BYTES}" in _refusal(model).reason


@pytest.mark.usefixtures("no_parsing")
def test_too_many_triangles_are_refused_before_parsing(tmp_path: Path) -> None:
    obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\n" + "f 1 2 3\n" * (limits.MAX_PART_TRIANGLES + 1)
    model = write_model(tmp_path, obj=obj)
    reason = _refusal(model).reason
    assert f"{limits.MAX_PART_TRIANGLES + 1} triangles" in reason and "a.obj" in reason


def test_voxeliser_work_is_bounded_before_it_starts(tmp_path: Path) -> None:
    """A unit cube beside a 20-step staircase of 2,160 triangles: some 8,000 cells times 27
    samples times 2,160 triangles is past MAX_WINDING_PAIRS, refused before any work."""
    model = write_model(tmp_path)
    write_part(model, "b", staircase(20, 3), "0 0 1 1")
    with pytest.raises(ModelImportError) as err:
        import_model(model, "puzzle")
    assert err.value.field.startswith("parts.")
    assert "sample-triangle pairs" in err.value.reason


# ---------------------------------------------------------------------------------------------
# Contents: one typed error naming the part and the file, never a traceback
# ---------------------------------------------------------------------------------------------

BAD_OBJ: dict[str, tuple[str | bytes, str]] = {
    "face index past the end": (CUBE + "f 1 2 99\n", "face 13 has corner '99'"),
    "negative index past the start": (CUBE + "f -1 -2 -9\n", "corner '-9'"),
    "index zero": (CUBE + "f 0 1 2\n", "corner '0'"),
    "non-numeric index": (CUBE + "f a b c\n", "corner 'a'"),
    "superscript index": (CUBE + "f 1 2 \u00b2\n", "corner '\u00b2'"),
    "20-digit index": (CUBE + "f 1 2 " + "9" * 20 + "\n", "corner '99999"),
    "not UTF-8": (CUBE.encode() + b"# \xff\xfe\n", "not UTF-8 text"),
    "infinite vertex": (CUBE.replace("v 1 1 1", "v 1e999 1 1"), "not a finite number"),
    "nan vertex": (CUBE.replace("v 1 1 1", "v nan 1 1"), "not a finite number"),
    "word for a vertex": (CUBE.replace("v 1 1 1", "v 1 one 1"), "not a number"),
    "no faces": ("v 0 0 0\n", "holds no triangles"),
}


@pytest.mark.parametrize("case", sorted(BAD_OBJ))
def test_bad_obj_is_a_typed_error(case: str, tmp_path: Path) -> None:
    obj, reason = BAD_OBJ[case]
    error = _refusal(write_model(tmp_path, obj=obj))
    assert reason in error.reason and "mesh '../meshes/obj/a.obj'" in error.reason


BAD_URDF: dict[str, tuple[dict[str, Any], str]] = {
    "short rgba": ({"rgba": "1 0"}, "rgba: expected 4 numbers, got '1 0'"),
    "words for rgba": ({"rgba": "a b c d"}, "rgba: expected 4 numbers"),
    "rgba past 1": ({"rgba": "2 0 0 1"}, "not four numbers from 0 to 1"),
    "nan origin": ({"xyz": "nan 0 0"}, "origin xyz: 'nan 0 0' holds a number that is not"),
    "huge origin": ({"xyz": "1e300 0 0"}, "beyond"),
    "doctype": ({"urdf": '<!DOCTYPE r [<!ENTITY x "y">]><robot/>'.encode("utf-16")}, "DOCTYPE"),
    "not xml": ({"urdf": b"\x00\x01"}, "invalid XML"),
}


@pytest.mark.parametrize("case", sorted(BAD_URDF))
def test_bad_urdf_is_a_typed_error(case: str, tmp_path: Path) -> None:
    kwargs, reason = BAD_URDF[case]
    assert reason in _refusal(write_model(tmp_path, **kwargs)).reason


def _hostile_obj(rng: random.Random) -> bytes:
    """Random bytes, or random OBJ-shaped lines (vertices, faces with wild indices)."""
    if rng.random() < 0.3:
        return rng.randbytes(rng.randrange(1, 400))
    words = ["v", "f", "vn", "vt", "o", "g", "s", "usemtl", "mtllib", "l", "#"]
    numbers = ["0", "1", "-1", "3", "8", "9", "1e999", "nan", "0.5", "x", "1/1/1", "2//3", ""]
    lines = [CUBE] if rng.random() < 0.5 else []
    for _ in range(rng.randrange(1, 30)):
        lines.append(" ".join([rng.choice(words), *rng.choices(numbers, k=rng.randrange(0, 6))]))
    return "\n".join(lines).encode()


@pytest.mark.parametrize("seed", range(40))
def test_random_obj_never_raises_anything_but_the_typed_error(seed: int, tmp_path: Path) -> None:
    model = write_model(tmp_path, obj=_hostile_obj(random.Random(seed)))
    try:
        import_model(model)
    except ModelImportError as e:
        assert e.field.startswith(("a/urdf/a.urdf", "parts", "lattice", "(folder)")), e
