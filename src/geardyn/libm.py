"""Elementary functions whose results do not depend on the CPU: the C library's, element by element.

numpy computes ``tan``, ``arcsin``, ``arccos``, ``arctan``, ``arctan2``, ``sinh``, ``cosh``, ``exp``,
``expm1``, ``log``, ``log1p``, ``log10``, ``log2``, ``cbrt`` and ``power`` with Intel's SVML kernels when
the CPU has AVX-512 (numpy's ``AVX512_SKX`` / ``X86_V4`` dispatch), and with the C library (glibc libm)
otherwise; the two differ in the last bit for a few per cent of arguments (``tanh`` has a third,
AVX2 path).  Measured on this project's machine: ``np.exp`` differs from ``math.exp`` for 4.6 % of
uniform arguments in [-3, 3] with AVX-512, for none with AVX-512 disabled (``docs/reproducibility.md``).
A last-bit difference in a gear's geometry or mesh stiffness moves a chaotic orbit to another one, so
the functions on the paths that decide results (geometry, stiffness, coefficients) come from here:
Python's :mod:`math`, which calls the C library on every CPU, applied element by element.  ``sin``,
``cos`` and ``sqrt`` need no replacement (numpy's are the C library's, or correctly rounded, on every
x86-64 CPU) but are here too, so one module serves a whole formula.

Every function takes a float, a numpy scalar or an array (any shape) and returns a float for a scalar
argument and a float64 array otherwise.  They are slower than numpy's (about 0.1 microseconds per
element), which is nothing on these paths (at most thousands of elements per call).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
import numpy.typing as npt

FloatArray = npt.NDArray[np.float64]


def _lift1(f: Callable[[float], float]) -> Callable[[Any], Any]:
    uf = np.frompyfunc(f, 1, 1)

    def g(x: Any) -> Any:
        if np.ndim(x) == 0:
            return f(float(x))
        with np.errstate(all="ignore"):  # libm's own status flags: the results above say it (NaN, inf)
            return np.asarray(uf(np.asarray(x, dtype=np.float64)), dtype=np.float64)

    g.__name__ = f.__name__
    g.__doc__ = f"``math.{f.__name__}`` element by element (C library, the same on every CPU)."
    return g


def _lift2(f: Callable[[float, float], float]) -> Callable[[Any, Any], Any]:
    uf = np.frompyfunc(f, 2, 1)

    def g(x: Any, y: Any) -> Any:
        if np.ndim(x) == 0 and np.ndim(y) == 0:
            return f(float(x), float(y))
        with np.errstate(all="ignore"):
            return np.asarray(uf(np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)), dtype=np.float64)

    g.__name__ = f.__name__
    g.__doc__ = f"``math.{f.__name__}`` element by element with broadcasting (C library, the same on every CPU)."
    return g


def _safe(f: Callable[..., float], pole: float | None = None) -> Callable[..., float]:
    """``f`` returning what numpy returns where :mod:`math` raises: -inf at the pole of a logarithm
    (``pole``), inf on overflow or for ``pow(0, y < 0)``, NaN outside the domain."""

    def g(*args: float) -> float:
        try:
            return f(*args)
        except ValueError:
            if pole is not None and args[0] == pole:
                return -math.inf
            if f is math.pow and args[0] == 0.0 and args[1] < 0:
                return math.inf
            return math.nan
        except OverflowError:
            return math.inf

    g.__name__ = f.__name__
    return g


sin = _lift1(math.sin)
cos = _lift1(math.cos)
tan = _lift1(math.tan)
arcsin = _lift1(_safe(math.asin))
arccos = _lift1(_safe(math.acos))
arctan = _lift1(math.atan)
arctan2 = _lift2(math.atan2)
sinh = _lift1(_safe(math.sinh))
cosh = _lift1(_safe(math.cosh))
tanh = _lift1(math.tanh)
exp = _lift1(_safe(math.exp))
expm1 = _lift1(_safe(math.expm1))
log = _lift1(_safe(math.log, 0.0))
log1p = _lift1(_safe(math.log1p, -1.0))
log10 = _lift1(_safe(math.log10, 0.0))
log2 = _lift1(_safe(math.log2, 0.0))
cbrt = _lift1(math.cbrt)
power = _lift2(_safe(math.pow))

for _name, _np in (("arcsin", "asin"), ("arccos", "acos"), ("arctan", "atan"), ("arctan2", "atan2"), ("power", "pow")):
    globals()[
        _name
    ].__doc__ = f"``math.{_np}`` element by element (C library, the same on every CPU); NaN outside the domain."
