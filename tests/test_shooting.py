"""Shooting on the stroboscopic map: monodromy, multipliers, period doubling of a classical oscillator.

Reference values (docs/orbits.md, "Validation"):

* Duffing double well x'' + 0.3 x' - x + x^3 = gamma cos(1.2 t), period-1 orbit of one well:
  period doubling at gamma_PD = 0.265581786 (scipy DOP853 rtol 1e-12 with the variational
  equations, periodic orbit by scipy.optimize.fsolve, det(M + I) = 0 by brentq); brute-force
  DOP853 runs of 3000 periods show P1 at gamma_PD - 5e-4 (|p_{k+1} - p_k| = 4e-10) and P2 at
  gamma_PD + 5e-4 (0.065).
"""

import math
from pathlib import Path

import numba
import numpy as np
import pytest
from numba import njit

from _oracle import fd_monodromy, linear_floquet, linear_part, rk4_flow, shoot
from _orbits import CallableFamily
from geardyn.khv import design, point
from geardyn.runs.continuation import ContinuationSettings, continue_branch, switch_at_period_doubling
from geardyn.solve import SimulationSettings, simulate
from geardyn.solve.base import Lane, Monodromy, ShootingSettings
from geardyn.solve.shooting import Shot, khv_flow, khv_flows, newton_shooting, newton_shooting_batch

ROOT = Path(__file__).resolve().parents[1]
GAMMA_PD = 0.265581786  # see the module docstring
DUFFING_DELTA, DUFFING_OMEGA = 0.3, 1.2


@pytest.fixture(scope="module")
def li2013():
    return design.load(ROOT / "config" / "designs" / "li2013.yaml")


@pytest.fixture(scope="module")
def contact_loss_orbit(li2013):
    c = point.point_coefficients(li2013, {"x1": 0.5, "b": 2.0, "e": 5.0, "w": 0.9})
    r = simulate(c, SimulationSettings(transient_periods=1500, recorded_periods=1))
    orbit = shoot(c, r.final_state)
    return c, orbit


def test_orbit_converges_and_loses_contact(contact_loss_orbit):
    c, orbit = contact_loss_orbit
    assert orbit.converged and orbit.status == "converged"
    assert orbit.residual <= 1e-9 * np.max(np.abs(orbit.state))
    dense = simulate(c, SimulationSettings(transient_periods=0, recorded_periods=1), orbit.state, dense=True)
    x2 = dense.states[:, 1]
    # the orbit crosses the backlash zone: contact is lost (|x_VH| <= b) and regained every period
    assert np.min(np.abs(x2)) <= c.b
    assert dense.n_events >= 2
    assert orbit.stable  # measured spectral radius 0.981


def test_variational_monodromy_matches_finite_differences(contact_loss_orbit):
    """The saltation matrix of a contact switch is the identity (continuous contact force): the
    variational monodromy equals the finite-difference derivative of the event-located map."""
    c, orbit = contact_loss_orbit
    flow = khv_flow(c, 1)
    _, M = flow(orbit.state, True)
    M_fd = fd_monodromy(flow, orbit.state, h=1e-5)
    rel = np.max(np.abs(M - M_fd)) / np.max(np.abs(M))
    assert rel < 1e-6  # measured 1.8e-8
    mu_fd = np.sort_complex(np.linalg.eigvals(M_fd))
    mu = np.sort_complex(orbit.multipliers)
    assert np.max(np.abs(mu - mu_fd)) < 1e-6


def test_monodromy_columns_are_the_single_column_runs_bit_for_bit(contact_loss_orbit):
    """The 6 columns of the monodromy matrix are stepped together in one buffer (vectorised); each is the
    same arithmetic as one tangent column carried alone: the same bits, contact switches included."""
    from geardyn.solve import _kernel  # noqa: PLC0415
    from geardyn.solve.run import simulate_batch, step_tables  # noqa: PLC0415

    c, orbit = contact_loss_orbit
    s = SimulationSettings(transient_periods=0, recorded_periods=3)
    full = simulate(c, s, orbit.state, variational=Monodromy(3))
    assert full.n_events >= 6  # the run crosses the backlash zone
    (lane,) = simulate_batch([Lane(c, orbit.state, variational=Monodromy(3))], s)
    assert np.array_equal(lane.monodromy, full.monodromy)
    cols = np.empty((6, 6))
    for i in range(6):
        W = np.zeros((6, 1))
        W[i, 0] = 1.0
        k, *tabs = (np.array(a) for a in step_tables(c, s.steps_per_period))
        # fmt: off
        _kernel.run(k, tuple(tabs), orbit.state.copy(), 0, 3, True, np.full(6, np.inf), 1, np.empty((3, 6)),
                    np.empty(0), np.empty((0, 6)), W, 3, False, np.empty(0), np.empty(0), np.empty(6),
                    _kernel.NO_EARLY_STOP, np.empty(0), 0.0, 0)
        # fmt: on
        cols[:, i] = W[:, 0]
    assert np.array_equal(cols, full.monodromy)


