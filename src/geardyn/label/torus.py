"""Torus or chaos: weighted Birkhoff averages of a series of Poincaré points (digits, extrapolated
digits, verdict) and the three-gap order test (the measure and its thresholds: ``docs/classify.md``)."""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from geardyn import libm
from geardyn.label._birkhoff import averages, scaled, standardised

#: cap of the digits: agreement to the last bits of float64 (about 15.65 digits) is "exact".
DIGITS_MAX = -math.log10(np.finfo(float).eps)

#: default thresholds of :func:`torus_verdict` (measured; ``docs/classify.md``): torus when
#: digits >= TORUS_DIGITS, chaotic when digits < log10 sqrt(N) + CHAOS_DIGITS
TORUS_DIGITS = 6.0
CHAOS_DIGITS = 1.5
#: default smallest half-length N of :func:`torus_verdict`: with fewer points the verdict is "inconclusive"
MIN_N = 2000
#: default fewest points of :func:`order_test` (measured, ``docs/classify.md``: from 800 points on no chaotic
#: series of the Henon and logistic maps nor of the model passes)
ORDER_MIN_N = 800

Observable = Callable[[np.ndarray], np.ndarray]


@functools.lru_cache(maxsize=256)
def bump_weights(n: int) -> np.ndarray:
    """The n normalised weights w(t_k) / sum w, w(t) = exp(-1 / (t (1 - t))), t_k = (k + 1) / (n + 1).

    ``exp`` is the C library's (:mod:`geardyn.libm`: numpy's differs with AVX-512), computed once per n
    (read-only, shared)."""
    if n < 1:
        raise ValueError(f"need at least one sample for a weighted average, got n = {n}")
    t = np.arange(1, n + 1, dtype=float) / (n + 1)
    w = libm.exp(-1.0 / (t * (1.0 - t)))
    out = w / w.sum()
    out.setflags(write=False)
    return out


def coordinates(points: np.ndarray) -> np.ndarray:
    """The default observable: the (m, d) standardised coordinates z = (x - mean) / std of the (m, d) points
    (a coordinate whose spread is below 1e-12 of its magnitude, i.e. rounding, gives z = 0).  Higher moments
    (z^2, z^3) converge too slowly on the model's slowly attracting tori to decide within a few hundred
    periods (``docs/classify.md``)."""
    p = np.asarray(points, dtype=float)
    if p.ndim == 1:
        p = p[:, None]
    return standardised(np.ascontiguousarray(p))


def _as_points(points: np.ndarray) -> np.ndarray:
    p = np.asarray(points, dtype=float)
    if p.ndim == 1:
        p = p[:, None]
    if p.ndim != 2:
        raise ValueError(f"points must be (m,) or (m, d), got shape {np.shape(points)}")
    bad = ~np.all(np.isfinite(p), axis=1)
    if bad.any():
        raise ValueError(
            f"points hold {int(bad.sum())} row(s) with NaN or inf (first at row {int(np.argmax(bad))}); "
            "pass only the finite Poincaré points of a run (a diverged run has no torus to test)"
        )
    return p


def _observed(points: np.ndarray, observable: Observable | None) -> np.ndarray | None:
    """The observable's values on the (m, d) points, centred and scaled by their standard deviations
    (components whose spread is below 1e-9 of the largest are dropped); None when the points do not vary
    (one point, to 1e-12 of their magnitude)."""
    f = np.asarray((coordinates if observable is None else observable)(points), dtype=float)
    if f.ndim == 1:
        f = f[:, None]
    if f.shape[0] != points.shape[0] or f.ndim != 2:
        raise ValueError(f"the observable must map (m, d) points to (m,) or (m, k) values, got {f.shape}")
    # centred: the averages then carry no rounding of a large mean
    g = scaled(np.ascontiguousarray(f), np.ascontiguousarray(points))
    return g if g.shape[1] else None


def _digits(diff: float) -> float:
    return DIGITS_MAX if diff <= 0.0 else min(-math.log10(diff), DIGITS_MAX)


