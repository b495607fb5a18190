"""Hard cases for the KHV integrators, each checked against something outside the RK4 kernels."""

from __future__ import annotations

import numpy as np
import pytest

import _model_oracle as oracle
from _oracle import linear_floquet
from _paper import li2013_parameters
from geardyn.khv import model
from geardyn.khv.model import Options, dimensionless
from geardyn.solve import SimulationSettings, simulate, warm_up

BASE = dimensionless(li2013_parameters(eps=1.30, k_c=3.1e8, omega_bar=0.9))


def run(c, n=512, trans=0, rec=20, integ="rk4_event", **kw):
    return simulate(
        c, SimulationSettings(integrator=integ, steps_per_period=n, transient_periods=trans, recorded_periods=rec), **kw
    )


@pytest.fixture(scope="module", autouse=True)
def _jit():
    warm_up(BASE)


def test_b0_linear_event_equals_plain_and_floquet_orbit():
    c = BASE.replace(b=0.0)
    fl = linear_floquet(c)
    assert fl.stable and fl.spectral_radius > 0.9  # weakly damped shaft mode: slow decay
    ev = run(c, x0=fl.periodic_state, rec=30)
    pl = run(c, x0=fl.periodic_state, rec=30, integ="rk4")
    # b = 0: no switching surface, both kernels do the same arithmetic (required: agree to 1e-10)
    np.testing.assert_allclose(ev.poincare, pl.poincare, rtol=0, atol=1e-10)
    # started on the Floquet periodic orbit it stays there; RK4 error at 512 steps/period
    # (~1e-8 per period relative to O(50) states, not accumulating on a stable orbit)
    np.testing.assert_allclose(ev.poincare, np.broadcast_to(fl.periodic_state, ev.poincare.shape), rtol=0, atol=1e-7)


def test_e0_parametric_only():
    c = BASE.replace(e=0.0)
    ref = run(c, integ="dop853", rec=10)
    r = run(c, rec=10)
    # 4th order at 512 steps: ~1e-8 (see test_integrators); 1e-7 margin
    np.testing.assert_allclose(r.poincare, ref.poincare, rtol=0, atol=1e-7)
    # e = 0 and constant stiffness: the static deflection is an exact equilibrium
    cm = c.replace(stiffness_mode="mean")
    y0 = model.static_deflection(cm)
    rm = run(cm, rec=5)
    np.testing.assert_allclose(rm.poincare, np.broadcast_to(y0, rm.poincare.shape), rtol=0, atol=1e-10)


def test_lti_matches_analytic_frequency_response():
    for w in (0.5, 0.9, 1.02, 1.6):  # below, near and above the mesh mode (1.02)
        c = BASE.replace(b=0.0, stiffness_mode="mean", omega=w)
        y0 = oracle.lti_response(c, np.array(0.0))
        r = run(c, n=256, rec=10, x0=y0, dense=True)
        exact = oracle.lti_response(c, r.tau)
        # RK4 global error at 256 steps/period on a smooth linear problem: observed <1e-7 of
        # the largest state (worst near the shaft resonances 0.49/0.54); limit 1e-6 of it
        np.testing.assert_allclose(r.states, exact, rtol=0, atol=1e-6 * np.abs(exact).max())


def _grazing_case(delta):
    """Constant stiffness, in contact on the -b side; e set so max x2 = -b + delta (linear orbit)."""
    c = BASE.replace(stiffness_mode="mean", e=1.0)
    lin = c.replace(b=0.0)
    tau = np.linspace(0, c.period, 20001)
    x2 = oracle.lti_response(lin, tau)[:, 1]
    xs = float(np.mean(x2))
    amp1 = (x2.max() - x2.min()) / 2
    e = (delta - xs) / amp1  # amplitude scales with e; static part does not
    c = c.replace(e=e)
    y0 = oracle.lti_response(c.replace(b=0.0), np.array(0.0))
    y0[1] -= c.b  # f = x2 + b in contact on the negative side: shift the linear orbit by -b
    return c, y0


def test_grazing_orbits():
    # barely not touching the dead zone: exactly linear, no events
    c, y0 = _grazing_case(-1e-3)
    r = run(c, n=256, rec=10, x0=y0)
    assert r.n_events == 0
    lin = oracle.lti_response(c.replace(b=0.0), np.arange(1, 11) * c.period)
    lin[:, 1] -= c.b
    # RK4 error at 256 steps: ~1e-9 of the largest state (x3 ~ 80)
    np.testing.assert_allclose(r.poincare, lin, rtol=0, atol=1e-8 * np.abs(lin).max())
    # barely entering it (penetration 1e-2 b_c, i.e. 0.5 % of b, lasting ~0.15 of 7 time units):
    # two events per period, located and converged.  (The reference limits steps to T/128 to
    # see such short excursions; RK4 sees those longer than about one step.)
    c, y0 = _grazing_case(1e-2)
    ref = run(c, x0=y0, rec=10, integ="dop853")
    r = run(c, n=512, x0=y0, rec=10)
    assert r.n_events == ref.n_events == 20
    np.testing.assert_allclose(r.poincare, ref.poincare, rtol=0, atol=1e-7)
    # the orbit stays close to the linear one: the tiny contact losses excite the weakly damped
    # output-shaft mode slightly (observed 2e-4 of max|x|); limit 1e-3 of max|x|
    np.testing.assert_allclose(r.poincare, lin, rtol=0, atol=1e-3 * np.abs(lin).max())


