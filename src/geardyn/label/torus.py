"""Torus or chaos: weighted Birkhoff averages of a series of Poincaré points.

On a smooth quasi-periodic orbit (an invariant torus with a Diophantine rotation), the time
average of a smooth observable f weighted by the bump w(t) = exp(-1 / (t (1 - t))),

    WB_N(f) = sum_n w(t_n) f(x_n) / sum_n w(t_n),   t_n = (n + 1) / (N + 1),  n = 0 .. N - 1,

converges to the space average faster than any power of N; on a chaotic orbit it converges only
like N^(-1/2), as a plain average does (Das, Saiki, Sander & Yorke, "Quantitative
quasiperiodicity", Nonlinearity 30 (2017) 4111; Das & Yorke, "Super convergence of ergodic averages
for quasiperiodic orbits", Nonlinearity 31 (2018) 491).  The measure used here is

    digits = -log10( max_j |WB_N(f_j)(x_0 .. x_N-1) - WB_N(f_j)(x_N .. x_2N-1)| / s_j )

over the components f_j of the observable, s_j the standard deviation of f_j over the 2N points
(dimensionless; components that do not vary are skipped).  The default observable is
:func:`moments`: z, z^2, z^3 of every standardised coordinate z (smooth; three moments instead of
one make a chance agreement of the two halves of a chaotic series rarer: the 99th percentile of
digits - log10 sqrt(N) on the Henon and logistic maps falls from 1.7 to 1.0).  :func:`torus_test`
turns it into a verdict with thresholds measured on cases whose answer is known (``docs/classify.md``, "Torus or
chaos: weighted Birkhoff averages").  :func:`rotation_number` gives the rotation number of the
points about a centre (e.g. the unstable period-1 point inside a torus) by a weighted Birkhoff
average of the angle increments.  :func:`extrapolated_digits` is the digits with a slowly decaying
transient removed (a geometric tail of the averages over successive windows, fitted and extrapolated):
a run still approaching its torus at a multiplier near 1 is then recognised long before the transient
has died out.

Periodic orbits: the weighted average of a periodic sequence also converges faster than any power
of N, so a period-n cycle scores as many digits as a torus (``DIGITS_MAX`` for a fixed point).  The
test cannot tell a cycle from a torus; the caller labels periodic points first.

The sums (coordinates, scaling, the weighted averages) run in compiled loops
(:mod:`geardyn.label._birkhoff`), in index order; ``tests/test_torus.py`` holds their statement in numpy
array operations as the oracle.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from geardyn import libm
from geardyn.label._birkhoff import averages, scaled, standardised

#: cap of :func:`birkhoff_digits`: agreement to the last bits of float64 (about 15.65 digits) is "exact".
DIGITS_MAX = -math.log10(np.finfo(float).eps)

#: default thresholds of :func:`torus_test` (measured; ``docs/classify.md``): torus when
#: digits >= TORUS_DIGITS, chaotic when digits < log10 sqrt(N) + CHAOS_DIGITS
TORUS_DIGITS = 6.0
CHAOS_DIGITS = 1.5
#: default smallest half-length N of :func:`torus_test`: with fewer points the verdict is "inconclusive"
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


def weighted_birkhoff(values: np.ndarray) -> np.ndarray:
    """Weighted Birkhoff average of ``values`` along axis 0 (bump weight over its length N).

    values: (N,) or (N, ...) samples f(x_0) .. f(x_N-1) in orbit order; returns the shape without
    axis 0 (a 0-d array for (N,)).  Any N >= 1 (N = 1: the sample itself).
    """
    v = np.asarray(values, dtype=float)
    if v.ndim == 0:
        raise ValueError("weighted_birkhoff needs a series (axis 0 = time), got a scalar")
    w = bump_weights(v.shape[0])
    flat = np.ascontiguousarray(v.reshape(v.shape[0], -1))
    return averages(flat, w, np.zeros(1, np.int64))[0].reshape(v.shape[1:])


def moments(points: np.ndarray) -> np.ndarray:
    """The default observable: (m, 3 d) values z, z^2, z^3 of the standardised coordinates
    z = (x - mean) / std of the (m, d) points (a coordinate whose spread is below 1e-12 of its
    magnitude, i.e. rounding, gives z = 0)."""
    z = coordinates(points)
    return np.concatenate([z, z * z, z * z * z], axis=1)


def coordinates(points: np.ndarray) -> np.ndarray:
    """The first moments of :func:`moments`: the (m, d) standardised coordinates z, the labeller's
    observable (the higher moments converge too slowly on the model's slowly attracting tori to decide
    within a few hundred periods, ``docs/classify.md``)."""
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
    f = np.asarray((moments if observable is None else observable)(points), dtype=float)
    if f.ndim == 1:
        f = f[:, None]
    if f.shape[0] != points.shape[0] or f.ndim != 2:
        raise ValueError(f"the observable must map (m, d) points to (m,) or (m, k) values, got {f.shape}")
    # centred: the averages then carry no rounding of a large mean
    g = scaled(np.ascontiguousarray(f), np.ascontiguousarray(points))
    return g if g.shape[1] else None


def _digits(diff: float) -> float:
    return DIGITS_MAX if diff <= 0.0 else min(-math.log10(diff), DIGITS_MAX)


def birkhoff_digits(points: np.ndarray, observable: Observable | None = None) -> float:
    """Convergence digits of the weighted Birkhoff average on a series of Poincaré points.

    points: (m,) or (m, d) in orbit order, m >= 4; the last 2N points are used, N = m // 2.
    observable: maps the (2N, d) points to (2N,) or (2N, k) values; default :func:`moments`.
    Returns -log10 of the largest difference between the averages of the first and the second N
    points, each component scaled by its standard deviation over the 2N points, capped at
    ``DIGITS_MAX``.  Components whose spread is below 1e-9 of the largest are skipped; when the
    points do not vary (a fixed point, to 1e-12 of their magnitude) the result is ``DIGITS_MAX``.
    Raises ValueError on rows with NaN or inf, or on fewer than 4 points.
    """
    p = _newest_pairs(points)
    f = _observed(p, observable)
    return DIGITS_MAX if f is None else _plain_digits(f)


def _newest_pairs(points: np.ndarray) -> np.ndarray:
    """The last 2N of the m points (N = m // 2) that the plain measure reads; at least 4 (two halves of 2)."""
    p = _as_points(points)
    m = p.shape[0]
    if m < 4:
        raise ValueError(f"birkhoff_digits needs at least 4 points (two halves of 2), got {m}")
    return p[m - 2 * (m // 2) :]


def _plain_digits(f: np.ndarray) -> float:
    """The digits of :func:`birkhoff_digits` from the observed values ``f`` of 2N points."""
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
    in :func:`birkhoff_digits`; q outside (0, 1): no tail, the digits of consecutive windows).  On a torus
    without a transient it scores like :func:`birkhoff_digits`; with a slow transient 2-11 digits more
    (``docs/classify.md``); on a chaotic series the averages scatter like N^(-1/2) and so do the limits
    (Henon, logistic: at most log10 sqrt(N) + 0.87 in 640 series, N = 50-8000).  Raises ValueError as
    :func:`birkhoff_digits`, or when the windows cannot be spaced by at least one point.
    """
    p = _as_points(points)
    _check_windows(p.shape[0], windows)
    f = _observed(p, observable)
    return DIGITS_MAX if f is None else _extrapolated(f, windows)


def torus_digits(
    points: np.ndarray, observable: Observable | None = None, windows: int = 6, extrapolate: bool = True
) -> tuple[float, float]:
    """:func:`birkhoff_digits` and :func:`extrapolated_digits` of the last 2N points (N = m // 2), the
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
    """Verdict of :func:`torus_test`: ``digits`` of :func:`birkhoff_digits`, ``n`` points per half,
    ``verdict`` one of "torus", "chaotic", "inconclusive"."""

    digits: float
    n: int
    verdict: str


def torus_test(
    points: np.ndarray,
    torus_digits: float = TORUS_DIGITS,
    chaos_digits: float = CHAOS_DIGITS,
    min_n: int = MIN_N,
    observable: Observable | None = None,
) -> TorusTest:
    """Torus or chaos from the weighted Birkhoff digits of the last 2N Poincaré points.

    "torus" when digits >= ``torus_digits``; "chaotic" when digits < log10 sqrt(N) + ``chaos_digits``
    (a chaotic average converges like N^(-1/2), i.e. to log10 sqrt(N) digits); otherwise, or with
    N < ``min_n``, "inconclusive".  The defaults (6, 1.5, N >= 2000) are measured in ``docs/classify.md``:
    a chaotic series scores log10 sqrt(N) + 0.0 +- 0.5 (99th percentile + 1.0, at most + 1.55 in 350
    Henon and logistic series, N = 250-16 000), the tori of the KHV model 6.7-8.8 digits at N = 2000
    once the transient has died out (5-7.5 at N = 500), the golden rotation 14.  The chaos threshold
    stays below 6 up to N = 10^9.  With N < 2000 slowly converging tori of the model scored below the
    chaos threshold; a torus within 1e-6 of a resonance p/q scores less as N grows until N passes the
    beat period 1 / |q rho - p|.  Periodic points are not told from tori (both converge fast): label
    them first.  A run still approaching its attractor drifts and scores like chaos: pass points after
    the transient, and read "chaotic" together with a positive Lyapunov exponent.
    """
    n = _as_points(points).shape[0] // 2
    return torus_verdict(birkhoff_digits(points, observable), n, torus_digits, chaos_digits, min_n)


def torus_verdict(
    digits: float,
    n: int,
    torus_digits: float = TORUS_DIGITS,
    chaos_digits: float = CHAOS_DIGITS,
    min_n: int = MIN_N,
) -> TorusTest:
    """The verdict of :func:`torus_test` for ``digits`` measured on 2 ``n`` points (any measure that scores
    log10 sqrt(N) on chaos, such as :func:`extrapolated_digits`)."""
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


def rotation_number(
    points: np.ndarray,
    center: np.ndarray | tuple[float, float],
    plane: tuple[int, int] = (0, 1),
) -> float:
    """Rotation number (turns per iterate, in [0, 1)) of the points about ``center`` in a coordinate plane.

    The angle of each point about ``center`` (coordinates ``plane`` of the points) is taken in
    turns; the increments between successive points are wrapped into the unit interval centred on
    their circular mean (so a steady rotation near 0 or 1/2 has no jumps of one turn) and averaged
    with the bump weight (:func:`weighted_birkhoff`).  Meaningful when the projected orbit winds
    around the centre (e.g. a torus born at a Neimark-Sacker point, about the unstable cycle).
    """
    p = _as_points(points)
    if p.shape[0] < 3:
        raise ValueError(f"rotation_number needs at least 3 points, got {p.shape[0]}")
    i, j = plane
    c = np.asarray(center, dtype=float)
    theta = np.arctan2(p[:, j] - c[1], p[:, i] - c[0]) / (2.0 * math.pi)
    inc = np.diff(theta)
    ang = 2.0 * math.pi * inc
    mean_dir = math.atan2(float(np.sin(ang).mean()), float(np.cos(ang).mean())) / (2.0 * math.pi)
    inc = mean_dir + (inc - mean_dir + 0.5) % 1.0 - 0.5
    return float(weighted_birkhoff(inc)) % 1.0


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
    (:func:`birkhoff_digits`) from super-polynomial to a low power of N.  On a torus of k loops (about a
    period-k orbit) every difference is k times those of one loop.

    The test: each point's nearest neighbour (Euclidean, in coordinates standardised by their standard
    deviations) is one of its two neighbours along the curve once the points are dense on it, so the index
    differences to the nearest neighbours take at most three values a < b < c with c = a + b (or two, or
    one).  It passes when they do and there are at least ``min_n`` points.  On a chaotic set the nearest
    neighbour comes from unrelated times and the differences take many values: no series of the Henon or
    logistic map nor a chaotic point of the model passes from 800 points on (``docs/classify.md``).  A
    periodic orbit or a torus locked to a long cycle may pass too: label periodic points first.  A curve
    that comes closer to itself than the spacing of the points fails (the test never passes a set that is
    not a curve; it may miss a curve).  Raises ValueError as :func:`birkhoff_digits` (NaN, inf, shape) or
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
