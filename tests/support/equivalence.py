"""The one check every kernel-versus-reference test makes (docs/design: kernels and their
references): the kernel's result equals the reference's, exactly, field by field, with the same
dtypes and shapes for arrays, so a kernel that rounds, widens or reorders fails loudly."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np


def assert_same(reference: Any, kernel: Any, where: str = "result") -> None:
    """``kernel`` equals ``reference``: arrays by dtype, shape and every element; dataclasses,
    mappings and sequences part by part; anything else by ``==``. The message names the part."""
    if isinstance(reference, np.ndarray) or isinstance(kernel, np.ndarray):
        a, b = np.asarray(reference), np.asarray(kernel)
        assert a.dtype == b.dtype, f"{where}: dtype {b.dtype}, want {a.dtype}"
        assert a.shape == b.shape, f"{where}: shape {b.shape}, want {a.shape}"
        assert np.array_equal(a, b), f"{where}: {int((a != b).sum())} elements differ"
    elif dataclasses.is_dataclass(reference) and not isinstance(reference, type):
        assert type(kernel) is type(reference), f"{where}: {type(kernel)}, want {type(reference)}"
        for f in dataclasses.fields(reference):
            assert_same(getattr(reference, f.name), getattr(kernel, f.name), f"{where}.{f.name}")
    elif isinstance(reference, Mapping):
        assert isinstance(kernel, Mapping) and set(kernel) == set(reference), f"{where}: keys"
        for k in reference:
            assert_same(reference[k], kernel[k], f"{where}[{k!r}]")
    elif isinstance(reference, Sequence) and not isinstance(reference, str | bytes):
        assert isinstance(kernel, Sequence), f"{where}: {type(kernel)}, want a sequence"
        assert len(kernel) == len(reference), f"{where}: {len(kernel)} items, want {len(reference)}"
        for i, (r, k) in enumerate(zip(reference, kernel, strict=True)):
            assert_same(r, k, f"{where}[{i}]")
    else:
        assert kernel == reference, f"{where}: {kernel!r}, want {reference!r}"
