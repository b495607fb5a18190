"""Elementary functions whose results do not depend on the CPU (the C library's, element by element) and the
process environment that makes the C library and OpenBLAS round the same on every x86-64 CPU (why and how, with
the measurements: ``docs/reproducibility.md``, sections 1, 2 and 5)."""

from __future__ import annotations

import ctypes
import glob
import importlib.util
import math
import os
import sys
from collections.abc import Callable, Mapping
from typing import Any, overload

import numpy as np
import numpy.typing as npt

#: A floor for a divisor that may be zero: below any scale that occurs (states, multipliers, coefficients), above
#: the smallest normal double (2.2e-308).
TINY = 1e-300

FloatArray = npt.NDArray[np.float64]


# A lifted function takes and returns a scalar or an array, as numpy's ufuncs do (typed Any in numpy's stubs too).
def _lift(f: Callable[..., float], nin: int = 1, domain: bool = False) -> Callable[..., Any]:
    """``f`` (of ``nin`` floats) element by element with broadcasting; a float for scalar arguments."""
    uf = np.frompyfunc(f, nin, 1)

    def g(*args: Any) -> Any:
        if all(np.ndim(x) == 0 for x in args):
            return f(*(float(x) for x in args))
        with np.errstate(all="ignore"):  # libm's own status flags: the results above say it (NaN, inf)
            return np.asarray(uf(*(np.asarray(x, dtype=np.float64) for x in args)), dtype=np.float64)

    g.__name__ = f.__name__
    g.__doc__ = f"``math.{f.__name__}`` element by element (C library, the same on every CPU)" + (
        "; NaN outside the domain." if domain else "."
    )
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


@overload
def cabs(z: complex) -> float: ...
@overload
def cabs(z: np.ndarray) -> np.ndarray: ...
def cabs(z: complex | np.ndarray) -> float | np.ndarray:
    """The modulus of complex numbers (far from overflow), the same bits on every CPU: sqrt(re^2 + im^2), each step
    correctly rounded (``np.abs`` and ``np.hypot`` run dispatched AVX-512 kernels that differ in the last bit for a
    few per cent of values); a float for a scalar argument."""
    zz = np.asarray(z)
    re, im = np.asarray(zz.real, dtype=np.float64), np.asarray(zz.imag, dtype=np.float64)
    out = np.sqrt(re * re + im * im)
    return float(out) if np.ndim(z) == 0 else out


def cmul(a: npt.ArrayLike, b: npt.ArrayLike) -> np.ndarray:
    """The product of complex arrays, the same bits on every CPU: (ar br - ai bi) + i (ar bi + ai br), each
    real product and sum rounded on its own.  (numpy's complex multiply runs an AVX-512 kernel with fused
    multiply-adds on CPUs that have it: 43 % of products differ from its baseline path in the last bit.)"""
    a, b = np.asarray(a, dtype=complex), np.asarray(b, dtype=complex)
    return (a.real * b.real - a.imag * b.imag) + 1j * (a.real * b.imag + a.imag * b.real)


sin = _lift(math.sin)
cos = _lift(math.cos)
tan = _lift(math.tan)
arcsin = _lift(_safe(math.asin), domain=True)
arccos = _lift(_safe(math.acos), domain=True)
arctan = _lift(math.atan, domain=True)
arctan2 = _lift(math.atan2, 2, domain=True)
exp = _lift(_safe(math.exp))
log = _lift(_safe(math.log, 0.0))
log10 = _lift(_safe(math.log10, 0.0))
cbrt = _lift(math.cbrt)
power = _lift(_safe(math.pow), 2, domain=True)


#: The features hidden from glibc's dispatch of its math functions (names of glibc >= 2.33, and of older
#: glibc; unknown names are ignored).  Hiding FMA changes nothing else: glibc's string functions do not
#: dispatch on it.
HWCAPS = ("-FMA", "-FMA4", "-FMA_Usable", "-FMA4_Usable")

#: The variant every x86-64 CPU can run: glibc's math functions without fused multiply-adds.
CANONICAL = "glibc-plain"

#: The OpenBLAS kernels (bundled with numpy and scipy) every process computes with, whatever the environment
#: says: SSE4.2 without fused multiply-adds, on every CPU of numpy's baseline (x86-64-v2); kernels picked per CPU
#: round the 6 x 6 solves differently, and a followed torus ends elsewhere (``docs/reproducibility.md``).
BLAS_CORETYPE = "Nehalem"