def test_period2_monodromy_is_square_of_period1(contact_loss_orbit):
    c, orbit = contact_loss_orbit
    two = shoot(c, orbit.state, n=2)
    assert two.converged
    np.testing.assert_allclose(two.monodromy, orbit.monodromy @ orbit.monodromy, atol=1e-8)


def test_linear_model_matches_dop853_floquet(li2013):
    c = linear_part(point.point_coefficients(li2013, {"x1": 0.5, "e": 5.0}))
    ref = linear_floquet(c)
    orbit = shoot(c, c.static_state())
    assert orbit.converged
    np.testing.assert_allclose(orbit.state, ref.periodic_state, atol=1e-6 * np.max(np.abs(ref.periodic_state)))
    mu_ref = np.sort_complex(ref.multipliers)
    mu = np.sort_complex(orbit.multipliers)
    assert np.max(np.abs(mu - mu_ref)) < 1e-6  # RK4 with 512 steps: measured 2e-9


def test_non_convergence_is_flagged(contact_loss_orbit):
    c, orbit = contact_loss_orbit
    r = shoot(c, orbit.state + 5.0, max_iter=1)
    assert not r.converged and r.status == "max_iterations"
    assert np.all(np.isfinite(r.state)) and np.isfinite(r.residual)

    def diverging(x, jacobian=True):
        return None, None

    r = newton_shooting(diverging, np.zeros(2))
    assert not r.converged and r.status == "diverged"


def test_batch_shooting_is_point_shooting_bit_for_bit(li2013, contact_loss_orbit):
    """newton_shooting_batch integrates the unfinished points together; each point's iterates, status and
    multipliers must be those of shoot() alone, whatever its neighbours (converged in a few iterations,
    stopped at max_iter, period 2, another design point)."""
    c, orbit = contact_loss_orbit
    c2 = point.point_coefficients(li2013, {"x1": 0.761, "b": 2.0, "e": 5.0, "w": 0.7})
    settings = SimulationSettings(steps_per_period=128)
    cases = [(c, orbit.state + 1e-3, 1), (c, orbit.state + 5.0, 1), (c2, c2.static_state(), 1), (c, orbit.state, 2)]
    for n in (1, 2):
        todo = [(s, x) for s, x, m in cases if m == n]
        for max_iter in (2, 15):
            batch = newton_shooting_batch(
                [Shot(s, x) for s, x in todo], n, settings, ShootingSettings(max_iter=max_iter)
            )
            for (s, x), b in zip(todo, batch, strict=True):
                a = shoot(s, x, n, settings, max_iter=max_iter)
                assert (a.status, a.iterations, a.converged) == (b.status, b.iterations, b.converged)
                np.testing.assert_array_equal(a.state, b.state)
                np.testing.assert_array_equal(a.multipliers, b.multipliers)
    statuses = {
        b.status
        for b in newton_shooting_batch([Shot(s, x) for s, x, _ in cases[:3]], 1, settings, ShootingSettings(max_iter=2))
    }
    assert statuses == {"converged", "max_iterations"}  # the test covers both endings
    # the growth stop: on the torus of li2013_calibrated at x1 = 0.56 no period-25 cycle exists and the residual
    # grows; the P1 orbit converges
    cal = design.load(ROOT / "config" / "designs" / "li2013_calibrated.yaml")
    ct = point.point_coefficients(cal, {"x1": 0.56, "b": 2.0, "e": 5.0})
    on_torus = simulate(ct, SimulationSettings(transient_periods=500, recorded_periods=1)).final_state
    for n, todo, ends in ((25, [(ct, on_torus), (c, orbit.state + 5.0)], ["residual_grows", "converged"]),):
        batch = newton_shooting_batch(
            [Shot(s, x) for s, x in todo], n, settings, ShootingSettings(max_iter=15, max_growth=2.0)
        )
        for (s, x), b in zip(todo, batch, strict=True):
            a = shoot(s, x, n, settings, max_iter=15, max_growth=2.0)
            assert (a.status, a.iterations, a.converged) == (b.status, b.iterations, b.converged)
            np.testing.assert_array_equal(a.state, b.state)
        assert [b.status for b in batch] == ends
    # the stop is what ends the torus's search: without it the search runs to its limit, unconverged
    assert shoot(ct, on_torus, 25, settings, max_iter=15).status == "max_iterations"


