"""``chain bench robustness``, round three (issue #37): the surfaces added since round two, tried
as a hostile user would, each case bounded in time, seeded where random, counted like the
issue's table: cases, tracebacks (an exception that is not the project's typed error), hangs,
wrong acceptances (a verdict, count or success the input does not support) and files written
outside their folder or left partial. Every class must print zeros but its cases.

The classes: trajectory files (:func:`trajectories`), the precompiled-kernel store
(:func:`kernel_store`), run folders read back (:func:`run_folders`), ``.xmpuzzle`` XML
(:func:`xmpuzzles`), identifiers (:func:`identifiers`), game doors (:func:`game_doors`),
output folders with two writers and a full disk (:func:`writers`), decoded video limits
(:func:`video_limits`).
"""

from __future__ import annotations

import contextlib
import errno
import gzip
import hashlib
import json
import os
import random
import tempfile
from collections.abc import Callable, Iterator
from functools import partial
from pathlib import Path
from typing import Any

from chaingeo.benchmarks._surface_kit import (
    SEED,
    SPECIALS,
    Surface,
    always,
    grew,
    never,
    refused_but_used,
    special,
    surface_table,
    usable,
    valid,
    whole_clip,
)

# ---------------------------------------------------------------------------------------------
# check-trajectory
# ---------------------------------------------------------------------------------------------


def trajectories(tmp: Path) -> Surface:
    """Trajectory documents of a shipped burr: the parser's old sentinel key with every kind of
    value, pieces named twice, nesting, huge numbers, special files."""
    from chaingeo.core.files import UnreadableFile, read_bounded
    from chaingeo.core.limits import MAX_TRAJECTORY_BYTES
    from chaingeo.core.suite import load_level
    from chaingeo.worldmodel.trajectory import (
        parse_trajectory,
        puzzle_trajectory,
        trajectory_json,
    )
    from chaingeo.worldmodel.trajectory_verdict import check_trajectory

    level = load_level("puzzle-easy-07-burr3")
    doc = trajectory_json(level.id, puzzle_trajectory(level, None))
    s = Surface("check-trajectory")
    rng = random.Random(SEED)

    def verdict(text: str | Path) -> Any:
        raw = read_bounded(text, MAX_TRAJECTORY_BYTES) if isinstance(text, Path) else text
        return check_trajectory(level, parse_trajectory(raw))

    def invented(v: Any) -> bool:  # no piece is named twice in these files
        return any("twice" in x["reason"] for x in v.violations)

    values: list[Any] = [7, -1, "red", ["red", "blue"], [], {}, None, True, 1.5, [[0, 0, 0]]]
    for value in values:
        for key in ("\u0000dup", "dup"):
            bad = json.loads(json.dumps(doc))
            bad["frames"][rng.randrange(len(bad["frames"]))]["poses"][key] = value
            s.run(partial(verdict, json.dumps(bad)), invented)
    for text in ("[" * 100_000, '{"format": 1e999}', "[" + "9" * 5000 + "]", "", "\ud800"):
        s.run(partial(verdict, text), valid)
    for kind in SPECIALS:
        path = special(tmp / f"t-{kind}.json", kind)
        with contextlib.suppress(UnreadableFile):
            s.run(partial(verdict, path))
    return s


# ---------------------------------------------------------------------------------------------
# The precompiled-kernel store
# ---------------------------------------------------------------------------------------------


