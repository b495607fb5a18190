"""Torus or chaos by weighted Birkhoff averages (docs/classify.md, "Torus or chaos: weighted Birkhoff
averages") on cases whose answer is known:

* the bump-weighted average of a smooth function sampled on (0, 1) is its weighted integral (scipy quad);
* the golden-mean rotation of the circle (a torus; rotation number (sqrt 5 - 1) / 2 exactly);
* the stroboscopic map of a weakly forced van der Pol oscillator off resonance (a smooth invariant
  circle), integrated by scipy's LSODA at 1e-12;
* the Henon map (a = 1.4, b = 0.3) and the logistic map at r = 4 (chaotic);
* the KHV model: ``li2013_calibrated`` past its Neimark-Sacker point (x1 = 0.5420) at x1 = 0.56 is on a
  torus whose rotation number is near the argument of the unstable P1 orbit's complex Floquet
  multipliers (Newton shooting); ``li2013_route`` at x1 = 0.80 is chaotic (exponent +0.032);
* with a slowly decaying transient (a circle approached at r = 0.999 per iterate; the model's torus at
  x1 = 0.55 after 500 periods) the plain test is inconclusive and the extrapolated one
  (:func:`~geardyn.label.torus.extrapolated_digits`) finds the torus; on chaos, weak chaos included, it
  stays at the chaotic rate.
"""

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import odeint, quad

import _oracle as O
from geardyn.khv import design, point
from geardyn.label import indicators
from geardyn.label import torus as T
from geardyn.solve import SimulationSettings, shooting, simulate
from geardyn.solve.base import Tangent

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


def _circle(m: int, rho: float = GOLDEN) -> np.ndarray:
    th = 2.0 * math.pi * ((0.1 + rho * np.arange(m)) % 1.0)
    return np.c_[np.cos(th), np.sin(th)]


def _henon(m: int, skip: int = 1000) -> np.ndarray:
    x, y = 0.1, 0.1
    out = np.empty((m, 2))
    for k in range(skip + m):
        x, y = 1.0 - 1.4 * x * x + y, 0.3 * x
        if k >= skip:
            out[k - skip] = x, y
    return out


def _logistic(m: int, skip: int = 1000) -> np.ndarray:
    x = 0.3141
    out = np.empty(m)
    for k in range(skip + m):
        x = 4.0 * x * (1.0 - x)
        if k >= skip:
            out[k - skip] = x
    return out


def test_weighted_average_is_the_weighted_integral():
    """A smooth function sampled at t_n = (n + 1) / (N + 1): the bump-weighted average converges to
    int f w / int w faster than any power (error 5e-6, 8e-9, 1e-12 at N = 10, 20, 50); the plain
    mean stays 0.017 off."""
    w = lambda t: math.exp(-1.0 / (t * (1.0 - t)))  # noqa: E731
    ref = (
        quad(lambda t: math.cos(3 * t) * w(t), 0, 1, epsabs=1e-15, epsrel=1e-14)[0]
        / quad(w, 0, 1, epsabs=1e-15, epsrel=1e-14)[0]
    )
    errs = {}
    for n in (10, 20, 50, 100):
        t = np.arange(1, n + 1) / (n + 1)
        errs[n] = abs(float(O.weighted_birkhoff(np.cos(3 * t))) - ref)
    assert 1e-6 < errs[10] < 1e-5 and errs[20] < 1e-7 and errs[50] < 1e-11 and errs[100] < 1e-14
    t = np.arange(1, 101) / 101
    assert abs(np.cos(3 * t).mean() - ref) > 0.01
    # along axis 0, column by column
    v = np.c_[np.cos(3 * t), 2.0 * np.cos(3 * t)]
    first = float(O.weighted_birkhoff(v[:, 0]))
    assert O.weighted_birkhoff(v) == pytest.approx([first, 2.0 * first])


