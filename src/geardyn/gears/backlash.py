"""The backlash (dead-zone) function of paper 1 Eq. (11)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray


def backlash(x: ArrayLike, b: float) -> NDArray[np.float64]:
    """f(X) = X - b for X > b, 0 for |X| <= b, X + b for X < -b; ``b`` is half the backlash (b >= 0); written as
    ``X - clip(X, -b, b)``, exact at the switching points and continuous."""
    if b < 0:
        raise ValueError(f"half backlash b = {b} must be >= 0")
    x = np.asarray(x, dtype=float)
    return x - np.clip(x, -b, b)