def kernel_store(tmp: Path) -> Surface:
    """A store whose manifest records its module, damaged one way per case; each must be
    refused by :func:`chaingeo.kernels.aot.status` before the module is imported."""
    import importlib.util

    import numpy as np

    from chaingeo.kernels import aot

    s = Surface("precompiled-kernel store")
    module = b"\x7fELF" + bytes(range(256)) * 32

    path_of = getattr(aot, "module_path", None) or getattr(aot, "_module_path")  # noqa: B009 (private before #37)

    def make(i: int) -> Path:
        folder = tmp / f"store{i}" / "tag"
        folder.mkdir(parents=True)
        src = folder.parent / "pkg" / "kernels.py"
        src.parent.mkdir()
        src.write_text("X = 1\n")
        st = src.stat()
        body = {
            "format": aot.FORMAT,
            "exports": {"chaingeo.pkg.kernels:k": {"<i8": "k0"}},
            "numpy": np.__version__,
            "numba": "0",
            "sources": {str(src): [st.st_size, st.st_mtime_ns, aot.file_digest(src)]},
            "module": {"size": len(module), "sha256": hashlib.sha256(module).hexdigest()},
        }
        (folder / aot.MANIFEST).write_text(json.dumps(body))
        path_of(folder).write_bytes(module)
        return folder

    def edit(folder: Path, change: Callable[[dict[str, Any]], Any]) -> None:
        body = json.loads((folder / aot.MANIFEST).read_text())
        change(body)
        (folder / aot.MANIFEST).write_text(json.dumps(body))

    damages: list[Callable[[Path], Any]] = [
        lambda f: path_of(f).write_bytes(module[:100]),
        lambda f: path_of(f).write_bytes(b""),
        lambda f: path_of(f).write_bytes(module[::-1]),
        lambda f: f.chmod(0o777),
        lambda f: path_of(f).chmod(0o666),
        lambda f: edit(f, lambda b: b["sources"].update({"/dev/zero": [1, 1, "0" * 64]})),
        lambda f: edit(f, lambda b: b.update(sources={})),
        lambda f: edit(f, lambda b: b.pop("module")),
        lambda f: edit(f, lambda b: b.update(format=1)),
        lambda f: edit(f, lambda b: b["exports"].update({"chaingeo.x.y:k": {"a": "k1"}})),
        lambda f: (f / aot.MANIFEST).write_text("[" * 200_000),
        lambda f: (f / aot.MANIFEST).write_text('{"format": 2, "sources": ' + "9" * 5000),
        lambda f: special(f / aot.MANIFEST, "zero"),
        lambda f: special(f / aot.MANIFEST, "fifo"),
        lambda f: special(f / aot.MANIFEST, "huge"),
        lambda f: special(path_of(f), "fifo"),
    ]
    imported: list[str] = []
    real = importlib.util.module_from_spec

    def spy(spec: Any) -> Any:
        imported.append(spec.name)
        raise ImportError("the bench never imports a store's module")

    setattr(importlib.util, "module_from_spec", spy)  # noqa: B010
    try:
        for i, damage in enumerate(damages):
            folder = make(i)
            damage(folder)
            before = len(imported)
            aot._loaded = None
            s.run(partial(aot.load, folder), partial(grew, imported, before))
            s.run(partial(aot.status, folder), usable)
    finally:
        setattr(importlib.util, "module_from_spec", real)  # noqa: B010
        aot._loaded = None
    return s


# ---------------------------------------------------------------------------------------------
# Run folders read back (chain report, --html)
# ---------------------------------------------------------------------------------------------


def _a_run(root: Path, resume: bool = False) -> Path:
    from chaingeo.core.geometry import Shape
    from chaingeo.core.level import stacking_level
    from chaingeo.evaluation.agents.base import AgentSpec
    from chaingeo.evaluation.runner import RunConfig, evaluate

    cells = [Shape([(i, 0, 0)]) for i in range(2)]
    levels = [stacking_level(f"L{i}", "easy", (2, 1, 1), cells) for i in range(2)]
    cfg = RunConfig(progress=False, resume=resume)
    evaluate(levels, AgentSpec("random"), root / "run", None, cfg)
    return root / "run"


