"""Signature reservations: atomic across processes, idempotent for their owner."""

from __future__ import annotations

import errno
import multiprocessing
import os
from pathlib import Path

import pytest

from chaingeo.generator.dedup import Reservation, SignatureStore

SIGS = [f"{i:040x}" for i in range(1, 31)]


def test_reserve_own_taken_release(tmp_path: Path) -> None:
    store = SignatureStore(tmp_path)
    sig = "ab" * 20
    assert store.owner(sig) is None
    assert store.reserve(sig, "level-a") is Reservation.NEW
    assert store.reserve(sig, "level-a") is Reservation.OWN
    assert store.reserve(sig, "level-b") is Reservation.TAKEN
    assert store.owner(sig) == "level-a"
    store.release(sig, "level-b")  # not the owner: nothing happens
    assert store.owner(sig) == "level-a"
    store.release(sig, "level-a")
    assert store.reserve(sig, "level-b") is Reservation.NEW
    assert store.signatures() == [sig]
    assert not [p for p in (tmp_path / "signatures").iterdir() if p.name.endswith(".tmp")]


@pytest.mark.parametrize("bad", ["../../etc/passwd", "ABCDEF12", "xyz", "", "ab" * 70])
def test_signatures_must_be_hex_digests(tmp_path: Path, bad: str) -> None:
    with pytest.raises(ValueError, match="not a lowercase hex digest"):
        SignatureStore(tmp_path).reserve(bad, "x")


def _contend(folder: str, worker: int) -> list[str]:
    store = SignatureStore(folder)
    return [s for s in SIGS if store.reserve(s, f"w{worker}") is Reservation.NEW]


def test_parallel_processes_never_reserve_one_signature_twice(tmp_path: Path) -> None:
    ctx = multiprocessing.get_context("spawn")
    with ctx.Pool(4) as pool:
        won = pool.starmap(_contend, [(str(tmp_path), w) for w in range(4)])
    winners = [s for batch in won for s in batch]
    assert sorted(winners) == sorted(SIGS)  # each signature exactly once
    store = SignatureStore(tmp_path)
    for w, batch in enumerate(won):
        for s in batch:
            assert store.owner(s) == f"w{w}"


def test_falls_back_to_exclusive_create_without_hard_links(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    def no_links(src: object, dst: object) -> None:
        raise OSError(errno.EPERM, "hard links not supported")

    monkeypatch.setattr(os, "link", no_links)
    store = SignatureStore(tmp_path)
    assert store.reserve("cd" * 20, "a") is Reservation.NEW
    assert store.reserve("cd" * 20, "b") is Reservation.TAKEN
    assert store.reserve("cd" * 20, "a") is Reservation.OWN
    assert store.owner("cd" * 20) == "a"