def test_golden_rotation_converges_super_fast():
    """Digits (default observable: three moments of each coordinate) 3.4, 5.2, 9.7, 13.8 at N = 50,
    100, 250, 500, then about 14 (rounding) up to N = 20 000: far beyond the log10 sqrt(N) = 0.8-2.2 of
    a 1/sqrt(N) convergence."""
    d = {n: O.birkhoff_digits(_circle(2 * n)) for n in (50, 100, 250, 2000)}
    assert 3.0 < d[50] < 4.0 and 5.0 < d[100] < 6.0 and d[250] > 9.0 and d[2000] > 13.5
    # a smooth non-linear observable of the angle: 4.4, 6.8 at N = 50, 100; 15 at N = 2000
    obs = lambda p: np.exp(p[:, 1]) + 0.3 * (2 * p[:, 0] ** 2 - 1)  # noqa: E731
    assert O.birkhoff_digits(_circle(100), obs) < 5.0 < O.birkhoff_digits(_circle(200), obs)
    assert O.birkhoff_digits(_circle(4000), obs) > 13.5
    res = O.torus_test(_circle(4000))
    assert res.verdict == "torus" and res.n == 2000


@pytest.mark.parametrize("rho", [GOLDEN, 0.01, 0.99, 1.0 - GOLDEN])
def test_rotation_number_of_circle_rotations(rho):
    assert O.rotation_number(_circle(4000, rho), (0.0, 0.0)) == pytest.approx(rho, abs=1e-13)
    # any centre inside the circle gives the same number (the average of the increments converges)
    assert O.rotation_number(_circle(4000, rho), (0.3, -0.2)) == pytest.approx(rho, abs=1e-9)


def test_forced_van_der_pol_circle_is_a_torus():
    """x'' - 0.2 (1 - x^2) x' + x = 0.5 cos(2.2 t), strobed every 2 pi / 2.2: an invariant circle off
    resonance (rotation number 0.5466; LSODA rtol = atol = 1e-12).  Digits 4.0 / 5.4 / 6.7 / 8.4 / 11.0
    at N = 100 / 250 / 500 / 1000 / 2000; the rotation number of 2000 and 4000 points agrees to 1e-9."""
    mu, a, w = 0.2, 0.5, 2.2
    period = 2 * math.pi / w

    def f(y, t):
        return [y[1], mu * (1.0 - y[0] ** 2) * y[1] - y[0] + a * math.cos(w * t)]

    p = odeint(f, [2.0, 0.0], period * np.arange(4100), rtol=1e-12, atol=1e-12, mxstep=100000)[100:]
    assert np.ptp(p[:, 0]) > 3.0  # the circle, not a fixed point
    res = O.torus_test(p)
    assert res.verdict == "torus" and res.n == 2000 and res.digits > 10.0
    assert O.birkhoff_digits(p[:200]) < 5.0 and O.birkhoff_digits(p[:2000]) > 7.5
    rho = O.rotation_number(p, O.weighted_birkhoff(p))
    assert rho == pytest.approx(O.rotation_number(p[:2000], O.weighted_birkhoff(p)), abs=1e-9)
    assert rho == pytest.approx(0.5466, abs=1e-4)


@pytest.mark.parametrize("n", [2000, 8000, 32000])
def test_chaotic_maps_converge_like_one_over_sqrt_n(n):
    """Henon (a = 1.4, b = 0.3) and logistic (r = 4): digits within 1.2 of log10 sqrt(N) = 1.65 /
    1.95 / 2.25 (measured +0.11 / -0.18 / +0.27 and -0.13 / -0.78 / -0.26), verdict chaotic."""
    for pts in (_henon(2 * n), _logistic(2 * n)):
        res = O.torus_test(pts)
        assert abs(res.digits - 0.5 * math.log10(n)) < 1.2
        assert res.verdict == "chaotic" and res.n == n


