"""Torus or chaos: weighted Birkhoff averages of a series of Poincaré points, and the three-gap order test.

On a smooth quasi-periodic orbit (an invariant torus with a Diophantine rotation), the time
average of a smooth observable f weighted by the bump w(t) = exp(-1 / (t (1 - t))),

    WB_N(f) = sum_n w(t_n) f(x_n) / sum_n w(t_n),   t_n = (n + 1) / (N + 1),  n = 0 .. N - 1,

converges to the space average faster than any power of N; on a chaotic orbit it converges only
like N^(-1/2), as a plain average does (Das, Saiki, Sander & Yorke, "Quantitative
quasiperiodicity", Nonlinearity 30 (2017) 4111; Das & Yorke, "Super convergence of ergodic averages
for quasiperiodic orbits", Nonlinearity 31 (2018) 491).  The plain measure is

    digits = -log10( max_j |WB_N(f_j)(x_0 .. x_N-1) - WB_N(f_j)(x_N .. x_2N-1)| / s_j )

over the components f_j of the observable, s_j the standard deviation of f_j over the 2N points
(dimensionless; components that do not vary are skipped).  The labeller's observable is
:func:`coordinates`.  :func:`torus_verdict` turns the digits into a verdict with thresholds measured on
cases whose answer is known (``docs/classify.md``, "Torus or chaos: weighted Birkhoff averages").
:func:`extrapolated_digits` is the digits with a slowly decaying transient removed (a geometric tail of
the averages over successive windows, fitted and extrapolated): a run still approaching its torus at a
multiplier near 1 is then recognised long before the transient has died out.  :func:`torus_digits`
gives both from one evaluation of the observable.

Periodic orbits: the weighted average of a periodic sequence also converges faster than any power
of N, so a period-n cycle scores as many digits as a torus (``DIGITS_MAX`` for a fixed point).  The
test cannot tell a cycle from a torus; the caller labels periodic points first.

The sums (coordinates, scaling, the weighted averages) run in compiled loops
(:mod:`geardyn.label._birkhoff`), in index order; ``tests/test_torus.py`` holds their statement in numpy
array operations as the oracle, and ``tests/_oracle.py`` the single-purpose forms of the measure (weighted
average, plain digits, verdict, rotation number) that the tests check the method with.
"""

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


def bump_weights(n: int) -> np.ndarray:
    """The n normalised weights w(t_k) / sum w, w(t) = exp(-1 / (t (1 - t))), t_k = (k + 1) / (n + 1).

    ``exp`` is the C library's (:mod:`geardyn.libm`: numpy's differs with AVX-512), computed once per n
    (read-only, shared)."""
    if n < 1:
        raise ValueError(f"need at least one sample for a weighted average, got n = {n}")
    return _bump_weights(int(n))


@functools.lru_cache(maxsize=256)
def _bump_weights(n: int) -> np.ndarray:
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
    """The plain digits (module docstring) from the observed values ``f`` of 2N points."""
    n = f.shape[0] // 2
    a = averages(f, bump_weights(n), np.array([0, n], np.int64))
    return _digits(float(np.max(np.abs(a[0] - a[1]))))


def extrapolated_digits(points: np.ndarray, observable: Observable | None = None, windows: int = 6) -> float:
    """Convergence digits of the weighted Birkhoff averages with a slowly decaying transient removed.

    A run that approaches a torus with a slow real multiplier r (the transverse attraction just past a
    Neimark-Sacker point, r = 0.998-0.9999 per period) carries a deviation c r^n whose weighted average
    over a window starting at n = k is A(k) = A + C r^k (the oscillating part of the deviation averages
    out like the torus itself).  The bump-weighted averages A(k) over ``windows`` windows of N = m // 2
    points, starting at k = 0, s, 2s, ... (s = (m - N) // (windows - 1)), are fitted with one ratio q for
    all components and steps (least squares of D_{i+1} = q D_i, D_i = A(k_{i+1}) - A(k_i)); the limit of the
    geometric tail is A(k_last) + D_last q / (1 - q) from every window triple, and the measure is

        digits = -log10( max_{i, j} |D_{i+1, j} - q D_{i, j}| / (1 - q) ),

    the largest disagreement of the extrapolated limits (components scaled by their standard deviation as
    in the plain measure; q outside (0, 1): no tail, the digits of consecutive windows).  On a torus
    without a transient it scores like the plain measure; with a slow transient 2-11 digits more
    (``docs/classify.md``); on a chaotic series the averages scatter like N^(-1/2) and so do the limits
    (Henon, logistic: at most log10 sqrt(N) + 0.87 in 640 series, N = 50-8000).  Raises ValueError as
    the plain measure (:func:`torus_digits`), or when the windows cannot be spaced by at least one point.
    """
    p = _as_points(points)
    _check_windows(p.shape[0], windows)
    f = _observed(p, observable)
    return DIGITS_MAX if f is None else _extrapolated(f, windows)


