"""Response measures (geardyn.solve.response): linear limit, zero excitation, impact classes on constructed
trajectories, bad input; the standard error of the RMS values (batch means) on known answers."""

import dataclasses
import math

import numpy as np
import pytest
import scipy.signal
import scipy.stats

from _oracle import contact_fractions
from geardyn.khv.model import Coefficients
from geardyn.label import Policy
from geardyn.runs.response import frequency_response
from geardyn.solve import SimulationSettings, simulate, simulate_batch
from geardyn.solve.base import Lane, Sums
from geardyn.solve.response import (
    IMPACT_CLASSES,
    ResponseMeasures,
    batch_means_rms_error,
    impact_class,
    measures_of_sums,
    response_measures,
    response_measures_many,
    rms_errors_many,
    static_mesh_force,
)


def _system(**changes):
    """A 3-DOF system of round numbers (mass ratios 2, shafts 0.3 and 0.5 of the mesh stiffness)."""
    base = dict(
        mu_D=2.0, mu_H=2.0, mu_V=2.0, mu_L=3.0, k_DH=0.3, k_VL=0.5, c_DH=0.05, c_VL=0.06, c_m=0.2,
        P_D=3.0, P_L=1.0, b=1.0, e=0.05, phi=0.3, omega=0.8, eps=1.4, stiffness_mode="mean",
        omega_n=1.0, k_mean=1.0,
    )  # fmt: skip
    base.update(changes)
    return Coefficients(**base)


def _linear_rms(c: Coefficients, w: float) -> tuple[float, float]:
    """Analytic steady state of the linear 3-DOF model in contact (kappa = 1): RMS of X_VH and of the mesh
    force F = X_VH + c_m X_VH' (complex amplitudes of (-w^2 + i w C + K) X = (0, e w^2, 0))."""
    m = c.matrices()
    e2 = np.array([0.0, 1.0, 0.0])
    K = m["K"] + np.outer(m["g"], e2)
    C = m["C"] + c.c_m * np.outer(m["g"], e2)
    X = np.linalg.solve(-(w**2) * np.eye(3) + 1j * w * C + K, np.array([0.0, c.e * w**2, 0.0]))
    return abs(X[1]) / math.sqrt(2.0), abs(X[1] * (1.0 + 1j * w * c.c_m)) / math.sqrt(2.0)


def test_linear_limit_matches_the_analytic_frequency_response():
    """Backlash 1 with a preload that keeps the teeth in contact, constant stiffness: the RMS DTE and RMS mesh
    force of the labelled up/down sweep equal the linear model's frequency response within 1e-3 (the RK4
    error at 256 steps per period is ~1e-8; the trapezoidal mean of a periodic signal is spectrally exact)."""
    c = _system()
    w = np.array([0.3, 0.45, 0.7, 0.9, 1.0, 1.1, 1.4, 1.8])
    policy = Policy(SimulationSettings(steps_per_period=256, transient_periods=400, recorded_periods=20))
    ds = frequency_response(c, w, policy, 0.25, 0.05)
    for d in range(2):
        for j, wj in enumerate(w):
            dte, force = _linear_rms(c, wj)
            assert ds.dte_rms.values[d, j] == pytest.approx(dte, rel=1e-3)
            assert ds.force_rms.values[d, j] == pytest.approx(force, rel=1e-3)
    assert np.all(ds.impact_class.values == IMPACT_CLASSES["no_impact"])
    assert np.all(ds.drive_fraction.values == 1.0)
    assert not ds.jump.values.any() and not ds.hysteresis.values.any()
    # the mean force is the static one: the linear response oscillates about the static deflection
    np.testing.assert_allclose(ds.force_mean.values, abs(static_mesh_force(c)), rtol=1e-6)


@pytest.mark.parametrize("mode_kw", [{"stiffness_mode": "mean"}, {"stiffness_mode": "mean", "b": 0.0}])
def test_zero_excitation_gives_dynamic_factor_one(mode_kw):
    """No TE and constant stiffness: the static deflection is an equilibrium, so K_v = 1 and the DTE does not
    move, to the integration error."""
    c = _system(e=0.0, **mode_kw)
    r = response_measures(c, c.static_state(), SimulationSettings(steps_per_period=128), periods=5)
    assert r.dynamic_factor == pytest.approx(1.0, abs=1e-12)
    assert r.force_mean == pytest.approx(abs(r.static_force), rel=1e-12)
    assert r.dte_rms == pytest.approx(0.0, abs=1e-12) and r.dte_pp == pytest.approx(0.0, abs=1e-12)
    assert r.impact_class == "no_impact" and r.drive_fraction == 1.0