def test_periodic_points_and_bad_input():
    # a period-5 cycle converges as fast as a torus: the caller labels periodic points first
    res = O.torus_test(_circle(4000, 0.2))
    assert res.digits > 12.0 and res.verdict == "torus"  # 12.6
    # a fixed point (no spread): the cap
    assert O.birkhoff_digits(np.full((100, 3), 5.0)) == T.DIGITS_MAX
    assert O.torus_test(np.full((4000, 3), 5.0)).verdict == "torus"
    assert O.birkhoff_digits(np.full((100, 3), 5.0) + 1e-15 * np.arange(100)[:, None]) == T.DIGITS_MAX  # rounding
    # too few points for a verdict (N < 2000), however good the convergence
    assert O.torus_test(_circle(3998)).verdict == "inconclusive"
    assert O.torus_test(_circle(3998), min_n=1999).verdict == "torus"
    p = _circle(100)
    p[37, 1] = np.nan
    with pytest.raises(ValueError, match=r"1 row.*NaN.*row 37"):
        O.birkhoff_digits(p)
    with pytest.raises(ValueError, match="at least 4"):
        O.birkhoff_digits(np.zeros((3, 2)))
    with pytest.raises(ValueError, match=r"chaos threshold .* exceeds torus_digits"):
        O.torus_test(_circle(4000), torus_digits=3.0, chaos_digits=4.0)


def test_khv_torus_past_neimark_sacker():
    """li2013_calibrated, b = 2, e = 5, x1 = 0.56 (NS of the P1 orbit at 0.5420): after 8000 periods
    the Poincaré points lie on a torus (digits 5.8 / 7.6 / 7.2 / 8.4 at N = 250 / 500 / 1000 / 2000).
    Its rotation number about the unstable P1 point, in the (x_VH, v_VH) plane, is 0.360342, near
    arg(mu) / 2 pi = 0.360542 of the orbit's complex multipliers (|mu| = 1.0009)."""
    d = design.load(ROOT / "config" / "designs" / "li2013_calibrated.yaml")
    c = point.point_coefficients(d, {"x1": 0.56, "b": 2.0, "e": 5.0})
    st = SimulationSettings(steps_per_period=128, transient_periods=8000, recorded_periods=4000)
    r = simulate(c, st)
    res = O.torus_test(r.poincare)
    assert res.verdict == "torus" and res.n == 2000 and res.digits > 7.5
    orbit = O.shoot(c, O.weighted_birkhoff(r.poincare), 1, st)
    mu = orbit.multipliers[0]
    assert orbit.converged and abs(mu.imag) > 0.5 and 1.0 < abs(mu) < 1.002
    rho = O.rotation_number(r.poincare, orbit.state[[1, 4]], plane=(1, 4))
    assert rho == pytest.approx(O.rotation_number(r.poincare[:1000], orbit.state[[1, 4]], plane=(1, 4)), abs=1e-7)
    assert abs(rho - shooting.rotation_number(mu)) < 5e-4


def test_khv_chaos_on_route_design():
    """li2013_route, b = 2, e = 5, x1 = 0.80: largest exponent +0.032 per unit tau; the Birkhoff
    averages do not converge (1.0 digits at N = 2000, below log10 sqrt(N) = 1.65)."""
    d = design.load(ROOT / "config" / "designs" / "li2013_route.yaml")
    c = point.point_coefficients(d, {"x1": 0.80, "b": 2.0, "e": 5.0})
    r = simulate(
        c,
        SimulationSettings(steps_per_period=128, transient_periods=500, recorded_periods=4000),
        variational=Tangent(4000),
    )
    lam, sigma = indicators.lyapunov_estimate(r.growth, r.period)
    assert lam > 0.03 and lam > 10 * sigma
    res = O.torus_test(r.poincare)
    assert res.verdict == "chaotic" and res.digits < 0.5 * math.log10(2000) + 0.5