def test_large_te_double_sided_impacts():
    c = BASE.replace(e=40.0, omega=0.9)
    r = run(c, n=512, trans=10, rec=5, dense=True)
    x2 = r.states[:, 1]
    assert x2.max() > c.b and x2.min() < -c.b  # both flanks hit
    assert r.n_events >= 4 * 5
    ref = run(c, trans=10, rec=5, integ="dop853")
    # short horizon (15 periods), 4th order at 512 steps; stretching of nearby orbits allowed x100
    np.testing.assert_allclose(r.poincare, ref.poincare, rtol=0, atol=1e-5)


def test_parametric_instability_is_flagged():
    # printed Eq. (9) with eps = 1.17 < 1.193: k(t) < 0 over part of the period (docs/paper1.md,
    # "The printed form is negative for eps < 1.193")
    p = li2013_parameters(eps=1.17, k_c=3.1e8, omega_bar=1.5)
    c = dimensionless(p, Options(stiffness_form="printed"))
    assert p.stiffness("printed").minimum() < 0
    assert linear_floquet(c).spectral_radius > 1.0  # linear (b = 0) model: unstable
    for integ in ("rk4_event", "rk4"):
        r = run(c, n=128, trans=1500, rec=100, integ=integ)
        assert r.diverged and 0 <= r.diverged_period < 1600
        assert np.all(np.isfinite(r.poincare)) and np.all(np.isfinite(r.final_state))
        # diverged: a component beyond 1e4 times its static deflection (growth, not a large load)
        static = np.abs(c.static_state())
        assert np.any(np.abs(r.final_state) > 1e4 * np.maximum(1.0, static))
    # the corrected form at the same point is stable
    ok = run(dimensionless(p), n=128, trans=500, rec=10)
    assert not ok.diverged


def test_long_run_no_drift():
    r = run(BASE, n=128, trans=20000, rec=100)
    short = run(BASE, n=128, trans=3000, rec=1)
    # weakly damped shaft mode decays e^-0.003 per unit time: gone (<1e-12) after 3000 periods;
    # a periodic orbit must then repeat to round-off, and not move over 17000 more periods
    spread = np.ptp(r.poincare, axis=0).max()
    assert spread < 1e-10
    np.testing.assert_allclose(r.poincare[-1], short.poincare[-1], rtol=0, atol=1e-10)


def test_energy_conserved_in_conservative_variant():
    c = BASE.replace(c_m=0.0, c_DH=0.0, c_VL=0.0, P_D=0.0, P_L=0.0, e=0.0, stiffness_mode="mean")
    y0 = np.array([1.0, 12.0, 5.0, 0.0, 0.0, 0.0])  # large mesh amplitude: crosses both flanks
    errs = []
    for n in (256, 512):
        r = run(c, n=n, rec=100, x0=y0, dense=True)
        assert r.n_events > 100
        E = oracle.energy(c, r.states)
        E0 = oracle.energy(c, y0)
        errs.append(np.abs(E - E0).max() / E0)
    # 4th-order integrator: relative energy error ~ h^4; 1e-7 at 512 steps over 100 periods
    assert errs[1] < 1e-7
    assert errs[0] / errs[1] > 10  # order >= 3.3 in the energy error


def test_contact_ratio_above_two_event_rk4_against_dop853():
    """eps = 2.3: three pairs mesh on [0, 0.3), two on [0.3, 1); the aligned grid and the reference both
    follow the zones, and agree like the two-zone case of eps < 2."""
    c = dimensionless(li2013_parameters(eps=2.3, k_c=3.1e8, omega_bar=0.9))
    ev = run(c, n=512, trans=20, rec=10)
    ref = simulate(c, SimulationSettings(integrator="dop853", transient_periods=20, recorded_periods=10))
    assert not ev.diverged and ev.n_events > 0
    np.testing.assert_allclose(ev.poincare, ref.poincare, atol=1e-6)


def test_a_large_static_deflection_is_not_a_divergence():
    """T_D = T_L = 1e6 N m: the static mesh deflection is about 5e5 um, far above an absolute 1e4 b_c,
    yet the motion is bounded; divergence is judged against the static deflection."""
    c = dimensionless(li2013_parameters(eps=1.30, k_c=3.1e8, omega_bar=0.9, T_D=1e6, T_L=1e6))
    assert np.abs(c.static_state()).max() > 1e5
    r = run(c, n=128, trans=50, rec=10)
    assert not r.diverged
    assert np.abs(r.poincare).max() < 2 * np.abs(c.static_state()).max()  # bounded, near the static state
