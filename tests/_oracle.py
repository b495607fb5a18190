"""Test oracle: the rules applied to one plain run (no following, no shooting, no torus test).

This is the classifier's point-by-point path of earlier versions, kept here only to test against: a run
from the static deflection (or ``x0``) with a tangent vector over its last ``tangent_periods`` periods,
labelled by :func:`classify_point` (the rules, stated here).  The product labels through :mod:`geardyn.label`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from geardyn import libm
from geardyn.label import indicators, vocabulary
from geardyn.solve import SimulationSettings, simulate
from geardyn.solve.base import Tangent
from geardyn.solve.shooting import FlowMap, khv_flow, newton_shooting

LABELS = vocabulary.LABELS


def rules_label(
    system,
    settings: SimulationSettings,
    cs: indicators.ClassifierSettings = indicators.ClassifierSettings(),
    x0: np.ndarray | None = None,
):
    """(SimulationResult, Classification) of one plain run."""
    res = simulate(system, settings, x0=x0, variational=Tangent(cs.tangent_periods))
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
    settings: indicators.ClassifierSettings = indicators.ClassifierSettings(),
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
        lam, sig = indicators.lyapunov_estimate(growth, period) if len(growth) else (float("inf"), 0.0)
        return Classification(LABELS["diverged"], 0, lam, sig, nan, nan, -1, "diverged")
    p = np.asarray(poincare, dtype=float)
    if p.ndim == 1:
        p = p[:, None]
    p = p[~np.isnan(p).any(axis=1)]
    lam, sig = indicators.lyapunov_estimate(growth, period)
    if p.shape[0] < 3:
        return Classification(LABELS["undetermined"], 0, lam, sig, nan, nan, -1, "too few points")
    tol = tolerance(p, settings)
    n = indicators.strict_period(p, settings)
    if n > 0:
        return Classification(n, n, lam, sig, nan, nan, -1, f"returns within {tol:.2g} after {n}")
    phi = p[:, 1] if samples is None else np.asarray(samples, dtype=float)  # X_VH at the section
    k01 = indicators.zero_one_test(phi)
    flat = indicators.spectral_flatness(phi)
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


# ------------------------------------------------------------------------------------------------
# the torus test's single-purpose forms (the labeller uses geardyn.label.torus.torus_digits)
# ------------------------------------------------------------------------------------------------


def moments(points: np.ndarray) -> np.ndarray:
    """The observable z, z^2, z^3 of the standardised coordinates z of the (m, d) points (three moments
    make a chance agreement of the two halves of a chaotic series rarer than z alone)."""
    from geardyn.label.torus import coordinates  # noqa: PLC0415

    z = coordinates(points)
    return np.concatenate([z, z * z, z * z * z], axis=1)


def weighted_birkhoff(values: np.ndarray) -> np.ndarray:
    """Weighted Birkhoff average of ``values`` (N,) or (N, ...) along axis 0 (bump weight over N)."""
    from geardyn.label._birkhoff import averages  # noqa: PLC0415
    from geardyn.label.torus import bump_weights  # noqa: PLC0415

    v = np.asarray(values, dtype=float)
    if v.ndim == 0:
        raise ValueError("weighted_birkhoff needs a series (axis 0 = time), got a scalar")
    flat = np.ascontiguousarray(v.reshape(v.shape[0], -1))
    return averages(flat, bump_weights(v.shape[0]), np.zeros(1, np.int64))[0].reshape(v.shape[1:])


def birkhoff_digits(points: np.ndarray, observable=None) -> float:
    """The plain digits of the last 2N points (default observable: :func:`moments`)."""
    from geardyn.label.torus import torus_digits  # noqa: PLC0415

    return torus_digits(points, moments if observable is None else observable, extrapolate=False)[0]


def torus_test(
    points: np.ndarray, torus_digits: float = 6.0, chaos_digits: float = 1.5, min_n: int = 2000, observable=None
):
    """The verdict of the plain digits of the last 2N points (:func:`geardyn.label.torus.torus_verdict`)."""
    from geardyn.label.torus import torus_verdict  # noqa: PLC0415

    n = np.asarray(points).shape[0] // 2
    return torus_verdict(birkhoff_digits(points, observable), n, torus_digits, chaos_digits, min_n)


def rotation_number(points: np.ndarray, center, plane: tuple[int, int] = (0, 1)) -> float:
    """Rotation number (turns per iterate, in [0, 1)) of the points about ``center`` in a coordinate plane:
    the angle increments, wrapped about their circular mean, averaged with the bump weight."""
    p = np.asarray(points, dtype=float)
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


# ------------------------------------------------------------------------------------------------
# flow maps for the shooting tests: any smooth forced ODE, and a finite-difference monodromy
# ------------------------------------------------------------------------------------------------


def rk4_flow(
    rhs: Callable[[float, np.ndarray], np.ndarray],
    jac: Callable[[float, np.ndarray], np.ndarray],
    period: float,
    steps_per_period: int = 400,
    n: int = 1,
    threshold: float = 1e6,
) -> FlowMap:
    """n-period map of a smooth T-periodic ODE y' = rhs(t, y) by classical RK4, with the variational
    equations Y' = jac(t, y) Y advanced by the same stages (the derivative of the discrete map)."""
    h = period / steps_per_period

    def flow(x: np.ndarray, jacobian: bool = True):
        y = np.asarray(x, dtype=float).copy()
        d = y.size
        Y = np.eye(d) if jacobian else None
        t = 0.0
        for _ in range(n * steps_per_period):
            k1 = rhs(t, y)
            y2 = y + 0.5 * h * k1
            k2 = rhs(t + 0.5 * h, y2)
            y3 = y + 0.5 * h * k2
            k3 = rhs(t + 0.5 * h, y3)
            y4 = y + h * k3
            k4 = rhs(t + h, y4)
            if jacobian:
                J1, J2, J3, J4 = jac(t, y), jac(t + 0.5 * h, y2), jac(t + 0.5 * h, y3), jac(t + h, y4)
                K1 = J1 @ Y
                K2 = J2 @ (Y + 0.5 * h * K1)
                K3 = J3 @ (Y + 0.5 * h * K2)
                K4 = J4 @ (Y + h * K3)
                Y = Y + h / 6.0 * (K1 + 2 * K2 + 2 * K3 + K4)
            y = y + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
            t += h
        if not (np.all(np.isfinite(y)) and np.max(np.abs(y)) < threshold):
            return None, None
        return y, Y

    return flow