def test_khv_long_cycle_scores_like_a_torus():
    """li2013_calibrated, b = 2, e = 1.658 (row 60 of the (x1, e) map), x1 = 0.4286: undetermined in the
    map, but after 2000 periods the run is on a period-48 cycle (return distance 6e-14 of the attractor
    size at 48 periods, above 2 at 12, 24, 47 and 49; exponent -0.0060) about the stable P1 orbit
    (|mu| = 0.9933).  The test scores it like a torus (9.8 digits at N = 2000), which is why periodic
    points must be labelled first; its rotation number about the P1 point is 17/48 to rounding."""
    d = design.load(ROOT / "config" / "designs" / "li2013_calibrated.yaml")
    c = point.point_coefficients(d, {"x1": 0.4286, "b": 2.0, "e": float(np.linspace(0.0, 5.5, 200)[60])})
    st = SimulationSettings(steps_per_period=128, transient_periods=2000, recorded_periods=4000)
    p = simulate(c, st).poincare
    size = p.std(axis=0).max()
    ret = {n: float(np.max(np.abs(p[n:] - p[:-n]))) / size for n in (12, 24, 47, 48, 49)}
    assert ret[48] < 1e-12 and min(ret[n] for n in (12, 24, 47, 49)) > 1.0
    res = O.torus_test(p)
    assert res.verdict == "torus" and res.digits > 9.0
    orbit = O.shoot(c, O.weighted_birkhoff(p), 1, st)
    assert orbit.converged and 0.99 < abs(orbit.multipliers[0]) < 0.995
    assert O.rotation_number(p, orbit.state[[1, 4]], plane=(1, 4)) == pytest.approx(17 / 48, abs=1e-12)


_coordinates = T.coordinates  # the labeller's observable


def test_torus_digits_are_the_two_measures_bit_for_bit() -> None:
    """One evaluation of the observable serves both measures: on 2N points each value is the measure's own,
    to the bit; on an odd count both read the newest 2N; the coordinates are the first moments."""
    p = _approached_circle(401)
    assert np.array_equal(T.coordinates(p), O.moments(p)[:, :2])
    for obs in (O.moments, _coordinates):
        plain, extrapolated = T.torus_digits(p[1:], obs)
        assert plain == O.birkhoff_digits(p[1:], obs) and extrapolated == T.extrapolated_digits(p[1:], obs)
        assert T.torus_digits(p, obs) == (plain, extrapolated)
        assert T.torus_digits(p, obs, extrapolate=False)[0] == plain
        assert math.isnan(T.torus_digits(p, obs, extrapolate=False)[1])
    assert T.extrapolated_digits(p, _coordinates) != T.torus_digits(p, _coordinates)[1]  # all 401 points
    assert T.torus_digits(np.full((100, 3), 5.0), O.moments) == (T.DIGITS_MAX, T.DIGITS_MAX)
    with pytest.raises(ValueError, match="at least 4 points"):
        T.torus_digits(np.zeros((3, 2)))
    with pytest.raises(ValueError, match="at least 9 points"):
        T.torus_digits(_circle(8))


def _numpy_digits(points: np.ndarray, windows: int = 6) -> tuple[np.ndarray, float, float]:
    """The coordinates and both measures of the labeller's torus test (on an even number of points), stated
    in numpy array operations: the oracle of the compiled loops (:mod:`geardyn.label._birkhoff`)."""
    p = np.asarray(points, dtype=float)
    s = p.std(axis=0)
    varies = s > 1e-12 * np.maximum(1.0, np.max(np.abs(p), axis=0))
    z = np.where(varies, (p - p.mean(axis=0)) / np.where(varies, s, 1.0), 0.0)
    f = z - z.mean(axis=0)
    sf = f.std(axis=0)
    f = f[:, sf > 1e-9 * sf.max()] / sf[sf > 1e-9 * sf.max()]
    m = f.shape[0]
    n = m // 2
    w = T.bump_weights(n)
    plain = float(np.max(np.abs(w @ f[:n] - w @ f[n:])))
    step = (m - n) // (windows - 1)
    d = np.diff(np.stack([w @ f[k * step : k * step + n] for k in range(windows)]), axis=0)
    q = float(np.sum(d[1:] * d[:-1])) / float(np.sum(d[:-1] * d[:-1]))
    q = q if 0.0 < q < 1.0 else 0.0
    return z, -math.log10(plain), -math.log10(float(np.max(np.abs(d[1:] - q * d[:-1]))) / (1.0 - q))