def run_folders(tmp: Path) -> Surface:
    """A real run, damaged one way per case, read by the report's tables and the site."""
    import shutil

    from chaingeo.evaluation.report.site import write_site
    from chaingeo.evaluation.report.tables import load_run

    base = _a_run(tmp / "base")
    s = Surface("run folders into report / --html")

    def record(change: Callable[[dict[str, Any]], Any]) -> Callable[[Path], None]:
        def edit(run: Path) -> None:
            recs = [json.loads(x) for x in (run / "episodes.jsonl").read_text().splitlines()]
            change(recs[0])
            (run / "episodes.jsonl").write_text("".join(json.dumps(r) + "\n" for r in recs))

        return edit

    secret = tmp / "secret.png"
    secret.write_bytes(b"\x89PNG not the run's")
    name = hashlib.sha256(secret.read_bytes()).hexdigest() + ".png"

    def outside(run: Path) -> None:
        (run / "images" / name).symlink_to(secret)
        record(lambda r: r["steps"].append({"turn": 0, "images": {"front": name}}))(run)

    damages: list[Callable[[Path], Any]] = [
        lambda r: (r / "episodes.jsonl").write_text("[" * 100_000 + "\n"),
        record(lambda r: r.update(sample=1e300)),
        record(lambda r: r.update(sample=-3)),
        record(lambda r: r.update(usage="lots")),
        record(lambda r: r.update(success="yes")),
        record(lambda r: r.update(level_id="L0\n")),
        record(lambda r: r.update(key="x#0")),
        record(lambda r: r.update(steps=5)),
        record(lambda r: r.update(cost_usd="free")),
        record(lambda r: r["steps"].append({"turn": "x"})),
        lambda r: special(r / "episodes.jsonl", "zero"),
        lambda r: special(r / "episodes.jsonl", "fifo"),
        lambda r: special(r / "header.json", "zero"),
        lambda r: special(r / "header.json", "fifo"),
        lambda r: special(r / "header.json", "huge"),
        lambda r: (r / "header.json").write_text("[" * 100_000),
        outside,
    ]

    def report(run: Path, i: int) -> tuple[int, bool]:
        loaded = [load_run(run)]
        site = write_site(loaded, tmp / f"site{i}")  # its report/ too
        won = sum(o.success for o in loaded[0].outcomes)
        return won, (site / "images" / name).exists()

    for i, damage in enumerate(damages):
        run = tmp / f"r{i}"
        shutil.copytree(base, run, symlinks=True)
        damage(run)

        # Each damage but the last must be refused; the last (a picture linked from outside
        # the run) is read, but the picture must not be copied.
        last = i == len(damages) - 1
        result = s.run(partial(report, run, i), always if not last else never)
        if isinstance(result, tuple) and result[1]:
            s.outside += 1
    return s


# ---------------------------------------------------------------------------------------------
# .xmpuzzle XML
# ---------------------------------------------------------------------------------------------


def xmpuzzles(tmp: Path) -> Surface:
    """BurrTools files: deep nesting inside a stored solution, millions of elements, huge grids,
    multi-member gzip (read whole), trailing data, DOCTYPEs."""
    from chaingeo.core.formats.bt_read import parse_xmpuzzle
    from chaingeo.core.formats.bt_write import assembled_puzzle, xmpuzzle_xml
    from chaingeo.core.suite import load_level

    xml = xmpuzzle_xml(assembled_puzzle(load_level("puzzle-easy-04-burr6").shapes))
    at = xml.index(b"</solution>")
    s = Surface(".xmpuzzle XML")
    whole = parse_xmpuzzle(xml)
    cases: list[bytes] = []
    for depth in (300, 5_000, 100_000):
        cases.append(xml[:at] + b"<s>" * depth + b"</s>" * depth + xml[at:])
    cases.append(xml[:at] + b"<a/>" * 1_000_000 + xml[at:])
    grid = b'<voxel x="100" y="100" z="100" type="0">' + b"_" * 1_000_000 + b"</voxel>"
    shapes = xml.index(b"</shapes>")
    cases.append(xml[:shapes] + grid * 3 + xml[shapes:])
    cases.append(b'<!DOCTYPE p [<!ENTITY a "aaaa">]>' + xml)
    cases.append(xml.decode().encode("utf-16"))
    for data in cases:
        s.run(partial(parse_xmpuzzle, gzip.compress(data)))
    for cut in (0.1, 0.5, 0.9):
        k = int(len(xml) * cut)
        two = gzip.compress(xml[:k]) + gzip.compress(xml[k:])
        if isinstance(s.run(partial(parse_xmpuzzle, two), whole.__ne__), Exception):
            s.wrong += 1  # a valid file refused (read up to its first member)
    s.run(lambda: parse_xmpuzzle(gzip.compress(xml) + b"junk"))
    return s


# ---------------------------------------------------------------------------------------------
# Identifiers
# ---------------------------------------------------------------------------------------------


