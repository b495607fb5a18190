"""Invariant circles by Newton's method (benchmarks.invariant_circle): an analytic map whose circle, rotation number
and normal multiplier are known, spectral convergence in the number of nodes, and the model's torus just past
the Neimark-Sacker point of li2013_calibrated, checked against the multipliers of the unstable period-1 orbit
inside it and against a long run."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from _oracle import shoot
from benchmarks import invariant_circle as C
from geardyn.khv import design, point
from geardyn.solve.base import Lane
from geardyn.solve.run import simulate_batch
from geardyn.solve.shooting import period_settings

LAM, OMEGA = 0.9, (math.sqrt(5.0) - 1.0) / 2.0


def _planar(eps: float):
    """(x, y, z) -> a circle map on r = 1 (radial multiplier LAM, rotation OMEGA + eps sin), z contracting by 1/2:
    the circle r = 1, z = 0 is invariant with normal radius max(LAM, 1/2) = LAM."""

    def f(xs: np.ndarray) -> np.ndarray:
        x, y, z = xs.T
        r, th = np.hypot(x, y), np.arctan2(y, x)
        r2 = 1.0 + LAM * (r - 1.0) + 0.3 * (r - 1.0) ** 2
        th2 = th + 2.0 * np.pi * OMEGA + eps * np.sin(th)
        return np.stack([r2 * np.cos(th2), r2 * np.sin(th2), 0.5 * z + 0.1 * (r - 1.0)], axis=1)

    def pmap(xs: np.ndarray, jacobian: bool):
        if not jacobian:
            return f(xs), None
        h, jac = 1e-6, np.empty((xs.shape[0], 3, 3))
        for i in range(3):
            e = np.zeros(3)
            e[i] = h
            jac[:, :, i] = (f(xs + e) - f(xs - e)) / (2.0 * h)
        return f(xs), jac

    x, pts = np.array([1.3, 0.0, 0.2]), []
    for _ in range(1500):
        x = f(x[None])[0]
        pts.append(x)
    return pmap, np.array(pts[-600:])


def test_rigid_rotation_circle_rotation_number_and_normal_radius():
    pmap, pts = _planar(0.0)
    c = C.newton_circle(pmap, *C.circle_from_points(pts, 15), tol=1e-12)
    assert c.converged
    assert abs(c.rotation - min(OMEGA, 1.0 - OMEGA)) < 1e-12
    assert np.max(np.abs(np.hypot(c.nodes[:, 0], c.nodes[:, 1]) - 1.0)) < 1e-12
    assert np.max(np.abs(c.nodes[:, 2])) < 1e-12
    assert c.invariance < 1e-12
    assert abs(c.normal_radius - LAM) < 1e-7  # the Jacobians are central differences (error ~ 1e-10)


def test_spectral_convergence_in_the_nodes():
    """A nonlinear rotation (eps = 0.1): the conjugacy is analytic, so the invariance error between the nodes
    falls geometrically with their number; rho and the normal radius do not depend on it."""
    pmap, pts = _planar(0.1)
    circles = [C.newton_circle(pmap, *C.circle_from_points(pts, m), tol=1e-12) for m in (9, 15, 21)]
    inv = [c.invariance for c in circles]
    assert all(c.converged for c in circles)
    assert inv[0] > 1e-7 and inv[1] < inv[0] * 1e-2 and inv[2] < max(inv[1] * 1e-2, 1e-13)
    assert abs(circles[1].rho - circles[2].rho) < 1e-12
    assert all(abs(c.normal_radius - LAM) < 1e-7 for c in circles)
    # the rotation number of the circle map theta -> theta + 2 pi omega + eps sin(theta), counted directly
    th, n = 0.3, 200000
    for _ in range(n):
        th += 2.0 * np.pi * OMEGA + 0.1 * np.sin(th)
    counted = ((th - 0.3) / (2.0 * np.pi * n)) % 1.0
    assert abs(circles[2].rotation - min(counted, 1.0 - counted)) < 1e-4


def test_interpolation_matrices_match_the_fourier_sums():
    m, theta = 21, np.concatenate([np.arange(5) / 21, np.random.default_rng(0).random(50)])
    k = np.arange(-10, 11)
    x = theta[:, None] - np.arange(m)[None, :] / m
    direct = (np.exp(2j * np.pi * k[None, None, :] * x[:, :, None]).sum(axis=2) / m).real
    deriv = ((2j * np.pi * k) * np.exp(2j * np.pi * k[None, None, :] * x[:, :, None])).sum(axis=2).real / m
    assert np.max(np.abs(C.interpolation_matrix(m, theta) - direct)) < 1e-13
    assert np.max(np.abs(C.interpolation_matrix(m, theta, derivative=True) - deriv)) < 1e-12 * np.max(np.abs(deriv))


def test_bad_input_gives_no_circle_and_a_clear_error():
    _, pts = _planar(0.1)
    assert C.circle_from_points(pts[:20], 15) is None  # fewer than 2M points
    bad = pts.copy()
    bad[7, 1] = np.nan
    assert C.circle_from_points(bad, 15) is None
    with pytest.raises(ValueError, match="odd number of nodes"):
        C.interpolation_matrix(16, np.zeros(3))
    diverging = C.newton_circle(lambda x, jac: None, *C.circle_from_points(pts, 15))
    assert not diverging.converged and diverging.status == "diverged"


def test_distance_to_circle():
    pmap, pts = _planar(0.1)
    c = C.newton_circle(pmap, *C.circle_from_points(pts, 21), tol=1e-12)
    on = C.interpolation_matrix(21, np.linspace(0.0, 1.0, 37)) @ c.nodes
    assert np.max(C.distance_to_circle(c.nodes, on)) < 1e-12
    off = on * np.array([1.02, 1.02, 1.0])  # 2 % out, radially (the circle is r = 1)
    assert np.allclose(C.distance_to_circle(c.nodes, off), 0.02, atol=1e-9)


@pytest.fixture(scope="module")
def calibrated():
    return design.load("config/designs/li2013_calibrated.yaml")


def _torus(d, x1: float, periods: int = 3000):
    system = point.point_coefficients(d, {"x1": x1, "b": 2.0, "e": 5.0})
    s = dataclasses.replace(
        point.integration_settings(d), steps_per_period=128, transient_periods=periods, recorded_periods=400
    )
    return system, s, simulate_batch([Lane(system)], s)[0]


def test_model_torus_past_the_neimark_sacker_point(calibrated):
    """li2013_calibrated on the line of Fig. 7 (b = 2, e = 5): the period-1 orbit loses stability through a
    complex pair at x1 = 0.542.  Just past it, at x1 = 0.55, the torus it sheds is found by Newton in a few
    iterations, its rotation number is the pair's angle |arg(mu)| / 2 pi and its normal radius the
    supercritical normal form's 1 - 2 (|mu| - 1), to first order in the distance from the bifurcation."""
    system, s, run = _torus(calibrated, 0.55)
    (c,) = C.find_circles([system], [run.poincare], s, m=21)
    assert c is not None and c.converged and c.iterations <= 6
    assert c.invariance < 5e-6
    orbit = shoot(system, run.final_state, 1, period_settings(s, 1))
    mu = orbit.multipliers[0]
    delta = abs(mu) - 1.0
    assert 0.0 < delta < 1e-3  # just past the bifurcation: the period-1 orbit is weakly unstable
    assert abs(c.rotation - abs(np.angle(mu)) / (2.0 * np.pi)) < 3e-4
    assert abs(c.normal_radius - (1.0 - 2.0 * delta)) < 2e-4
    assert c.normal_radius < 1.0
    # more nodes: the same rotation number and normal radius
    (c41,) = C.find_circles([system], [run.poincare], s, m=41)
    assert abs(c41.rho - c.rho) < 1e-6 and abs(c41.normal_radius - c.normal_radius) < 1e-5
    # the run is still approaching the circle (normal radius 0.999 per period): closer at its end
    d = C.distance_to_circle(c41.nodes, run.poincare)
    assert d[-50:].mean() < 0.9 * d[:50].mean()
    assert d.max() < 5e-3 * max(1.0, float(np.max(np.abs(c41.nodes))))


def test_no_circle_in_chaos(calibrated):
    """A chaotic point of map_x1_e (x1 = 0.622, e = 1.658; exponent 3e-3 per unit time): Newton finds no
    attracting invariant circle that the run lies on."""
    system = point.point_coefficients(calibrated, {"x1": 0.622, "b": 2.0, "e": 1.658})
    s = dataclasses.replace(
        point.integration_settings(calibrated), steps_per_period=128, transient_periods=1000, recorded_periods=400
    )
    run = simulate_batch([Lane(system)], s)[0]
    (c,) = C.find_circles([system], [run.poincare], s, m=41)
    attracting = c is not None and c.converged and c.invariance < 1e-3 and c.normal_radius < 1.0
    on_it = False
    if attracting:
        d = C.distance_to_circle(c.nodes, run.poincare[-200:]) / max(1.0, float(np.max(np.abs(c.nodes))))
        on_it = bool(d.max() <= 1e-3)
    assert not (attracting and on_it)