def _newest_pairs(points: np.ndarray) -> np.ndarray:
    """The last 2N of the m points (N = m // 2) that the plain measure reads; at least 4 (two halves of 2)."""
    p = _as_points(points)
    m = p.shape[0]
    if m < 4:
        raise ValueError(f"the torus test needs at least 4 points (two halves of 2), got {m}")
    return p[m - 2 * (m // 2) :]


def _plain_digits(f: np.ndarray) -> float:
    """The plain digits (``docs/classify.md``) from the observed values ``f`` of 2N points."""
    n = f.shape[0] // 2
    a = averages(f, bump_weights(n), np.array([0, n], np.int64))
    return _digits(float(np.max(np.abs(a[0] - a[1]))))


def extrapolated_digits(points: np.ndarray, observable: Observable | None = None, windows: int = 6) -> float:
    """Convergence digits of the weighted Birkhoff averages with a slowly decaying geometric transient
    fitted over ``windows`` windows and extrapolated away; raises ValueError as :func:`torus_digits` or when
    the windows cannot be spaced (method and measurements: ``docs/classify.md``)."""
    p = _as_points(points)
    _check_windows(p.shape[0], windows)
    f = _observed(p, observable)
    return DIGITS_MAX if f is None else _extrapolated(f, windows)


def torus_digits(
    points: np.ndarray, observable: Observable | None = None, windows: int = 6, extrapolate: bool = True
) -> tuple[float, float]:
    """The plain digits (``docs/classify.md``) and :func:`extrapolated_digits` of the last 2N points (N = m // 2), the
    observable evaluated once for both (NaN for the second with ``extrapolate=False``).  On an even number
    of points each equals the function's own value, bit for bit; on an odd number the extrapolation reads
    the same 2N points as the plain test, not all m.  Raises ValueError as the two functions do."""
    p = _newest_pairs(points)
    if extrapolate:
        _check_windows(p.shape[0], windows)
    f = _observed(p, observable)
    if f is None:
        return DIGITS_MAX, DIGITS_MAX if extrapolate else math.nan
    return _plain_digits(f), _extrapolated(f, windows) if extrapolate else math.nan


def _check_windows(m: int, windows: int) -> None:
    if windows < 3:
        raise ValueError(f"extrapolated_digits needs at least 3 windows, got {windows}")
    if m // 2 < 2 or (m - m // 2) // (windows - 1) < 1:
        raise ValueError(f"extrapolated_digits needs at least {max(4, 2 * windows - 3)} points, got {m}")


def _extrapolated(f: np.ndarray, windows: int) -> float:
    """The digits of :func:`extrapolated_digits` from the observed values ``f`` of the m points."""
    m = f.shape[0]
    n = m // 2
    step = (m - n) // (windows - 1)
    d = np.diff(averages(f, bump_weights(n), step * np.arange(windows, dtype=np.int64)), axis=0)
    den = float(np.sum(d[:-1] * d[:-1]))
    q = float(np.sum(d[1:] * d[:-1])) / den if den > 0.0 else 0.0
    q = q if 0.0 < q < 1.0 else 0.0
    return _digits(float(np.max(np.abs(d[1:] - q * d[:-1]))) / (1.0 - q))


@dataclass(frozen=True)
class TorusTest:
    """Verdict of :func:`torus_verdict`: the ``digits`` measured, ``n`` points per half,
    ``verdict`` one of "torus", "chaotic", "inconclusive"."""

    digits: float
    n: int
    verdict: str


def torus_verdict(
    digits: float,
    n: int,
    torus_digits: float = TORUS_DIGITS,
    chaos_digits: float = CHAOS_DIGITS,
    min_n: int = MIN_N,
) -> TorusTest:
    """Torus or chaos from ``digits`` measured on 2 ``n`` points: "torus" at >= ``torus_digits``, "chaotic"
    below log10 sqrt(N) + ``chaos_digits``, else (or with N < ``min_n``) "inconclusive" (thresholds:
    ``docs/classify.md``)."""
    if n >= min_n and not 0.5 * math.log10(n) + chaos_digits <= torus_digits:
        raise ValueError(
            f"the chaos threshold log10 sqrt(N) + {chaos_digits} exceeds torus_digits = {torus_digits} at N = {n}"
        )
    if n >= min_n and digits >= torus_digits:
        verdict = "torus"
    elif n >= min_n and digits < 0.5 * math.log10(n) + chaos_digits:
        verdict = "chaotic"
    else:
        verdict = "inconclusive"
    return TorusTest(digits=float(digits), n=int(n), verdict=verdict)


@dataclass(frozen=True)
class OrderTest:
    """Verdict of :func:`order_test`: ``passed`` when the points are visited in the order of a circle
    rotation; ``gaps`` the distinct index differences between each point and its nearest neighbour
    (ascending); ``n`` the number of points."""

    passed: bool
    gaps: tuple[int, ...]
    n: int


def order_test(points: np.ndarray, min_n: int = ORDER_MIN_N) -> OrderTest:
    """Torus or not from the order in which a series of Poincaré points visits its set: the three-gap test
    (nearest-neighbour index differences take at most three values a < b < c = a + b), with at least
    ``min_n`` points; raises ValueError as :func:`torus_digits` or on fewer than 3 points (``docs/classify.md``)."""
    p = _as_points(points)
    m = p.shape[0]
    if m < 3:
        raise ValueError(f"order_test needs at least 3 points, got {m}")
    s = p.std(axis=0)
    z = (p - p.mean(axis=0)) / np.where(s > 0.0, s, 1.0)
    from scipy.spatial import cKDTree  # noqa: PLC0415 - 0.1 s to import: only records that reach the test

    _, nearest = cKDTree(z).query(z, k=2)
    gaps = np.unique(np.abs(nearest[:, 1] - np.arange(m)))
    a = gaps.tolist()
    rotation = len(a) <= 2 or (len(a) == 3 and a[2] == a[0] + a[1])
    return OrderTest(passed=bool(rotation and m >= min_n), gaps=tuple(a), n=m)
