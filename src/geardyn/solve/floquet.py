"""Floquet multipliers read: which are complex, and how an orbit's leading multiplier leaves the unit
circle (the bifurcation it meets).  The Floquet analysis of the linear (b = 0) model by DOP853, an
independent check of the shooting's multipliers, is in ``tests/_oracle.py``.
"""

from __future__ import annotations

import numpy as np

from geardyn import libm

#: A multiplier is complex when its imaginary part exceeds this fraction of its modulus (a real multiplier
#: computed from a real monodromy matrix can carry a rounding-level imaginary part).
COMPLEX_RTOL = 1e-8


def is_complex(mu: np.ndarray) -> np.ndarray:
    """Which of the multipliers ``mu`` are complex (:data:`COMPLEX_RTOL`), element by element."""
    mu = np.asarray(mu)
    return np.abs(mu.imag) > COMPLEX_RTOL * np.maximum(libm.cabs(mu), libm.TINY)


def bifurcation_type(multipliers: np.ndarray) -> str:
    """How the leading multiplier of an orbit leaves (or reaches) the unit circle: ``neimark_sacker`` (a
    complex pair), ``period_doubling`` (real, through -1) or ``fold`` (real, through +1)."""
    mu = np.asarray(multipliers)[:1]
    if bool(is_complex(mu)[0]):
        return "neimark_sacker"
    return "period_doubling" if mu[0].real < 0 else "fold"