def identifiers(tmp: Path) -> Surface:
    """A level with each identifier followed by a stray character: refused, never accepted."""
    from chaingeo.core.level import level_bytes, load_level, parse_level
    from chaingeo.core.suite import load_level as shipped

    data = json.loads(level_bytes(shipped("puzzle-easy-04-burr6")))
    s = Surface("identifiers")
    for suffix in ("\n", "\r", "\r\n", " ", "\t", "\x00", "\u2028"):
        for fieldname in ("id", "name", "rgb"):
            bad = json.loads(json.dumps(data))
            if fieldname == "id":
                bad["id"] += suffix
            else:
                bad["pieces"][0][fieldname] += suffix
            s.run(partial(parse_level, bad, "bench"), always)
    path = tmp / "ok.json"
    path.write_text(json.dumps(data))
    s.run(lambda: load_level(path))
    return s


# ---------------------------------------------------------------------------------------------
# Gymnasium / vector / verifiers game
# ---------------------------------------------------------------------------------------------


def _hostile_actions(rng: random.Random, names: list[str]) -> Iterator[Any]:
    pool: list[Any] = [None, 5, 2.5, b"finish", ["finish"], {"a": 1}, "", "finish", "\ud800"]
    while True:
        r = rng.random()
        if r < 0.3:
            yield rng.choice(pool)
        elif r < 0.5:
            yield "x" * rng.choice((1_025, 10_000, 100_000))
        else:
            name = rng.choice(names)
            yield rng.choice((f"move {name} +x", f"place {name} (1,1,1)", f"pickup {name}"))


def game_doors(tmp: Path, calls: int = 600) -> Surface:
    """Seeded hostile calls into the Gymnasium environments and a vector environment; a step
    that raises, or that refuses yet uses a step, is a failure. (The chat game of the verifiers
    door is a layer this package may not import: ``tests/envs/test_gym_hostile.py`` tries it.)"""
    import gymnasium

    from chaingeo.core.suite import load_level
    from chaingeo.envs.gym import PuzzleEnv, StackingEnv

    rng = random.Random(SEED + 7)
    s = Surface("Gymnasium / vector game")
    levels = [load_level("puzzle-easy-04-burr6"), load_level("stacking-2x2x2-easy-s101-000000")]
    envs = [PuzzleEnv([levels[0]], images=False), StackingEnv([levels[1]], images=False)]
    for env in envs:
        names = [p.name for p in env.levels[next(iter(env.levels))].pieces]
        actions = _hostile_actions(rng, names)
        env.reset(seed=1)
        for _ in range(calls // 4):
            if env.state.is_success() or env.state.finished or env.state.is_truncated():
                env.reset(seed=1)
            action, used = next(actions), env.state.steps_used

            unused = partial(refused_but_used, env, used)
            if isinstance(s.run(partial(env.step, action), unused), BaseException) and (
                env.state.steps_used != used
            ):
                s.wrong += 1  # it raised after using the step
        hostile_options: list[Any] = ["x", 5, ["level"], {"level": ["x"]}, {"level": "nope"}]
        for options in hostile_options:
            s.run(partial(env.reset, options=options), always)
    vector = gymnasium.vector.SyncVectorEnv([lambda: StackingEnv([levels[1]], images=False)] * 2)
    vector.reset(seed=2)
    actions = _hostile_actions(rng, [p.name for p in levels[1].pieces])
    for _ in range(calls // 8):
        s.run(lambda: vector.step((next(actions), next(actions))))
    vector.close()
    return s


# ---------------------------------------------------------------------------------------------
# Output folders: two writers, a full disk
# ---------------------------------------------------------------------------------------------


def writers(tmp: Path) -> Surface:
    """A second writer on a locked run folder, site and dataset folder; a full disk (ENOSPC)
    at each write of a new run, its records and the report: refused with a typed error or an
    ``OSError`` naming the path, nothing partial left, each finished episode recorded once and
    the run resumable."""
    from chaingeo.core import files
    from chaingeo.evaluation import logs
    from chaingeo.evaluation.report import tables

    s = Surface("two writers, a full disk")
    base = _a_run(tmp / "base")
    for target in (base, tmp / "site", tmp / "rep"):
        if not hasattr(files, "lock_folder"):  # no lock at all: the second writer goes on
            s.cases += 1
            s.wrong += 1
            continue
        fd = files.lock_folder(target)
        try:
            s.run(partial(files.lock_folder, target), always)
        finally:
            files.unlock_folder(fd)
    real_write, real_atomic = os.write, files.atomic_write

    def enospc(*args: Any, **kwargs: Any) -> Any:
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), "bench")

    for patch in ("append", "create", "report"):
        root = tmp / f"disk-{patch}"
        root.mkdir()
        try:
            module, name = {"append": (os, "write"), "create": (logs, "atomic_write")}.get(
                patch, (tables, "atomic_write")
            )
            setattr(module, name, enospc)
            s.cases += 1
            try:
                run = _a_run(root)
                tables.write_report([tables.load_run(run)], root / "rep")
            except OSError:
                pass
        finally:
            setattr(os, "write", real_write)  # noqa: B010
            setattr(logs, "atomic_write", real_atomic)  # noqa: B010
            setattr(tables, "atomic_write", real_atomic)  # noqa: B010
        left = [p for p in root.rglob(".*") if p.is_file() and not p.name.endswith(".lock")]
        s.outside += len(left)
        keys = s.run(partial(_resumed_keys, root))
        if not isinstance(keys, list) or len(keys) != 2 or len(set(keys)) != 2:
            s.wrong += 1  # the run cannot be resumed, or records an episode twice
    return s


