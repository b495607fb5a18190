"""Labels for steady motions: period-n, quasi-periodic, chaotic, diverged, undetermined.

A sequence of Poincaré points p_0, p_1, ... (one per mesh period) is period-n when
p_{k+n} = p_k for all k, to a tolerance scaled to the attractor size and kept above the
integration error.  The smallest such n (up to ``max_n``) is the period.

Points that are not periodic are told apart by the largest Lyapunov exponent (tangent vector
integrated alongside the orbit by :func:`geardyn.solve.simulate`), cross-checked by the 0-1 test for chaos
(Gottwald & Melbourne 2009, correlation method, on the stroboscopic samples) and by the spectral
flatness of the stroboscopic samples (discrete lines vs broadband).  :func:`classify_point` gives
the indicators; the labeller (:mod:`geardyn.label`) integrates the points and decides their labels.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from geardyn._indicators import (
    correlations,  # compiled; releases the GIL
    falling,
)
from geardyn.config import settings_from
from geardyn.solve.simulate import strict_period as rule3

#: Label codes stored in cubes (``flag_values``/``flag_meanings``); n >= 1 is period-n.
#: ``not_periodic`` is what the Poincaré test alone says (QP or chaos, unresolved).
LABELS = {"long_period": -5, "chaotic": -4, "quasi_periodic": -3, "diverged": -2, "undetermined": -1, "not_periodic": 0}

#: values of ``Classification.settled`` (cube variable ``settled``)
SETTLED, POSSIBLE_TRANSIENT = 1, 2


def _return_distances(p: np.ndarray, n: int) -> np.ndarray:
    """max over states of |p_{k+n} - p_k| for each k."""
    return np.max(np.abs(p[n:] - p[:-n]), axis=1)


def falling_return_distances(poincare: np.ndarray, max_n: int, factor: float = 0.95) -> np.ndarray:
    """For n = 1 .. ``max_n`` (boolean array, entry n - 1): whether the return distance
    d_n(k) = max_i |p_k+n,i - p_k,i| of the Poincare points (rows with NaN left out) falls over the
    record: mean of its last quarter < ``factor`` x mean of its first quarter (a quarter: max(2, len // 4)
    values).  True when there are fewer than n + 8 points (too short to tell).  Compiled."""

    p = np.asarray(poincare, dtype=float)
    return falling(np.ascontiguousarray(p[np.all(np.isfinite(p), axis=1)]), max_n, factor)


def bands(values: np.ndarray, labels: np.ndarray) -> list[tuple[float, float, int]]:
    """Runs of equal labels along a sweep as (first value, last value, label)."""
    out: list[tuple[float, float, int]] = []
    start = 0
    for i in range(1, len(labels) + 1):
        if i == len(labels) or labels[i] != labels[start]:
            out.append((float(values[start]), float(values[i - 1]), int(labels[start])))
            start = i
    return out


def label_name(n: int) -> str:
    if n == LABELS["diverged"]:
        return "diverged"
    if n == LABELS["undetermined"]:
        return "undetermined"
    if n == LABELS["chaotic"]:
        return "chaotic"
    if n == LABELS["quasi_periodic"]:
        return "quasi-periodic"
    if n == LABELS["long_period"]:
        return "long period (a phase-locked torus)"
    if n == 0:
        return "not periodic (QP or chaos)"
    return f"P{n}"


def short_name(n: int) -> str:
    """Compact label: P1, P5, QP, chaos, div, undet."""
    return {
        LABELS["diverged"]: "div",
        LABELS["undetermined"]: "undet",
        LABELS["chaotic"]: "chaos",
        LABELS["long_period"]: "Plong",
        LABELS["quasi_periodic"]: "QP",
        0: "NP",
    }.get(int(n), f"P{int(n)}")


def flag_attrs(max_n: int = 12) -> dict:
    """CF ``flag_values``/``flag_meanings`` of the label codes (period-n for n = 1..max_n; ``long_period``: a
    certified periodic orbit of a period above max_n, stored in the variable ``period``)."""
    names = ("long_period", "chaotic", "quasi_periodic", "diverged", "undetermined", "not_periodic")
    values = [LABELS[k] for k in names]
    meanings = list(names)
    values += list(range(1, max_n + 1))
    meanings += [f"period_{n}" for n in range(1, max_n + 1)]
    return {"flag_values": np.array(values, np.int16), "flag_meanings": " ".join(meanings)}


# ----------------------------------------------------------------------------------------
# indicators
# ----------------------------------------------------------------------------------------


def lyapunov_estimate(
    growth: np.ndarray, period: float, skip: int | None = None, blocks: int = 8
) -> tuple[float, float]:
    """Largest Lyapunov exponent (per unit dimensionless time) and its uncertainty.

    ``growth[k]``: log growth of the renormalised tangent vector over mesh period k.  The first
    ``skip`` periods (default max(5, 10 %)) are left out while the vector aligns with the most
    unstable direction.  Uncertainty: the larger of the batch-means standard error (``blocks``
    contiguous blocks) and half the difference between the estimates of the two halves (the
    convergence of the running estimate).  (inf, 0) when the growth is infinite (divergence).
    """
    g = np.asarray(growth, dtype=float)
    if g.size == 0 or not np.all(np.isfinite(g)):
        return (float("nan"), float("nan")) if g.size == 0 else (float("inf"), 0.0)
    skip = max(5, g.size // 10) if skip is None else skip
    g = g[skip:] if g.size > skip + 4 else g
    lam = float(g.mean()) / period
    nb = max(2, min(blocks, g.size // 4))
    means = np.array([b.mean() for b in np.array_split(g, nb)])
    se = float(means.std(ddof=1)) / np.sqrt(nb) / period
    half = g.size // 2
    drift = abs(float(g[:half].mean()) - float(g[half:].mean())) / period if half > 0 else 0.0
    return lam, max(se, 0.5 * drift)


def zero_one_test(phi: np.ndarray, n_c: int = 32, seed: int = 1) -> float:
    """K of the 0-1 test for chaos (Gottwald & Melbourne, SIAM J. Appl. Dyn. Syst. 8 (2009) 129,
    correlation method, mean removed): ~0 for regular motion, ~1 for chaos.

    ``phi``: one observable at stroboscopic times (e.g. X_VH at the Poincaré section).  K is the
    median over ``n_c`` fixed frequencies c in (pi/5, 4 pi/5) (fixed seed: reproducible) of the
    correlation of the mean-square displacement D_c(n), n <= N/10, with n.  A constant series
    (period-1) gives 0.
    """
    x = np.asarray(phi, dtype=float)
    x = x[np.isfinite(x)]
    n_pts = x.size
    if n_pts < 20:
        return float("nan")
    x = x - x.mean()
    if float(np.max(np.abs(x))) <= 1e-12 * max(1.0, float(np.max(np.abs(phi)))):
        return 0.0

    ncut = max(3, n_pts // 10)
    cs = np.random.default_rng(seed).uniform(np.pi / 5, 4 * np.pi / 5, n_c)
    return float(np.median(correlations(np.ascontiguousarray(x), cs, ncut)))


def spectral_flatness(phi: np.ndarray) -> float:
    """Wiener entropy of the stroboscopic series: geometric / arithmetic mean of the Hann-windowed
    power spectrum (DC left out).  About 0.56 for white noise, below 1e-2 for a few discrete lines
    (quasi-periodic or periodic samples); 0 for a constant series."""
    x = np.asarray(phi, dtype=float)
    x = x[np.isfinite(x)]
    if x.size < 16:
        return float("nan")
    x = x - x.mean()
    if float(np.max(np.abs(x))) == 0.0:
        return 0.0
    pw = np.abs(np.fft.rfft(x * np.hanning(x.size)))[1:] ** 2
    pw = pw + 1e-30 * pw.max()
    return float(np.exp(np.mean(np.log(pw))) / np.mean(pw))


# ----------------------------------------------------------------------------------------
# decision
# ----------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ClassifierSettings:
    """Thresholds of :func:`classify_point` (exponents per unit dimensionless time tau = w_n t).

    max_n: largest period tested.  rtol, atol: return-distance tolerance rtol * attractor size +
    atol * max(|p|, 1).  error_floor: the tolerance is never below this (integration error of the
    Poincaré points, e.g. 7.5e-8 at 512 steps and 1.9e-5 at 128, docs/model.md Sec. 6; 10x margin by
    default via ``error_margin``).  lam_tol: |lambda| below this is "zero" (quasi-periodic); the
    least-damped mode of the KHV model decays at about 2.5e-3, chaos in the model shows 3e-2.
    k_chaos: 0-1 statistic above which the series looks chaotic.  flat_broadband: spectral
    flatness above which the samples look broadband.  tangent_periods: mesh periods the tangent
    vector is carried (the last ones of the run).  separation: the points of a period-n cycle must
    differ by more than separation * tol (return distances for m < n).  settle_max_n,
    settle_max_periods: the slow-transient check applied after these rules by
    the labeller (:mod:`geardyn.label.settle`; 0: off).
    """

    max_n: int = 12
    rtol: float = 1e-4
    atol: float = 1e-6
    error_floor: float = 7.5e-8
    error_margin: float = 10.0
    lam_tol: float = 1e-3
    k_chaos: float = 0.5
    flat_broadband: float = 0.05
    tangent_periods: int = 400
    separation: float = 10.0
    settle_max_n: int = 12
    settle_max_periods: int = 4000
    torus_margin: float = 2.5
    chaos_margin: float = 1.5
    torus_min_n: int = 50
    torus_extend: int = 3
    torus_max_periods: int = 4000
    long_max_n: int = 240

    @classmethod
    def from_mapping(cls, spec: dict | None) -> ClassifierSettings:
        return settings_from(cls, spec, "classifier settings")


@dataclass(frozen=True)
class Classification:
    """Result of :func:`classify_point`.

    label: code of :data:`LABELS` or n >= 1 (period-n).  period: n (0 when not periodic).
    lyapunov, lyapunov_sigma: largest exponent and its uncertainty (per unit tau).
    k01: 0-1 statistic; flatness: spectral flatness of the stroboscopic X_VH.
    crosscheck: 1 when the 0-1 test and the spectrum both agree with the label, 0 when only one
    does, -1 when not applicable (periodic by the return test, diverged).
    reason: short text.  settled: 0 the rules decided; :data:`SETTLED` the label is period-n because
    the run was found to approach a stable period-n orbit (:mod:`geardyn.label.settle`) after the rules
    called it quasi-periodic or undetermined; :data:`POSSIBLE_TRANSIENT` a stable orbit was found whose
    multiplier is too close to 1 to see the run approach it, so the label is undetermined.
    """

    label: int
    period: int
    lyapunov: float
    lyapunov_sigma: float
    k01: float
    flatness: float
    crosscheck: int
    reason: str
    settled: int = 0


def _tolerance(p: np.ndarray, cs: ClassifierSettings) -> float:
    size = float(np.max(np.ptp(p, axis=0)))
    scale = max(float(np.max(np.abs(p))), 1.0)
    return max(cs.atol * scale + cs.rtol * size, cs.error_margin * cs.error_floor)


def strict_period(p: np.ndarray, settings: ClassifierSettings = ClassifierSettings()) -> int:
    """Rule 3 of :func:`classify_point`: the smallest n <= max_n with every return distance after n
    periods within the tolerance and the n cycle points distinct (> separation * tol); 0 if none.
    ``p``: (n_points, n_states) without NaN rows.  Compiled (:func:`geardyn.solve.simulate.strict_period`:
    the one statement of the rule, also used by the batch classifier and the early stop)."""

    q = np.ascontiguousarray(p, dtype=float)
    if q.shape[0] == 0:
        raise ValueError("strict_period needs at least one Poincaré point")
    n, _ = rule3(
        q,
        settings.max_n,
        settings.atol,
        settings.rtol,
        settings.error_margin * settings.error_floor,
        settings.separation,
    )
    return n


def _converging_period(p: np.ndarray, rate: float, max_n: int, tol: float) -> int:
    """Smallest n whose return distance decays like the exponent says (no floor): the last quarter's
    maximum is below the first quarter's times sqrt(exp(rate * span)), i.e. at least half the decay in
    log terms that the Lyapunov exponent (``rate`` = lambda T per period, < 0) predicts, or below tol.
    A period that is not a multiple of the true one leaves a constant floor (the cycle's spread)."""
    for n in range(1, max_n + 1):
        d = _return_distances(p, n)
        if d.size < 8:
            return 0
        q = np.array_split(d, 4)
        first, last = float(np.max(q[0])), float(np.max(q[-1]))
        span = d.size - 0.5 * (q[0].size + q[-1].size)
        if last <= tol or last <= first * math.exp(0.5 * rate * span):
            return n
    return 0


def classify_point(
    poincare: np.ndarray,
    growth: np.ndarray,
    period: float,
    diverged: bool = False,
    settings: ClassifierSettings = ClassifierSettings(),
    samples: np.ndarray | None = None,
) -> Classification:
    """Label one point from its Poincaré points (n, 6) and its tangent growth per period.

    ``samples``: a longer stroboscopic series of X_VH for the 0-1 test and the spectrum (default:
    column 1 of ``poincare``).  The 0-1 test needs about 400 samples to separate a quasi-periodic
    circle (K < 0.1) from chaos (K > 0.99); with 100 it gives K = 0.4-0.9 for quasi-periodic
    samples (measured, tests/test_classify.py), hence the default of 400 tangent periods.

    Rules, in order:

    1. diverged -> ``diverged``.
    2. fewer than 3 points -> ``undetermined``.
    3. period-n: the smallest n <= max_n with max_k |p_{k+n} - p_k| <= tol (tolerance scaled to the
       attractor, above the integration error) and max_k |p_{k+m} - p_k| > separation * tol for every
       m < n (distinct cycle points) -> ``P n``.
    4. lambda > lam_tol + 2 sigma -> ``chaotic`` if the 0-1 test (K > k_chaos) or the spectrum
       (flatness > flat_broadband) agrees, else ``undetermined``.
    5. lambda < -(lam_tol + 2 sigma): the orbit is attracted to a periodic orbit not yet reached
       (the slowly decaying shaft mode) -> ``P n`` for the smallest n <= max_n whose return distance
       decays at (at least half) the rate the exponent predicts, with no floor; else ``undetermined``
       (transient not settled, or a period above max_n).
    6. |lambda| <= lam_tol with sigma <= lam_tol -> ``quasi_periodic`` if the 0-1 test (K < k_chaos)
       or the spectrum (flatness <= flat_broadband) agrees, else ``undetermined``.
    7. anything else (exponent not resolved) -> ``undetermined``.
    """
    nan = float("nan")
    if diverged:
        lam, sig = lyapunov_estimate(growth, period) if len(growth) else (float("inf"), 0.0)
        return Classification(LABELS["diverged"], 0, lam, sig, nan, nan, -1, "diverged")
    p = np.asarray(poincare, dtype=float)
    if p.ndim == 1:
        p = p[:, None]
    p = p[~np.isnan(p).any(axis=1)]
    lam, sig = lyapunov_estimate(growth, period)
    if p.shape[0] < 3:
        return Classification(LABELS["undetermined"], 0, lam, sig, nan, nan, -1, "too few points")
    tol = _tolerance(p, settings)
    n = strict_period(p, settings)
    if n > 0:
        return Classification(n, n, lam, sig, nan, nan, -1, f"returns within {tol:.2g} after {n}")
    phi = p[:, 1] if samples is None else np.asarray(samples, dtype=float)  # X_VH at the section
    k01 = zero_one_test(phi)
    flat = spectral_flatness(phi)
    k_chaos = bool(k01 > settings.k_chaos)
    broad = bool(flat > settings.flat_broadband)
    if not np.isfinite(lam):
        return Classification(LABELS["undetermined"], 0, lam, sig, k01, flat, -1, "no exponent")
    if lam > settings.lam_tol + 2 * sig:
        agree = int(k_chaos) + int(broad)
        if agree:
            return Classification(LABELS["chaotic"], 0, lam, sig, k01, flat, int(agree == 2), "positive exponent")
        return Classification(
            LABELS["undetermined"],
            0,
            lam,
            sig,
            k01,
            flat,
            0,
            "positive exponent, but 0-1 test and spectrum say regular",
        )
    if lam < -(settings.lam_tol + 2 * sig):
        n = _converging_period(p, lam * period, settings.max_n, tol)
        if n > 0:
            return Classification(n, n, lam, sig, k01, flat, -1, f"negative exponent, converging to period {n}")
        return Classification(
            LABELS["undetermined"],
            0,
            lam,
            sig,
            k01,
            flat,
            -1,
            "negative exponent, transient not settled (or period > max_n)",
        )
    if abs(lam) <= settings.lam_tol and sig <= settings.lam_tol:
        agree = int(not k_chaos) + int(not broad)
        if agree:
            return Classification(LABELS["quasi_periodic"], 0, lam, sig, k01, flat, int(agree == 2), "zero exponent")
        return Classification(
            LABELS["undetermined"], 0, lam, sig, k01, flat, 0, "zero exponent, but 0-1 test and spectrum say chaotic"
        )
    return Classification(LABELS["undetermined"], 0, lam, sig, k01, flat, -1, "exponent not resolved")