def test_newton_gives_up_when_its_residual_grows() -> None:
    """F(x) = x^2 + 1 has no real root: from x0 = 0.1 Newton's first step goes to -4.95 and the residual grows
    from 1.01 to 25.5; with max_growth = 2 the search stops there, without it runs to max_iter."""

    def flow(x, jacobian=True):
        return x + x**2 + 1.0, (np.eye(1) + np.diag(2.0 * x) if jacobian else None)

    stop = newton_shooting(flow, np.array([0.1]), max_iter=20, max_growth=2.0)
    assert (stop.status, stop.iterations, stop.converged) == ("residual_grows", 1, False)
    assert stop.state[0] == pytest.approx(0.1 - 1.01 / 0.2, rel=1e-15)
    assert stop.residual == pytest.approx(stop.state[0] ** 2 + 1.0, rel=1e-15)
    assert newton_shooting(flow, np.array([0.1]), max_iter=20).status == "max_iterations"
    # a root is found as before: F(x) = x^2 - 1 from 3 falls every iteration
    ok = newton_shooting(
        lambda x, j=True: (x + x**2 - 1.0, np.eye(1) + np.diag(2.0 * x)), np.array([3.0]), max_growth=2.0
    )
    assert ok.converged and ok.state[0] == pytest.approx(1.0, abs=1e-9)


def duffing_family(steps=200):
    d, w = DUFFING_DELTA, DUFFING_OMEGA

    def flow_of(g, n):
        def rhs(t, y):
            return np.array([y[1], g * math.cos(w * t) - d * y[1] + y[0] - y[0] ** 3])

        def jac(t, y):
            return np.array([[0.0, 1.0], [1.0 - 3.0 * y[0] ** 2, -d]])

        return rk4_flow(rhs, jac, 2 * math.pi / w, steps, n)

    return CallableFamily(flow_of)


def test_duffing_period_doubling_located():
    fam = duffing_family()
    flow = fam.flow(0.2, 1)
    x = np.array([0.1, 0.0])
    for _ in range(200):
        x, _ = flow(x, False)
    br = continue_branch(fam, 0.2, x, 1, 0.2, 0.3, ContinuationSettings(ds=0.02, ds_max=0.02))
    pds = [b for b in br.bifurcations if b.kind == "period_doubling"]
    assert len(pds) == 1
    pd = pds[0]
    assert pd.located
    assert abs(pd.p - GAMMA_PD) < 1e-3  # measured 1.2e-9 (RK4, 200 steps per period)
    assert abs(pd.critical - (-1.0)) < 1e-6
    # stable before, unstable after
    assert br.stable[br.p < pd.p - 1e-3].all() and not br.stable[br.p > pd.p + 1e-3].any()


@njit(cache=True)
def _duffing_returns(gamma, periods, steps):
    """|x_{k+1} - x_k| of the stroboscopic x over the last 20 periods: a long run, one period at a time,
    with the RK4 of :func:`_duffing_map` (no shooting)."""
    y = np.array([0.568, 0.4127])
    last = np.empty(21)
    for per in range(periods):
        y, _ = _duffing_map(gamma, y, 1, steps, False)
        if per >= periods - 21:
            last[per - periods + 21] = y[0]
    return np.max(np.abs(np.diff(last)))


def test_duffing_period_doubling_bracketed_by_brute_force_simulation():
    # independent of shooting: long runs on either side of the reference value
    assert _duffing_returns(GAMMA_PD - 1e-3, 3000, 200) < 1e-6
    assert _duffing_returns(GAMMA_PD + 1e-3, 3000, 200) > 1e-2


@njit(cache=True)
def _duffing_map(gamma, y0, n, steps, want_jac):
    """n-period map of the double-well Duffing oscillator and its 2 x 2 derivative (numba RK4 with
    the variational equations, the same scheme as ``tests/_oracle.rk4_flow``)."""
    d, w = 0.3, 1.2
    h = 2 * math.pi / w / steps
    x, v = y0[0], y0[1]
    Y = np.eye(2)
    for k in range(n * steps):
        t = k * h
        a1 = gamma * math.cos(w * t) - d * v + x - x**3
        x2, v2 = x + 0.5 * h * v, v + 0.5 * h * a1
        a2 = gamma * math.cos(w * (t + 0.5 * h)) - d * v2 + x2 - x2**3
        x3, v3 = x + 0.5 * h * v2, v + 0.5 * h * a2
        a3 = gamma * math.cos(w * (t + 0.5 * h)) - d * v3 + x3 - x3**3
        x4, v4 = x + h * v3, v + h * a3
        if want_jac:
            J1 = np.array([[0.0, 1.0], [1.0 - 3 * x * x, -d]])
            J2 = np.array([[0.0, 1.0], [1.0 - 3 * x2 * x2, -d]])
            J3 = np.array([[0.0, 1.0], [1.0 - 3 * x3 * x3, -d]])
            J4 = np.array([[0.0, 1.0], [1.0 - 3 * x4 * x4, -d]])
            K1 = J1 @ Y
            K2 = J2 @ (Y + 0.5 * h * K1)
            K3 = J3 @ (Y + 0.5 * h * K2)
            K4 = J4 @ (Y + h * K3)
            Y = Y + h / 6 * (K1 + 2 * K2 + 2 * K3 + K4)
        a4 = gamma * math.cos(w * (t + h)) - d * v4 + x4 - x4**3
        x += h / 6 * (v + 2 * v2 + 2 * v3 + v4)
        v += h / 6 * (a1 + 2 * a2 + 2 * a3 + a4)
    return np.array([x, v]), Y


