"""Test oracle: the rules applied to one plain run (no following, no shooting, no torus test).

This is the classifier's point-by-point path of earlier versions, kept here only to test against: a run
from the static deflection (or ``x0``) with a tangent vector over its last ``tangent_periods`` periods,
labelled by :func:`classify_point` (the rules, stated here).  The product labels through :mod:`geardyn.label`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from geardyn import classify
from geardyn.solve import SimulationSettings, simulate

LABELS = classify.LABELS


def rules_label(
    system,
    settings: SimulationSettings,
    cs: classify.ClassifierSettings = classify.ClassifierSettings(),
    x0: np.ndarray | None = None,
):
    """(SimulationResult, Classification) of one plain run."""
    res = simulate(system, settings, x0=x0, tangent_periods=cs.tangent_periods)
    return res, classify_point(res.poincare, res.growth, res.period, res.diverged, cs, samples=res.strobe)


@dataclass(frozen=True)
class Classification:
    """Result of :func:`classify_point`.

    label: code of :data:`LABELS` or n >= 1 (period-n).  period: n (0 when not periodic).
    lyapunov, lyapunov_sigma: largest exponent and its uncertainty (per unit tau).
    k01: 0-1 statistic; flatness: spectral flatness of the stroboscopic X_VH.
    crosscheck: 1 when the 0-1 test and the spectrum both agree with the label, 0 when only one
    does, -1 when not applicable (periodic by the return test, diverged).
    reason: short text.  settled: 0 the rules decided; 1 the label is period-n because
    the run was found to approach a stable period-n orbit after the rules
    called it quasi-periodic or undetermined; 2 a stable orbit was found whose
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


def _converging_period(p: np.ndarray, rate: float, max_n: int, tol: float) -> int:
    """Smallest n whose return distance decays like the exponent says (no floor): the last quarter's
    maximum is below the first quarter's times sqrt(exp(rate * span)), i.e. at least half the decay in
    log terms that the Lyapunov exponent (``rate`` = lambda T per period, < 0) predicts, or below tol.
    A period that is not a multiple of the true one leaves a constant floor (the cycle's spread)."""
    for n in range(1, max_n + 1):
        d = np.max(np.abs(p[n:] - p[:-n]), axis=1)
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
    settings: classify.ClassifierSettings = classify.ClassifierSettings(),
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
        lam, sig = classify.lyapunov_estimate(growth, period) if len(growth) else (float("inf"), 0.0)
        return Classification(LABELS["diverged"], 0, lam, sig, nan, nan, -1, "diverged")
    p = np.asarray(poincare, dtype=float)
    if p.ndim == 1:
        p = p[:, None]
    p = p[~np.isnan(p).any(axis=1)]
    lam, sig = classify.lyapunov_estimate(growth, period)
    if p.shape[0] < 3:
        return Classification(LABELS["undetermined"], 0, lam, sig, nan, nan, -1, "too few points")
    tol = classify._tolerance(p, settings)
    n = classify.strict_period(p, settings)
    if n > 0:
        return Classification(n, n, lam, sig, nan, nan, -1, f"returns within {tol:.2g} after {n}")
    phi = p[:, 1] if samples is None else np.asarray(samples, dtype=float)  # X_VH at the section
    k01 = classify.zero_one_test(phi)
    flat = classify.spectral_flatness(phi)
    k_chaos = bool(k01 > settings.k_chaos)
    broad = bool(flat > settings.flat_broadband)

    def undetermined(cross: int, why: str) -> Classification:
        return Classification(LABELS["undetermined"], 0, lam, sig, k01, flat, cross, why)

    if not np.isfinite(lam):
        return undetermined(-1, "no exponent")
    if lam > settings.lam_tol + 2 * sig:
        agree = int(k_chaos) + int(broad)
        if agree:
            return Classification(LABELS["chaotic"], 0, lam, sig, k01, flat, int(agree == 2), "positive exponent")
        return undetermined(0, "positive exponent, but 0-1 test and spectrum say regular")
    if lam < -(settings.lam_tol + 2 * sig):
        n = _converging_period(p, lam * period, settings.max_n, tol)
        if n > 0:
            return Classification(n, n, lam, sig, k01, flat, -1, f"negative exponent, converging to period {n}")
        return undetermined(-1, "negative exponent, transient not settled (or period > max_n)")
    if abs(lam) <= settings.lam_tol and sig <= settings.lam_tol:
        agree = int(not k_chaos) + int(not broad)
        if agree:
            return Classification(LABELS["quasi_periodic"], 0, lam, sig, k01, flat, int(agree == 2), "zero exponent")
        return undetermined(0, "zero exponent, but 0-1 test and spectrum say chaotic")
    return undetermined(-1, "exponent not resolved")