@pytest.mark.parametrize(
    "case",
    ["approached circle", "golden circle with an offset", "henon", "logistic, delay coordinates", "constant column"],
)
def test_compiled_torus_test_equals_its_numpy_statement(case: str) -> None:
    """The compiled loops sum in index order, numpy pairwise: the coordinates agree to 1e-13, the differences
    of averages that the digits measure to 1e-9 of themselves or to 1e-15 (rounding)."""
    if case == "approached circle":
        p = _approached_circle(800)
    elif case == "golden circle with an offset":
        p = _circle(2000) * 1e-3 + np.array([50.0, -7.0])
    elif case == "henon":
        p = _henon(4000)
    elif case == "logistic, delay coordinates":
        x = _logistic(1201)
        p = np.c_[x[:-1], x[1:]]
    else:
        p = np.c_[_henon(1000), np.full(1000, 3.0)]
    z, plain, extrapolated = _numpy_digits(p)
    assert np.max(np.abs(T.coordinates(p) - z)) < 1e-13
    # the measures' differences of averages (10^-digits) agree to 1e-9 of themselves or to 1e-15 (rounding)
    for got, want in zip(T.torus_digits(p, _coordinates), (plain, extrapolated), strict=True):
        assert 10.0**-got == pytest.approx(10.0**-want, rel=1e-9, abs=1e-15)
    assert O.weighted_birkhoff(p) == pytest.approx(T.bump_weights(p.shape[0]) @ p, rel=1e-14, abs=1e-15)


def _approached_circle(m: int, r: float = 0.999, d0: float = 0.02) -> np.ndarray:
    """The golden rotation on the unit circle, approached from off the circle: the deviation d0 r^n has a
    non-zero mean (the centre drifts) and a part that turns with the angle."""
    n = np.arange(m)
    th = 2.0 * math.pi * (0.1 + GOLDEN * n)
    return np.c_[np.cos(th) + d0 * r**n, np.sin(th) + 0.5 * d0 * r**n * np.cos(th)]


