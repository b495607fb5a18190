"""What the labeller measures on a record: rule 3 (:func:`strict_period` with its thresholds,
:class:`ClassifierSettings`), the falling return distances and the indicators (Lyapunov exponent, 0-1 test,
spectral flatness); :mod:`geardyn.label` decides the labels, :mod:`geardyn.label.vocabulary` names them
(``docs/classify.md``)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geardyn import libm
from geardyn.config import settings_from
from geardyn.solve.precision import POINCARE_ERROR

#: Numeric guards of the indicators (not thresholds of a verdict):
#: a signal or coordinate whose spread is below CONSTANT_SPREAD of its magnitude is constant (ten thousand
#: times double precision's 2.2e-16: round-off, not motion);
CONSTANT_SPREAD = 1e-12
#: a spread below FLAT_COMPONENT of the largest component's is no component of the motion (round-off of the
#: largest one carried into the others);
FLAT_COMPONENT = 1e-9
#: the floor, relative to the largest bin, that keeps the log of an empty spectral bin finite without moving the
#: flatness of any spectrum with content (its bins are far above 1e-30 of the largest);
POWER_FLOOR = 1e-30
#: the floor that keeps the log of a zero distance finite (the smallest normal double is 2.2e-308).
LOG_FLOOR = 1e-300


def falling_return_distances(poincare: np.ndarray, max_n: int, factor: float = 0.95) -> np.ndarray:
    """For n = 1 .. ``max_n`` (boolean array, entry n - 1): whether the return distance
    d_n(k) = max_i |p_k+n,i - p_k,i| of the Poincare points (rows with NaN left out) falls over the
    record: mean of its last quarter < ``factor`` x mean of its first quarter (a quarter: max(2, len // 4)
    values).  True when there are fewer than n + 8 points (too short to tell).  Compiled."""

    from geardyn.label._falling import falling  # noqa: PLC0415 - numba: only the jobs that label import it

    p = np.asarray(poincare, dtype=float)
    return falling(np.ascontiguousarray(p[np.all(np.isfinite(p), axis=1)]), max_n, factor)


# ----------------------------------------------------------------------------------------
# indicators
# ----------------------------------------------------------------------------------------


def lyapunov_estimate(
    growth: np.ndarray, period: float, skip: int | None = None, blocks: int = 8
) -> tuple[float, float]:
    """Largest Lyapunov exponent (per unit dimensionless time) from the per-period log growths, after
    ``skip`` aligning periods, and its uncertainty ((inf, 0) on divergence; ``docs/classify.md``)."""
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
    """K of the 0-1 test for chaos (Gottwald & Melbourne 2009, correlation method) on a stroboscopic
    series ``phi``: ~0 for regular motion, ~1 for chaos, 0 for a constant series (``docs/classify.md``)."""
    x = np.asarray(phi, dtype=float)
    x = x[np.isfinite(x)]
    n_pts = x.size
    if n_pts < 20:
        return float("nan")
    x = x - x.mean()
    if float(np.max(np.abs(x))) <= CONSTANT_SPREAD * max(1.0, float(np.max(np.abs(phi)))):
        return 0.0

    ncut = max(3, n_pts // 10)
    cs = np.random.default_rng(seed).uniform(np.pi / 5, 4 * np.pi / 5, n_c)
    return float(np.median(_msd_correlations(x, cs, ncut)))


def _msd_correlations(x: np.ndarray, cs: np.ndarray, ncut: int) -> np.ndarray:
    """K_c for each frequency c of ``cs``: the correlation with n = 1 .. ``ncut`` of the mean-square
    displacement of the translation variables of ``x``, by cumulative sums and an FFT autocorrelation
    (the expansion: ``docs/classify.md``)."""
    import scipy.fft  # noqa: PLC0415 - 0.1 s to import: only the jobs that label need it

    n_pts = x.size
    P = np.cumsum(x[None, :] * np.exp(1j * np.outer(cs, np.arange(1, n_pts + 1))), axis=1)
    a2 = np.concatenate([np.zeros((cs.size, 1)), np.cumsum(P.real**2 + P.imag**2, axis=1)], axis=1)
    ns = np.arange(1, ncut + 1)
    nfft = scipy.fft.next_fast_len(n_pts + ncut + 1)
    F = scipy.fft.fft(P, nfft, axis=1)
    auto = scipy.fft.ifft(F.real**2 + F.imag**2, axis=1)[:, 1 : ncut + 1].real
    d = ((a2[:, n_pts : n_pts + 1] - a2[:, ns]) + a2[:, n_pts - ns] - 2.0 * auto) / (n_pts - ns)
    dn = d - d.mean(axis=1, keepdims=True)
    nn = ns - 0.5 * (ncut + 1)
    den = np.sqrt(np.sum(dn * dn, axis=1) * float(nn @ nn))
    return np.where(den > 0.0, (dn @ nn) / np.where(den > 0.0, den, 1.0), 0.0)


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
    pw = libm.cabs(np.fft.rfft(x * np.hanning(x.size)))[1:] ** 2
    pw = pw + POWER_FLOOR * pw.max()
    return float(libm.exp(float(np.mean(libm.log(pw)))) / np.mean(pw))


# ----------------------------------------------------------------------------------------
# decision
# ----------------------------------------------------------------------------------------


@dataclass(frozen=True)
class ClassifierSettings:
    """Thresholds of the labeller (exponents per unit dimensionless time tau = w_n t): rule 3's period,
    tolerances and separation, the exponent's zero band, indicator thresholds, and the slow-transient and torus
    tests' settings (measured values: ``docs/classify.md``)."""

    max_n: int = 12
    rtol: float = 1e-4
    atol: float = 1e-6
    error_floor: float = POINCARE_ERROR[512]  # the measured Poincare error at the default 512 steps per period
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
    torus_extend: int = 1
    torus_max_periods: int = 4000
    order_min_n: int = 800
    long_max_n: int = 240

    @classmethod
    def from_mapping(cls, spec: dict | None) -> ClassifierSettings:
        return settings_from(cls, spec, "classifier settings")


def strict_period(p: np.ndarray, settings: ClassifierSettings = ClassifierSettings()) -> int:
    """Rule 3: the smallest n <= max_n with every return distance after n periods within the tolerance and the n
    cycle points distinct (> separation * tol); 0 if none.  ``p``: (n_points, n_states) without NaN rows.  Stated
    once, compiled (:mod:`geardyn.solve._period`), read here, by the batch classifier and by the early stop."""

    from geardyn.solve.run import strict_period as rule3  # noqa: PLC0415 - numba: only labelling jobs

    q = np.ascontiguousarray(p, dtype=float)
    if q.shape[0] == 0:
        raise ValueError("strict_period needs at least one Poincaré point")
    s = settings
    return int(rule3(q, q.shape[0], s.max_n, s.atol, s.rtol, s.error_margin * s.error_floor, s.separation)[0])


def strict_periods(records: list[np.ndarray], settings: ClassifierSettings = ClassifierSettings()) -> list[int]:
    """Rule 3 (:func:`strict_period`) on many records (m_i, 6) at once: each record's period, 0 for one with a NaN
    row or fewer than 3 points."""

    from geardyn.solve.run import strict_periods as rule3  # noqa: PLC0415 - numba: only labelling jobs

    pts = np.zeros((len(records), max([p.shape[0] for p in records] + [0]), 6))
    npts = np.zeros(len(records), np.int64)
    for i, p in enumerate(records):
        if p.shape[0] and not np.isnan(p).any():
            pts[i, : p.shape[0]] = p
            npts[i] = p.shape[0]
    s, out = settings, np.zeros((len(records), 2))
    rule3(pts, npts, s.max_n, s.atol, s.rtol, s.error_margin * s.error_floor, s.separation, out)
    return [int(v) for v in out[:, 0]]