def _sine(mean: float, amp: float, n: int = 200, periods: int = 3):
    t = np.linspace(0.0, 2.0 * np.pi * periods, n * periods + 1)
    return mean + amp * np.sin(t), amp * np.cos(t), t[1] - t[0]


def _below(level: float) -> float:
    """Fraction of time a unit sine spends below ``level`` (analytic)."""
    return (math.pi - 2.0 * math.asin(-level)) / (2.0 * math.pi) if abs(level) < 1 else float(level > 1)


@pytest.mark.parametrize(
    ("amp", "expected"), [(1.5, "no_impact"), (3.0, "single_sided"), (5.0, "double_sided")]
)  # fmt: skip
def test_impact_classes_of_constructed_trajectories(amp, expected):
    """x2 = 3 + A sin t with half backlash 1: A = 1.5 stays in drive contact, A = 3 enters the backlash
    (x2 >= 0 > -1), A = 5 strikes the back side.  The fractions equal the analytic times below +1 and -1."""
    x, v, h = _sine(3.0, amp)
    drive, sep, back = contact_fractions(x, v, h, 1.0)
    below_plus, below_minus = _below((1.0 - 3.0) / amp), _below((-1.0 - 3.0) / amp)
    assert back == pytest.approx(below_minus, abs=1e-8)
    assert sep == pytest.approx(below_plus - below_minus, abs=1e-8)
    assert drive == pytest.approx(1.0 - below_plus, abs=1e-8)
    assert impact_class(sep, back) == expected
    # the mirror image (drive side negative) has the same class
    d2, s2, b2 = contact_fractions(-x, -v, h, 1.0, side=-1.0)
    assert (d2, s2, b2) == pytest.approx((drive, sep, back), abs=1e-12)


def test_bad_input_is_flagged_not_nan():
    c = _system()
    r = response_measures(c, np.full(6, np.nan), SimulationSettings(steps_per_period=64), periods=2)
    assert r.impact_class == "diverged" and r.diverged
    with pytest.raises(ValueError, match="periods"):
        response_measures(c, c.static_state(), SimulationSettings(steps_per_period=64), periods=0)
    with pytest.raises(ValueError, match="finite"):
        impact_class(math.nan, 0.0)
    with pytest.raises(ValueError, match="contact_fractions"):
        contact_fractions(np.zeros(3), np.zeros(2), 0.1, 1.0)


def _same(a, b) -> bool:
    """Two measures equal field by field, bit for bit (NaN equal to NaN)."""
    return all(
        u == v or (u != u and v != v) for u, v in zip(dataclasses.astuple(a), dataclasses.astuple(b), strict=True)
    )


def test_a_batch_gives_each_point_its_own_measures_bit_for_bit():
    """The lanes step 8 points together, those of equal length side by side: each point's measures are those
    of the point alone (on the scalar loop), whatever its neighbours (other TE, periods 1 to 40, a start that
    diverges, one that is not finite, more points than a lockstep block)."""
    settings = SimulationSettings(integrator="rk4_event", steps_per_period=64)
    systems = [_system(e=e, b=0.5) for e in (0.05, 0.8, 1.5, 2.5, 0.3, 1.1, 3.0, 0.6, 2.0, 0.9, 1.8)]
    starts = [s.static_state() for s in systems]
    starts[3] = np.full(6, 1e9)  # beyond the divergence limits: diverges in its first period
    starts[5] = np.full(6, np.nan)
    periods = [1, 40, 3, 2, 40, 1, 17, 40, 5, 2, 40]
    many = response_measures_many(systems, starts, settings, periods)
    alone = [response_measures(s, y, settings, n) for s, y, n in zip(systems, starts, periods, strict=True)]
    assert all(_same(a, b) for a, b in zip(many, alone, strict=True))
    assert many[3].diverged and many[5].diverged and not any(m.diverged for k, m in enumerate(many) if k not in (3, 5))
    assert {m.impact_class for m in many} >= {"no_impact", "double_sided"}


