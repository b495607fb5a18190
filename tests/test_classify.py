"""Period labels from Poincaré points, on sequences whose answers are known."""

import numpy as np
import pytest

from _oracle import classify_point
from geardyn.label import indicators
from geardyn.runs.bands import bands
from geardyn.runs.spectrum import amplitude_spectrum


@pytest.mark.parametrize("n", [1, 2, 3, 5, 6, 12])
def test_period_n_sequence(n):
    rng = np.random.default_rng(n)
    cycle = rng.normal(size=(n, 6))
    pts = np.tile(cycle, (100 // n + 1, 1))[:100] + 1e-9 * rng.normal(size=(100, 6))  # integration noise
    assert indicators.strict_period(pts) == n


def test_quasi_periodic_circle_is_not_periodic():
    k = np.arange(100)
    theta = 2 * np.pi * k * (np.sqrt(5) - 1) / 2  # irrational rotation number
    pts = np.column_stack([np.cos(theta), np.sin(theta)])
    assert indicators.strict_period(pts) == 0


def test_bands():
    x = np.array([0.1, 0.2, 0.3, 0.4])
    assert bands(x, np.array([1, 1, 0, 5])) == [(0.1, 0.2, 1), (0.3, 0.3, 0), (0.4, 0.4, 5)]


def test_spectrum_of_a_sine_shows_its_amplitude_and_frequency():
    spp = 64
    t = np.arange(100 * spp) / spp  # 100 mesh periods
    x = 3.0 + 2.0 * np.sin(2 * np.pi * 1.0 * t) + 0.5 * np.sin(2 * np.pi * 0.48 * t)
    f, a = amplitude_spectrum(x, spp)
    assert f[np.argmax(a)] == pytest.approx(1.0)
    assert a.max() == pytest.approx(2.0, rel=0.02)  # Hann coherent-gain corrected
    near = (f > 0.4) & (f < 0.56)
    assert f[near][np.argmax(a[near])] == pytest.approx(0.48, abs=0.01)


def test_converging_period_two_counts_as_period_two():
    # a period-2 orbit plus a transient decaying 2 % per period (the weakly damped shaft mode)
    k = np.arange(100)
    cycle = np.where(k % 2 == 0, 1.0, -1.0)
    transient = 0.3 * 0.98**k * np.cos(0.9 * k)
    pts = np.column_stack([cycle + transient, 0.5 * cycle - transient])
    assert indicators.strict_period(pts) == 0  # the return test alone: not yet periodic
    # with the exponent of that decay (log 0.98 per period), rule 5 of the classifier: converging to P2
    lab = classify_point(pts, np.full(100, np.log(0.98)), period=1.0)
    assert (lab.label, lab.period) == (2, 2)


def test_chaotic_logistic_map_is_not_periodic():
    x = np.empty(200)
    x[0] = 0.3
    for i in range(199):
        x[i + 1] = 4.0 * x[i] * (1 - x[i])
    assert indicators.strict_period(x[100:, None]) == 0