def fast_duffing_family(steps=200):
    def flow_of(g, n):
        def flow(x, jacobian=True):
            y, Y = _duffing_map(g, np.asarray(x, dtype=float), n, steps, jacobian)
            return y, (Y if jacobian else None)

        return flow

    return CallableFamily(flow_of)


def test_duffing_cascade_by_branch_switching():
    """P1 -> P2 at 0.2655818, P2 -> P4 at 0.2866932 (scipy DOP853 + fsolve + brentq on the 2-period
    map: 0.286693157824; measured here 0.2866931603)."""

    fam = fast_duffing_family()
    x = np.array([0.1, 0.0])
    for _ in range(200):
        x, _ = fam.flow(0.2, 1)(x, False)
    cs = ContinuationSettings(ds=0.02, ds_max=0.02)
    br = continue_branch(fam, 0.2, x, 1, 0.2, 0.3, cs)
    pd1 = next(b for b in br.bifurcations if b.kind == "period_doubling")
    assert abs(pd1.p - GAMMA_PD) < 1e-6
    p2 = switch_at_period_doubling(fam, pd1, 0.2, 0.3, cs)
    assert p2 is not None and p2.n == 2
    assert p2.stable[p2.p < 0.28].all()
    pd2 = [b for b in p2.bifurcations if b.kind == "period_doubling"]
    assert len(pd2) == 1 and pd2[0].n == 2
    assert abs(pd2[0].p - 0.286693158) < 1e-3  # measured 2.4e-9


def test_singular_newton_matrix_is_reported_not_raised():
    """phi(x) = x + (1, 2) with M = I: M - I is singular, so Newton stops at once with status
    'singular', the residual 2 and the multipliers of M (1, 1); a map with a regular M converges."""
    r = newton_shooting(lambda x, jac: (x + np.array([1.0, 2.0]), np.eye(2)), np.zeros(2))
    assert (r.status, r.converged, r.iterations, r.residual) == ("singular", False, 0, 2.0)
    np.testing.assert_array_equal(np.abs(r.multipliers), [1.0, 1.0])
    half = newton_shooting(lambda x, jac: (0.5 * x + 1.0, 0.5 * np.eye(2)), np.zeros(2))
    assert half.converged and half.iterations == 1
    np.testing.assert_allclose(half.state, [2.0, 2.0], rtol=0, atol=1e-15)


def test_batched_flows_are_the_single_flows_bit_for_bit(li2013, contact_loss_orbit):
    """khv_flows (one kernel call for many orbits, the continuation's corrector) gives each (system, x) the
    numbers of khv_flow alone, with or without the monodromy, whatever its neighbours: a period-2 map, another
    design point, a diverging start ((None, None))."""
    c, orbit = contact_loss_orbit
    c2 = point.point_coefficients(li2013, {"x1": 0.761, "b": 2.0, "e": 5.0, "w": 0.7})
    settings = SimulationSettings(steps_per_period=128)
    threads = numba.get_num_threads()
    for n in (1, 2):
        cases = [
            (c, orbit.state, True),
            (c2, c2.static_state(), False),
            (c, orbit.state + 1e9, True),
            (c2, orbit.state, True),
        ]
        batch = khv_flows([s for s, _, _ in cases], [x for _, x, _ in cases], n, [j for _, _, j in cases], settings)
        for (s, x, j), (phi, M) in zip(cases, batch, strict=True):
            phi1, M1 = khv_flow(s, n, settings)(x, j)
            assert (phi is None) == (phi1 is None) and (M is None) == (M1 is None)
            if phi1 is not None:
                np.testing.assert_array_equal(phi, phi1)
            if M1 is not None:
                np.testing.assert_array_equal(M, M1)
        assert batch[2] == (None, None) and batch[1][1] is None and batch[0][1] is not None
    assert numba.get_num_threads() == threads  # the batch's one thread given back