def test_measures_equal_the_dense_trajectory_reduced_in_numpy():
    """The sums added in the lanes equal the same record of :func:`simulate`'s dense output reduced in numpy:
    trapezoidal means and RMS of the DTE and of the drive-side mesh force s (f(x2) + c_m x2') (constant
    stiffness), the extremes on the step grid, and the contact fractions (uniform steps: the grid not
    aligned)."""
    c = _system(e=1.5, b=0.5, omega=1.2)  # double-sided impacts: 4 contact switches per period
    settings = SimulationSettings(
        integrator="rk4_event", steps_per_period=128, aligned=False, transient_periods=0, recorded_periods=30
    )
    y0 = simulate(c, dataclasses.replace(settings, transient_periods=5)).final_state  # still a transient
    run = simulate(c, settings, x0=y0, dense=True)
    r = response_measures(c, y0, settings, 30)
    assert r.impact_class == "double_sided" and r.n_switches > 30
    x = np.concatenate([[y0[1]], run.states[:, 1]])
    v = np.concatenate([[y0[4]], run.states[:, 4]])
    h = c.period / 128
    side = math.copysign(1.0, static_mesh_force(c))  # the drive side: negative for this preload
    force = side * (x - np.clip(x, -c.b, c.b) + c.c_m * v)

    def mean_rms(f):
        d = f - f[0]
        m = np.trapezoid(d, dx=h) / (h * (f.size - 1))
        return f[0] + m, math.sqrt(np.trapezoid(d * d, dx=h) / (h * (f.size - 1)) - m * m)

    assert (r.dte_mean, r.dte_rms) == pytest.approx(mean_rms(x), rel=1e-12, abs=1e-13)
    assert (r.force_mean, r.force_rms) == pytest.approx(mean_rms(force), rel=1e-12, abs=1e-13)
    assert r.dte_pp == np.ptp(x) and r.force_max == np.max(force)
    fractions = (r.drive_fraction, r.separation_fraction, r.back_fraction)
    assert fractions == pytest.approx(contact_fractions(x, v, h, c.b, side), abs=1e-13)