def fd_monodromy(flow: FlowMap, x: np.ndarray, h: float = 1e-5) -> np.ndarray:
    """Central finite-difference monodromy (relative step h * max(1, |x_i|)), for checks."""
    x = np.asarray(x, dtype=float)
    M = np.empty((x.size, x.size))
    for i in range(x.size):
        d = h * max(1.0, abs(x[i]))
        e = np.zeros(x.size)
        e[i] = d
        up, _ = flow(x + e, False)
        dn, _ = flow(x - e, False)
        M[:, i] = (up - dn) / (2 * d)
    return M


# ------------------------------------------------------------------------------------------------
# the linear (b = 0) model's Floquet analysis by DOP853: an independent check of the shooting
# ------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class FloquetResult:
    monodromy: np.ndarray  # (6, 6)
    multipliers: np.ndarray  # (6,) complex
    periodic_state: np.ndarray  # (6,) Poincare point of the T-periodic orbit

    @property
    def spectral_radius(self) -> float:
        return float(np.max(libm.cabs(self.multipliers)))

    @property
    def stable(self) -> bool:
        return self.spectral_radius < 1.0


def linear_part(coeffs):
    """The linear (b = 0) model of the same coefficients."""
    return coeffs.replace(b=0.0, backlash_on=False)


def linear_floquet(coeffs, rtol: float = 1e-12) -> FloquetResult:
    """Floquet analysis of the linear case (b = 0: the dead zone vanishes, f(x) = x): the model is then
    y' = A(tau) y + q(tau) with period T.  The monodromy Phi (one mesh period of the homogeneous system) and
    the particular solution y_p(T) from y(0) = 0 are integrated with DOP853 (rtol 1e-12, zone by zone,
    :mod:`geardyn.solve.reference`); the T-periodic orbit is y* = (I - Phi)^-1 y_p(T)."""
    from geardyn.solve.reference import integrate_period  # noqa: PLC0415 - scipy.integrate

    lin = linear_part(coeffs)
    hom = lin.replace(P_D=0.0, P_L=0.0, e=0.0)
    phi = np.empty((6, 6))
    for i in range(6):
        e = np.zeros(6)
        e[i] = 1.0
        phi[:, i], _, _ = integrate_period(hom, e, 0, rtol, atol=rtol * 1e-2)
    yp, _, _ = integrate_period(lin, np.zeros(6), 0, rtol)
    ystar = np.linalg.solve(np.eye(6) - phi, yp)
    return FloquetResult(phi, np.linalg.eigvals(phi), ystar)


def tolerance(p: np.ndarray, cs: indicators.ClassifierSettings) -> float:
    """Rule 3's return-distance tolerance of the points ``p`` (the classifier's, stated in numpy)."""
    size = float(np.max(np.ptp(p, axis=0)))
    scale = max(float(np.max(np.abs(p))), 1.0)
    return max(cs.atol * scale + cs.rtol * size, cs.error_margin * cs.error_floor)


def shoot(
    system,
    x0: np.ndarray | None = None,
    n: int = 1,
    settings: SimulationSettings | None = None,
    tol: float = 1e-9,
    max_iter: int = 30,
    max_growth: float = math.inf,
):
    """Period-n orbit of a KHV system from x0 (default: the static deflection): :func:`newton_shooting` on
    :func:`khv_flow`, one point alone (the reference of the batched shooting)."""
    x0 = system.static_state() if x0 is None else x0
    return newton_shooting(khv_flow(system, n, settings), x0, n, tol, max_iter, max_growth=max_growth)


def contact_fractions(
    x: np.ndarray, v: np.ndarray, h: float, b: float, side: float = 1.0
) -> tuple[float, float, float]:
    """Fractions of time (drive, separation, back) of a trajectory sampled every h (x2 and its slope x2' at
    the samples), the crossings of x2 = +-b located on the cubic Hermite interpolant between samples as the
    accumulator does; ``side``: the sign of the drive-side contact."""
    import geardyn.solve._response as _acc  # noqa: PLC0415 - compiled

    x, v = np.asarray(x, dtype=float), np.asarray(v, dtype=float)
    if x.shape != v.shape or x.ndim != 1 or x.size < 2 or not h > 0.0 or not b >= 0.0:
        raise ValueError("contact_fractions: x and v of equal length >= 2, h > 0, b >= 0")
    times = np.zeros(3)
    for i in range(x.size - 1):
        _acc.region_times(x[i], x[i + 1], v[i], v[i + 1], h, b, times, 0)
    pos, zero, neg = times / times.sum()
    return (float(pos), float(zero), float(neg)) if side > 0 else (float(neg), float(zero), float(pos))