#: The process environment that makes results the same on every x86-64 CPU (:func:`canonical_environ`): OpenBLAS's
#: kernels, and one thread (a sum split between threads depends on the cores; the jobs are parallel already).
BLAS_ENVIRON = {"OPENBLAS_CORETYPE": BLAS_CORETYPE, "OPENBLAS_NUM_THREADS": "1"}

#: sin(x) at this x rounds differently in glibc's FMA and plain builds (found among 100 001 random arguments).
_PROBE = 0.1277399286858092
_PROBE_VALUES = {
    float.fromhex("0x1.04e685e7a7fb5p-3"): CANONICAL,
    float.fromhex("0x1.04e685e7a7fb4p-3"): "glibc-fma",
}

#: Set in the environment of a process that :func:`restart_canonical` restarted (no second restart).
_RESTARTED = "GEARDYN_LIBM_RESTARTED"


def variant() -> str:
    """The build of the C library's math functions that this process runs: :data:`CANONICAL` (plain, the
    same on every x86-64 CPU), ``"glibc-fma"`` (fused multiply-adds: other last bits), or ``"other"`` (a
    C library or CPU whose ``sin`` gives neither value, e.g. musl, macOS or ARM; not claimed to agree)."""
    return _PROBE_VALUES.get(math.sin(_PROBE), "other")


def canonical_environ(environ: Mapping[str, str]) -> dict[str, str]:
    """``environ`` with :data:`HWCAPS` added to ``GLIBC_TUNABLES`` (other tunables and hwcaps entries kept)
    and :data:`BLAS_ENVIRON` set (replacing what the environment said)."""
    env = dict(environ)
    env.update(BLAS_ENVIRON)
    parts = [p for p in env.get("GLIBC_TUNABLES", "").split(":") if p]
    for i, part in enumerate(parts):
        if part.startswith("glibc.cpu.hwcaps="):
            have = part.split("=", 1)[1].split(",")
            parts[i] = "glibc.cpu.hwcaps=" + ",".join([h for h in have if h] + [h for h in HWCAPS if h not in have])
            break
    else:
        parts.append("glibc.cpu.hwcaps=" + ",".join(HWCAPS))
    env["GLIBC_TUNABLES"] = ":".join(parts)
    return env


def blas_core(package: str = "numpy") -> str:
    """The kernel set ("core", e.g. ``Nehalem``) of the OpenBLAS bundled with ``package`` (``numpy`` or ``scipy``),
    or ``unknown``; opens the library, not the package (the package's own handle where it loaded it already)."""
    spec = importlib.util.find_spec(package)
    if spec is None or not spec.submodule_search_locations:
        return "unknown"
    where = next(iter(spec.submodule_search_locations))
    libs = glob.glob(os.path.join(where, "..", f"{package}.libs", "libscipy_openblas*.so"))
    symbol = "scipy_openblas_get_corename64_" if package == "numpy" else "scipy_openblas_get_corename"
    try:
        lib = ctypes.CDLL(libs[0])  # already loaded by the package: the same handle
        fn = getattr(lib, symbol)
        fn.restype = ctypes.c_char_p
        return fn().decode()
    except (IndexError, OSError, AttributeError):
        return "unknown"


def canonical_process() -> bool:
    """Whether this process computes the canonical bits: glibc's plain math functions (or a C library that is
    not glibc on x86-64, about which nothing is claimed) and OpenBLAS's :data:`BLAS_CORETYPE` kernels in
    numpy and, if it was imported (it loads its own OpenBLAS), scipy (or another BLAS)."""
    blas = [blas_core("numpy")] + ([blas_core("scipy")] if "scipy" in sys.modules else [])
    return variant() != "glibc-fma" and all(core in (BLAS_CORETYPE, "unknown") for core in blas)


def needs_restart() -> bool:
    """Whether :func:`restart_canonical` would restart this process: it is not :func:`canonical_process` and
    was not restarted already."""
    return not canonical_process() and not os.environ.get(_RESTARTED)


def restart_canonical() -> None:
    """Restart this process (same interpreter and command line) with :func:`canonical_environ` when
    :func:`needs_restart`, else return; for entry points only (open files stay open, output buffered in Python
    is lost: flush first)."""
    if not needs_restart():
        return
    env = canonical_environ(os.environ)
    env[_RESTARTED] = "1"
    sys.stdout.flush()
    sys.stderr.flush()
    os.execve(sys.executable, list(sys.orig_argv), env)