def _blocks(x: np.ndarray, nb: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Equal blocks of the samples x: durations, means and RMS about each block's own mean."""
    parts = np.array_split(x, nb)
    return (
        np.array([p.size for p in parts], float),
        np.array([p.mean() for p in parts]),
        np.array([p.std() for p in parts]),
    )


def test_rms_error_of_white_noise_is_sigma_over_sqrt_2n():
    """Independent Gaussian samples of standard deviation s: the RMS of N of them has the standard error
    s / sqrt(2 N) (the chi distribution).  Batch means over 100 blocks agree within 25 % (the estimate's own
    scatter is 1 / sqrt(2 x 99) = 7 %)."""
    rng = np.random.default_rng(7)
    n, s = 100_000, 2.5
    x = 3.0 + s * rng.standard_normal(n)
    se = batch_means_rms_error(*_blocks(x, 100))
    assert se == pytest.approx(s / math.sqrt(2 * n), rel=0.25)


def test_rms_error_of_a_quasi_periodic_signal_covers_its_known_mean_square():
    """x(t) = 3 cos t + 2 cos(g t), g the golden mean: its RMS over infinite time is sqrt((9 + 4) / 2).  Over
    records of 500 and 5000 time units the RMS lies within 3 standard errors of it, and the error falls as
    the record grows (a quasi-periodic average converges like 1 / T: ten times the record, a tenth of the
    error, within a factor 3)."""
    g = (1.0 + math.sqrt(5.0)) / 2.0
    exact = math.sqrt((9.0 + 4.0) / 2.0)
    errors = []
    for length in (500.0, 5000.0):
        t = np.arange(0.0, length, 0.05)
        x = 3.0 * np.cos(t) + 2.0 * np.cos(g * t)
        se = batch_means_rms_error(*_blocks(x, 10))
        assert 0.0 < se < 0.05 * exact
        assert abs(x.std() - exact) <= 3.0 * se
        errors.append(se)
    assert errors[1] < errors[0] / 3.0


def test_rms_error_covers_the_difference_of_two_independent_records_as_often_as_it_should():
    """A Gaussian AR(1) process x_k = phi x_(k-1) + noise, of unit variance: the RMS of N samples has the
    standard error sqrt((1 + phi^2) / (2 N (1 - phi^2))) (the variance of x^2 summed over its correlations
    phi^(2k)).  Over 1000 pairs of independent records of N = 4000 samples, 10 blocks each: the errors' root
    mean square is that within 2 % (4 of its own standard deviations), and |RMS1 - RMS2| <= 1.96 sqrt(SE1^2 +
    SE2^2) as often as a t variable of 18 degrees of freedom (two errors of 9 each) is within +-1.96, 93.4 %:
    within 3.3 binomial standard deviations (0.8 %) of it."""
    phi, n, pairs, blocks = 0.6, 4000, 1000, 10
    rng = np.random.default_rng(2024)
    noise = rng.standard_normal((2 * pairs, n)) * math.sqrt(1.0 - phi * phi)
    noise[:, 0] = rng.standard_normal(2 * pairs)  # stationary from the first sample
    x = 1.5 + scipy.signal.lfilter([1.0], [1.0, -phi], noise, axis=1)
    parts = x.reshape(2 * pairs, blocks, n // blocks)
    means, rms = parts.mean(axis=2), parts.std(axis=2)
    se = np.array([batch_means_rms_error(np.ones(blocks), m, r) for m, r in zip(means, rms, strict=True)])
    exact = math.sqrt((1.0 + phi * phi) / (2.0 * n * (1.0 - phi * phi)))
    assert math.sqrt(np.mean(se**2)) == pytest.approx(exact, rel=0.02)
    total = x.std(axis=1)
    covered = np.abs(total[0::2] - total[1::2]) <= 1.96 * np.hypot(se[0::2], se[1::2])
    expected = 2.0 * scipy.stats.t.cdf(1.96, 2 * (blocks - 1)) - 1.0
    assert expected == pytest.approx(0.934, abs=1e-3)
    assert abs(np.mean(covered) - expected) <= 3.3 * math.sqrt(expected * (1.0 - expected) / pairs)


def _record(c: Coefficients, settings: SimulationSettings, x0: np.ndarray | None = None):
    """A record of ``settings`` (transient, then the recorded periods) from x0: its Poincare points and the
    measures summed over its recorded periods (as the labeller's runs sum them)."""
    (r,) = simulate_batch([Lane(c, x0, sums=Sums(settings.recorded_periods))], settings)
    return r.poincare, measures_of_sums(r.sums, c, settings.recorded_periods)


def test_rms_error_of_a_periodic_orbit_is_zero():
    """On a periodic orbit every block of whole periods is the same record: the error is 0 to rounding (the
    linear model's orbit, reached after 400 periods)."""
    c = _system()
    settings = SimulationSettings(steps_per_period=128, transient_periods=400, recorded_periods=40)
    points, r = _record(c, settings)
    (e,) = rms_errors_many([c], [points], [r], settings)
    assert e.blocks == 10 and r.dte_rms > 0.01
    assert e.dte_rms_error <= 1e-12 * r.dte_rms and e.force_rms_error <= 1e-12 * r.force_rms


def test_rms_error_is_batch_means_of_the_record_itself():
    """The blocks are the record's own: the error of a record's RMS equals batch means of :func:`simulate`'s
    dense output of that record over the same blocks (3 periods each of a 30-period transient with impacts,
    reduced in numpy with the trapezoidal rule; constant stiffness, uniform steps), the first block's share
    taken from the record's sums, the others integrated again from its Poincare points."""
    c = _system(e=1.5, b=0.5, omega=1.2)
    settings = SimulationSettings(
        integrator="rk4_event", steps_per_period=128, aligned=False, transient_periods=0, recorded_periods=30
    )
    y0 = simulate(c, dataclasses.replace(settings, transient_periods=5)).final_state
    run = simulate(c, settings, x0=y0, dense=True)
    x = np.concatenate([[y0[1]], run.states[:, 1]])
    means, rms = [], []
    for k in range(10):
        seg = x[k * 3 * 128 : (k + 1) * 3 * 128 + 1]
        m = np.trapezoid(seg) / (seg.size - 1)
        means.append(m)
        rms.append(math.sqrt(np.trapezoid((seg - m) ** 2) / (seg.size - 1)))
    expected = batch_means_rms_error(np.full(10, 3.0), np.array(means), np.array(rms))
    points, r = _record(c, settings, y0)
    assert np.array_equal(points, run.poincare)
    (e,) = rms_errors_many([c], [points], [r], settings)
    assert expected > 1e-4  # a transient: the blocks differ, and a record from its end would differ again
    assert e.dte_rms_error == pytest.approx(expected, rel=1e-9)
    # only the measured periods' points are read: a record that holds older points too gives the same
    assert rms_errors_many([c], [np.vstack([np.zeros((5, 6)), points])], [r], settings) == [e]


def test_rms_error_bad_input():
    c = _system()
    settings = SimulationSettings(steps_per_period=64, transient_periods=20, recorded_periods=20)
    points, r = _record(c, settings)
    one, bad = rms_errors_many(
        [c, c], [points, points], [dataclasses.replace(r, periods=1), ResponseMeasures.not_computed()], settings
    )
    assert one.blocks == 1 and math.isnan(one.dte_rms_error)  # one period: no batch means
    assert math.isnan(bad.dte_rms_error) and math.isnan(bad.force_rms_error)  # a diverged record
    with pytest.raises(ValueError, match="Poincare points"):  # fewer points than measured periods
        rms_errors_many([c], [points[:10]], [r], settings)
    with pytest.raises(ValueError, match="at least 2 blocks"):
        rms_errors_many([c], [points], [r], settings, blocks=1)
    with pytest.raises(ValueError, match="batch means"):
        batch_means_rms_error(np.ones(1), np.ones(1), np.ones(1))
