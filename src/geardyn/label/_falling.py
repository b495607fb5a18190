"""The compiled inner loop of :func:`geardyn.label.indicators.falling_return_distances` (private); it releases
the GIL, so the labeller's threads run on both cores."""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def falling(p: np.ndarray, max_n: int, factor: float) -> np.ndarray:
    """For n = 1 .. ``max_n`` (entry n - 1): whether the return distance d_n(k) = max_i |p_k+n,i - p_k,i|
    of the rows of ``p`` (finite) falls: mean of its last quarter < ``factor`` x mean of its first
    quarter (quarter: max(2, len // 4) values); True when there are fewer than n + 8 rows."""
    m = p.shape[0]
    out = np.ones(max_n, dtype=np.bool_)
    for n in range(1, min(max_n, m - 8) + 1):
        size = m - n
        q = max(2, size // 4)
        first = 0.0
        last = 0.0
        for k in range(size):
            if k >= q and k < size - q:
                continue
            d = 0.0
            for i in range(p.shape[1]):
                d = max(d, abs(p[k + n, i] - p[k, i]))
            if k < q:
                first += d
            if k >= size - q:
                last += d
        out[n - 1] = last / q < factor * (first / q)
    return out
