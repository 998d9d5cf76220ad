"""The NumPy array types every layer's kernels and wrappers annotate with, defined once.

Kernels take flat arrays of fixed dtypes (design notes: kernels and their references); these
names say which, in signatures short enough to read.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

I16 = npt.NDArray[np.int16]
I32 = npt.NDArray[np.int32]
I64 = npt.NDArray[np.int64]
U8 = npt.NDArray[np.uint8]
U64 = npt.NDArray[np.uint64]
F64 = npt.NDArray[np.float64]
Bools = npt.NDArray[np.bool_]