def _resumed_keys(root: Path) -> list[str]:
    from chaingeo.evaluation.logs import RunLog

    run = _a_run(root, resume=True)
    return [str(r["key"]) for r in RunLog(run).records()]


# ---------------------------------------------------------------------------------------------
# Decoded video limits
# ---------------------------------------------------------------------------------------------


def video_limits(tmp: Path) -> Surface:
    """Raw H.264 and streamed MKV (no frame count in any header) under lowered limits: each
    must be refused while decoding, never read whole."""
    import subprocess

    from chaingeo.core import limits
    from chaingeo.worldmodel.judge_video import read_clip

    s = Surface("judge-video decoding")
    try:
        import imageio_ffmpeg
    except ImportError:
        return s
    saved = limits.MAX_VIDEO_TOTAL_PIXELS, limits.MAX_VIDEO_FRAMES
    try:
        for fmt, suffix in (("h264", ".h264"), ("matroska", ".mkv"), ("gif", ".gif")):
            out = tmp / f"clip{suffix}"
            cmd = [imageio_ffmpeg.get_ffmpeg_exe(), "-v", "error", "-f", "lavfi"]
            cmd += ["-i", "testsrc=s=160x120:r=30", "-frames:v", "120"]
            cmd += ([] if fmt == "gif" else ["-c:v", "libx264"]) + ["-f", fmt, "pipe:1"]
            out.write_bytes(subprocess.run(cmd, capture_output=True, check=True).stdout)
            for pixels, frames in ((160 * 120 * 20, 10_000), (10**12, 15)):
                setattr(limits, "MAX_VIDEO_TOTAL_PIXELS", pixels)  # noqa: B010
                setattr(limits, "MAX_VIDEO_FRAMES", frames)  # noqa: B010
                s.run(partial(read_clip, out), whole_clip)
    finally:
        setattr(limits, "MAX_VIDEO_TOTAL_PIXELS", saved[0])  # noqa: B010
        setattr(limits, "MAX_VIDEO_FRAMES", saved[1])  # noqa: B010
    return s


CLASSES: tuple[Callable[[Path], Surface], ...] = (
    trajectories,
    kernel_store,
    run_folders,
    xmpuzzles,
    identifiers,
    game_doors,
    writers,
    video_limits,
)


def surfaces() -> list[Surface]:
    """Every class, in a temporary folder of its own."""
    rows = []
    for cls in CLASSES:
        with tempfile.TemporaryDirectory(prefix="chain-bench-") as tmp:
            rows.append(cls(Path(tmp)))
    return rows


__all__ = ["CLASSES", "Surface", "surface_table", "surfaces"]