def torus_digits(
    points: np.ndarray, observable: Observable | None = None, windows: int = 6, extrapolate: bool = True
) -> tuple[float, float]:
    """The plain digits (module docstring) and :func:`extrapolated_digits` of the last 2N points (N = m // 2), the
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
    """Torus or chaos from ``digits`` measured on 2 ``n`` points (the plain measure, or any measure that
    scores log10 sqrt(N) on chaos, such as :func:`extrapolated_digits`).

    "torus" when digits >= ``torus_digits``; "chaotic" when digits < log10 sqrt(N) + ``chaos_digits``
    (a chaotic average converges like N^(-1/2), i.e. to log10 sqrt(N) digits); otherwise, or with
    N < ``min_n``, "inconclusive".  The defaults (6, 1.5, N >= 2000) are measured in ``docs/classify.md``
    with the observable z, z^2, z^3: a chaotic series scores log10 sqrt(N) + 0.0 +- 0.5 (99th percentile
    + 1.0, at most + 1.55 in 350 Henon and logistic series, N = 250-16 000), the tori of the KHV model
    6.7-8.8 digits at N = 2000 once the transient has died out (5-7.5 at N = 500), the golden rotation 14.
    A torus within 1e-6 of a resonance p/q scores less as N grows until N passes the beat period
    1 / |q rho - p|.  A run still approaching its attractor drifts and scores like chaos: read "chaotic"
    together with a positive Lyapunov exponent."""
    if n >= min_n and not 0.5 * math.log10(n) + chaos_digits <= torus_digits:
        raise ValueError(
            f"the chaos threshold log10 sqrt(N) + {chaos_digits} exceeds torus_digits = {torus_digits} at N = {n}"
        )
    if n < min_n:
        verdict = "inconclusive"
    elif digits >= torus_digits:
        verdict = "torus"
    elif digits < 0.5 * math.log10(n) + chaos_digits:
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
    """Torus or not from the order in which a series of Poincaré points visits its set: the three-gap test.

    The N points n rho mod 1 of a rotation of the circle (rho irrational) split it into gaps, and the index
    differences between neighbours on the circle take at most three values, the largest the sum of the
    other two (the three-distance theorem: Sós 1958, Świerczkowski 1959).  A circle homeomorphism with
    an irrational rotation number keeps the cyclic order of its orbit as the rotation does (Poincaré), so
    the same holds for the orbit of any map on an invariant closed curve, smooth or not: the corners
    where the gears lose contact change nothing, while they slow the weighted Birkhoff averages
    (module docstring) from super-polynomial to a low power of N.  On a torus of k loops (about a
    period-k orbit) every difference is k times those of one loop.

    The test: each point's nearest neighbour (Euclidean, in coordinates standardised by their standard
    deviations) is one of its two neighbours along the curve once the points are dense on it, so the index
    differences to the nearest neighbours take at most three values a < b < c with c = a + b (or two, or
    one).  It passes when they do and there are at least ``min_n`` points.  On a chaotic set the nearest
    neighbour comes from unrelated times and the differences take many values: no series of the Henon or
    logistic map nor a chaotic point of the model passes from 800 points on (``docs/classify.md``).  A
    periodic orbit or a torus locked to a long cycle may pass too: label periodic points first.  A curve
    that comes closer to itself than the spacing of the points fails (the test never passes a set that is
    not a curve; it may miss a curve).  Raises ValueError as :func:`torus_digits` (NaN, inf, shape) or
    on fewer than 3 points.
    """
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