@pytest.mark.parametrize("m", [400, 800, 1600, 4000])
def test_extrapolation_removes_a_slow_transient(m):
    """The golden rotation approached at r = 0.999 per iterate: the plain digits stay at 1.98-2.33, within
    the chaotic rate + 1 (log10 sqrt(N) = 1.15-1.65), however long the record; with the geometric tail
    extrapolated away 12.2-13.4 (rounding of the averages).  Without a transient both measures agree
    (golden rotation 14.0 / 13.9, period 5 12.6 / 12.4)."""
    p = _approached_circle(m)
    assert O.birkhoff_digits(p, _coordinates) < 0.5 * math.log10(m // 2) + 1.2
    assert T.extrapolated_digits(p, _coordinates) > 12.0
    assert T.extrapolated_digits(_circle(m), O.moments) == pytest.approx(O.birkhoff_digits(_circle(m)), abs=1.0)
    assert T.extrapolated_digits(_circle(m, 0.2), O.moments) > 12.0


@pytest.mark.parametrize("n", [200, 800, 2000, 8000])
def test_extrapolation_does_not_make_chaos_converge(n):
    """Henon and logistic, 20 series each: the extrapolated digits stay below log10 sqrt(N) + 1.0 (measured
    at most + 0.87 in 640 series, N = 50-8000, both observables), under the labeller's chaos margin 1.5."""
    for k in range(20):
        for pts in (_henon(2 * n, skip=1000 + 37 * k), _logistic(2 * n, skip=1000 + 37 * k)):
            for obs in (O.moments, _coordinates):
                assert T.extrapolated_digits(pts, obs) < 0.5 * math.log10(n) + 1.0


def test_extrapolation_bad_input():
    with pytest.raises(ValueError, match="at least 9 points"):
        T.extrapolated_digits(_circle(8), O.moments)
    assert T.extrapolated_digits(_circle(9), O.moments) > 0.0
    with pytest.raises(ValueError, match="at least 3 windows"):
        T.extrapolated_digits(_circle(100), O.moments, windows=2)
    assert T.extrapolated_digits(np.full((100, 3), 5.0), O.moments) == T.DIGITS_MAX
    assert T.torus_verdict(5.0, 2000).verdict == "inconclusive"  # 6 for a torus, < 3.15 for chaos
    assert T.torus_verdict(3.0, 2000).verdict == "chaotic" and T.torus_verdict(6.0, 2000).verdict == "torus"


def test_khv_slowly_approached_torus_is_found_by_extrapolation():
    """li2013_calibrated, b = 2, e = 5, x1 = 0.55 (0.008 past the Neimark-Sacker point: the torus attracts
    at about 2 (|mu| - 1) per period), 400 periods after a transient of 500 from the static deflection,
    128 steps: the plain digits 3.49 are under the labeller's torus threshold log10 sqrt(200) + 2.5 = 3.65,
    the extrapolated ones 5.33 (after 2000 periods the plain digits reach 3.98 on 400 points)."""
    d = design.load(ROOT / "config" / "designs" / "li2013_calibrated.yaml")
    c = point.point_coefficients(d, {"x1": 0.55, "b": 2.0, "e": 5.0})
    p = simulate(c, SimulationSettings(steps_per_period=128, transient_periods=500, recorded_periods=400)).poincare
    threshold = 0.5 * math.log10(200) + 2.5
    assert O.birkhoff_digits(p, _coordinates) == pytest.approx(3.49, abs=0.05)
    assert T.extrapolated_digits(p, _coordinates) == pytest.approx(5.33, abs=0.05)
    assert 3.49 + 0.05 < threshold < 5.33 - 1.5


def test_khv_weak_chaos_stays_chaotic_for_the_extrapolation():
    """li2013_calibrated, b = 2, e = 1.658, x1 = 0.4518 (weak chaos: exponent +0.00018 +- 0.00002 over
    64 000 periods): after 20 000 periods, 4000 recorded, the extrapolated digits 2.41 (plain 2.65) are
    under the chaos threshold log10 sqrt(2000) + 1.5 = 3.15; the exponent over these 4000 periods, +0.00025
    +- 0.00054, cannot say "positive": the labeller leaves such a point undetermined."""
    d = design.load(ROOT / "config" / "designs" / "li2013_calibrated.yaml")
    c = point.point_coefficients(d, {"x1": 0.4518, "b": 2.0, "e": 1.658})
    st = SimulationSettings(steps_per_period=128, transient_periods=20000, recorded_periods=4000)
    r = simulate(c, st, variational=Tangent(4000))
    chaos = 0.5 * math.log10(2000) + 1.5
    assert T.extrapolated_digits(r.poincare, _coordinates) == pytest.approx(2.41, abs=0.1)
    assert O.birkhoff_digits(r.poincare, _coordinates) == pytest.approx(2.65, abs=0.1)
    assert 2.65 + 0.1 < chaos
    lam, sigma = indicators.lyapunov_estimate(r.growth, r.period)
    assert 0.0 < lam < 1e-3 and sigma > lam


# ------------------------------------------------------------------------------------------------
# the three-gap order test: tori with corners, no smoothness needed
# ------------------------------------------------------------------------------------------------


def _square(m: int, rho: float = GOLDEN) -> np.ndarray:
    """The golden rotation carried onto the boundary of the unit square by a piecewise-linear homeomorphism
    (slope 5/3 on [0, 0.3), 5/7 after): an invariant closed curve with corners, conjugate to the rotation
    only by a map with jumps in its derivative."""
    t = (0.1 + rho * np.arange(m)) % 1.0
    s = 4.0 * np.where(t < 0.3, t * 0.5 / 0.3, 0.5 + (t - 0.3) * 0.5 / 0.7)
    x = np.select([s < 1, s < 2, s < 3], [s, np.ones_like(s), 3.0 - s], np.zeros_like(s))
    y = np.select([s < 1, s < 2, s < 3], [np.zeros_like(s), s - 1.0, np.ones_like(s)], 4.0 - s)
    return np.c_[x, y]


def _three_loops(m: int, rho: float = GOLDEN) -> np.ndarray:
    """A torus of three loops: the points visit three unit circles in turn, turning by rho each iterate."""
    n = np.arange(m)
    th = 2.0 * math.pi * (0.1 + rho * n)
    return np.c_[np.cos(th) + 4.0 * (n % 3), np.sin(th)]


@pytest.mark.parametrize("m", [800, 3200])
def test_order_test_passes_rotations_on_closed_curves_smooth_or_not(m):
    """The golden rotation: the nearest neighbours are two consecutive Fibonacci numbers of iterates away
    (377, 610 on 800 points; 1597, 2584 on 3200).  On the square with corners the three gaps of the
    three-distance theorem (233, 377, 610 / 987, 1597, 2584), where the weighted Birkhoff averages reach
    only 4.2 / 5.0 digits (a smooth circle: 14).  Three loops: three times the gaps of the rotation by
    3 rho on each loop.  The circle approached at r = 0.999 per iterate passes on 800 points."""
    fib = {800: (377, 610), 3200: (1597, 2584)}[m]
    circle = T.order_test(_circle(m))
    assert circle.passed and circle.gaps == fib and circle.n == m
    square = T.order_test(_square(m))
    assert square.passed and square.gaps == (fib[1] - fib[0], *fib)
    assert O.birkhoff_digits(_square(m)) < 5.1 < 13.0 < O.birkhoff_digits(_circle(m))
    loops = T.order_test(_three_loops(m + 1))
    assert loops.passed and all(g % 3 == 0 for g in loops.gaps)
    assert T.order_test(_approached_circle(800)).passed


@pytest.mark.parametrize("n", [200, 800, 3200])
def test_order_test_fails_on_chaos(n):
    """Henon (a = 1.4, b = 0.3) and logistic (r = 4), 50 series each: the nearest neighbours come from
    unrelated times (dozens of distinct index differences); none passes, even with no fewest points
    (measured: 0 of 200 series of each map at N = 200 - 3200)."""
    for k in range(50):
        for pts in (_henon(n, skip=1000 + 37 * k), _logistic(n, skip=1000 + 37 * k)):
            res = T.order_test(pts, min_n=0)
            assert not res.passed and len(res.gaps) > 3


def test_order_test_fewest_points_and_bad_input():
    """Below ``min_n`` points (default 800) a rotation does not pass, although its gaps are those of a
    rotation; NaN rows and fewer than 3 points raise."""
    short = T.order_test(_circle(200))
    assert not short.passed and short.gaps == (89, 144)
    assert T.order_test(_circle(200), min_n=0).passed
    with pytest.raises(ValueError, match="NaN or inf"):
        T.order_test(np.r_[_circle(10), [[np.nan, 0.0]]])
    with pytest.raises(ValueError, match="at least 3 points"):
        T.order_test(_circle(2))


def test_khv_order_test_decides_a_slowly_approached_torus_and_not_chaos():
    """li2013_calibrated, b = 2, e = 5, x1 = 0.56, 800 periods after a transient of 500 from the static
    deflection: the run is still approaching its torus, the plain Birkhoff digits are 0.62 (a chaotic score),
    but the points already visit the torus in the order of a rotation (nearest neighbours 86 and 111 periods
    away; its rotation number 0.3603 has the convergents 31/86 and 40/111).  li2013_route at x1 = 0.80
    (chaos, exponent +0.032): 226 distinct index differences on 800 points."""
    st = SimulationSettings(steps_per_period=128, transient_periods=500, recorded_periods=800)

    def record(name: str, x1: float) -> np.ndarray:
        d = design.load(ROOT / "config" / "designs" / f"{name}.yaml")
        return simulate(point.point_coefficients(d, {"x1": x1, "b": 2.0, "e": 5.0}), st).poincare

    torus = record("li2013_calibrated", 0.56)
    res = T.order_test(torus)
    assert res.passed and res.gaps == (86, 111)
    assert O.birkhoff_digits(torus) < 1.0
    res = T.order_test(record("li2013_route", 0.80))
    assert not res.passed and len(res.gaps) > 100
