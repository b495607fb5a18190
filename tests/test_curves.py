"""Regime boundaries as curves (two-parameter continuation), against numbers computed outside the code.

* Linear limit: li2013 with the mean mesh stiffness (``stiffness_mode: mean``) is linear and time-invariant
  while the teeth stay in contact, so its grazing curve in (w, e) is e_g(w) = (|x_s| - b) / |H(w)|
  (docs/orbits.md, "Regime boundaries as curves"); measured relative error 5.0e-8 at 20 frequencies and
  5.7e-8 at the 79 points of the curve (limit 1e-6).
* Smooth oscillator: the period-doubling curve of the double-well Duffing oscillator
  x'' + 0.3 x' - x + x^3 = gamma cos(omega t) in (gamma, omega) against scipy's DOP853 (rtol 1e-12)
  multipliers, det(M + I) = 0 located by brentq over gamma at three omega; the cusp of the fold curve of
  a hardening Duffing oscillator against one-parameter sweeps on either side of it.
* Crossing with a sweep: the Neimark-Sacker curve of li2013_calibrated in (x1, e) through the point of the
  Fig. 7 sweep (b = 2, e = 5, x1 = 0.54203) against one-parameter continuations along x1 at other e.
"""

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from numba import njit
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from _orbits import CallableFamily, cycle_of
from geardyn import io
from geardyn.config import schema as io_schema
from geardyn.io import provenance
from geardyn.khv import design, model, point
from geardyn.label import vocabulary
from geardyn.plots import curves as plots_curves
from geardyn.runs import continuation as C
from geardyn.runs import maps
from geardyn.runs.continuation import boundaries, curve_check, curve_maps, pixel_probe, pixel_samples
from geardyn.runs.continuation.family import back_margin
from geardyn.runs.continuation.problem import CurveProblem, condition
from geardyn.solve import SimulationSettings, simulate
from geardyn.solve.bifurcations import CODES, decode
from geardyn.solve.shooting import newton_shooting

ROOT = Path(__file__).resolve().parents[1]
CHECK = pixel_samples.CheckSettings(every=1)


# --- a smooth oscillator as a two-parameter family ------------------------------------------------------


@njit(cache=True)
def _duffing_map(delta, alpha, beta, gamma, omega, y0, n, steps, want_jac):
    """n-period map of x'' + delta x' + alpha x + beta x^3 = gamma cos(omega t) and its 2 x 2 derivative
    (classical RK4 with the variational equations by the same stages)."""
    h = 2 * math.pi / omega / steps
    x, v = y0[0], y0[1]
    Y = np.eye(2)
    for k in range(n * steps):
        t = k * h
        a1 = gamma * math.cos(omega * t) - delta * v - alpha * x - beta * x**3
        x2, v2 = x + 0.5 * h * v, v + 0.5 * h * a1
        a2 = gamma * math.cos(omega * (t + 0.5 * h)) - delta * v2 - alpha * x2 - beta * x2**3
        x3, v3 = x + 0.5 * h * v2, v + 0.5 * h * a2
        a3 = gamma * math.cos(omega * (t + 0.5 * h)) - delta * v3 - alpha * x3 - beta * x3**3
        x4, v4 = x + h * v3, v + h * a3
        if want_jac:
            K1 = np.array([[0.0, 1.0], [-alpha - 3 * beta * x * x, -delta]]) @ Y
            K2 = np.array([[0.0, 1.0], [-alpha - 3 * beta * x2 * x2, -delta]]) @ (Y + 0.5 * h * K1)
            K3 = np.array([[0.0, 1.0], [-alpha - 3 * beta * x3 * x3, -delta]]) @ (Y + 0.5 * h * K2)
            K4 = np.array([[0.0, 1.0], [-alpha - 3 * beta * x4 * x4, -delta]]) @ (Y + h * K3)
            Y = Y + h / 6 * (K1 + 2 * K2 + 2 * K3 + K4)
        a4 = gamma * math.cos(omega * (t + h)) - delta * v4 - alpha * x4 - beta * x4**3
        x += h / 6 * (v + 2 * v2 + 2 * v3 + v4)
        v += h / 6 * (a1 + 2 * a2 + 2 * a3 + a4)
    return np.array([x, v]), Y


class DuffingPlane:
    """The Duffing oscillator over (p, q) = (gamma, omega) or (omega, gamma): what curve continuation
    needs of a family (box, flow(p, q, n), grazing)."""

    def __init__(self, delta, alpha, beta, box, names=("gamma", "omega"), steps=400):
        self.coef, self.box, self.names, self.steps = (delta, alpha, beta), box, names, steps

    def flow(self, p, q, n):
        gamma, omega = (p, q) if self.names == ("gamma", "omega") else (q, p)

        def f(x, jacobian=True):
            y, Y = _duffing_map(*self.coef, gamma, omega, np.asarray(x, dtype=float), n, self.steps, jacobian)
            if not np.all(np.isfinite(y)) or np.max(np.abs(y)) > 1e6:
                return None, None
            return y, (Y if jacobian else None)

        return f

    def grazing(self, p, q, x, n):
        return float("nan")

    def cycle(self, p, q, x, n):
        return cycle_of(self.flow(p, q, 1), x, n)

    def along_p(self, q):
        """The one-parameter family along p at q (for :func:`continue_branch`)."""
        return CallableFamily(lambda p, n: self.flow(p, q, n))


def _attractor(flow, x, periods):
    for _ in range(periods):
        x, _ = flow(x, False)
    return x


def _scipy_period_doubling(omega, lo, hi, x_guess, delta=0.3):
    """gamma in [lo, hi] where det(M + I) = 0 for the P1 orbit of the double-well Duffing oscillator:
    scipy DOP853 (rtol 1e-12, atol 1e-13) with the variational equations, the orbit by Newton on the
    period map, brentq (xtol 1e-13) on det(M + I).  Independent of geardyn."""
    T = 2 * math.pi / omega
    x = np.array(x_guess, dtype=float)

    def period_map(gamma, x0):
        def rhs(t, y):
            J = np.array([[0.0, 1.0], [1.0 - 3.0 * y[0] ** 2, -delta]])
            f = [y[1], gamma * math.cos(omega * t) - delta * y[1] + y[0] - y[0] ** 3]
            return np.concatenate([f, (J @ y[2:].reshape(2, 2)).ravel()])

        y0 = np.concatenate([x0, np.eye(2).ravel()])
        y = solve_ivp(rhs, (0.0, T), y0, method="DOP853", rtol=1e-12, atol=1e-13).y[:, -1]
        return y[:2], y[2:].reshape(2, 2)

    def det_plus(gamma):
        nonlocal x
        for _ in range(20):
            phi, M = period_map(gamma, x)
            dx = np.linalg.solve(M - np.eye(2), x - phi)
            x = x + dx
            if np.max(np.abs(dx)) < 1e-12:
                break
        return float(np.linalg.det(period_map(gamma, x)[1] + np.eye(2)))

    return brentq(det_plus, lo, hi, xtol=1e-13, rtol=1e-15), x


def test_period_doubling_curve_of_duffing_matches_scipy_floquet():
    plane = DuffingPlane(0.3, -1.0, 1.0, (0.2, 0.4, 1.1, 1.3))
    fam = plane.along_p(1.2)
    x = _attractor(fam.flow(0.2, 1), np.array([0.1, 0.0]), 200)
    br = C.continue_branch(fam, 0.2, x, 1, 0.2, 0.3, C.ContinuationSettings(ds=0.02, ds_max=0.02))
    curves = C.curves_from_branch(plane, br, "p", 1.2, dataclasses.replace(C.CURVES, ds=0.02, ds_max=0.05))
    assert [c.kind for c in curves] == ["period_doubling"]
    pd = curves[0]
    assert pd.end_status == {"down": "box", "up": "box"} and np.max(np.abs(pd.residual)) < 1e-10
    for omega in (1.12, 1.2, 1.28):
        (cross,) = C.line_points(plane, pd, "q", omega)
        gamma = float(cross.z[-2])
        ref, orbit = _scipy_period_doubling(omega, gamma - 2e-3, gamma + 2e-3, cross.z[:2])
        assert abs(gamma - ref) < 1e-6  # measured 2.2e-11 to 3.9e-10
        assert np.max(np.abs(orbit - cross.z[:2])) < 1e-6  # measured 2.8e-11
        assert abs(cross.crit[0] + 1.0) < 1e-9


def test_pixel_check_types_the_duffing_period_doubling_supercritical():
    """The pixel check's criticality of a period doubling (the period-2 branch switched at the crossing reaches the
    pixel on the orbit's unstable side, stable: supercritical): the Duffing period doubling is supercritical, as a
    run from the P1 orbit pushed off just past it shows (it settles on a period-2 cycle next to the orbit, and
    before it on the orbit itself); with the pixels' sides swapped the same crossing reads subcritical."""
    plane = DuffingPlane(0.3, -1.0, 1.0, (0.2, 0.4, 1.1, 1.3))
    fam = plane.along_p(1.2)
    x = _attractor(fam.flow(0.2, 1), np.array([0.1, 0.0]), 200)
    br = C.continue_branch(fam, 0.2, x, 1, 0.2, 0.3, C.ContinuationSettings(ds=0.02, ds_max=0.02))
    (bf,) = [b for b in br.bifurcations if b.kind == "period_doubling"]
    (pd,) = C.curves_from_branch(plane, br, "p", 1.2, dataclasses.replace(C.CURVES, ds=0.02, ds_max=0.05))
    ref = min(pd.points, key=lambda pt: abs(pt.q - 1.2))
    probe = pixel_probe.Probe(plane, pd, pixel_samples.CheckSettings())
    for d in (2e-3, 1e-2):
        t_pair = (bf.p - d, bf.p + d)  # the P1 orbit is stable below the period doubling
        origin = pixel_probe.Origin(bf.p, 1.2, "p")
        assert probe.criticality(origin, ref, bf.state, t_pair) == "supercritical", d
        assert probe.criticality(origin, ref, bf.state, t_pair[::-1]) == "subcritical", d
        for g, past in ((bf.p - d, False), (bf.p + d, True)):
            orbit = newton_shooting(plane.flow(g, 1.2, 1), bf.state, 1, 1e-10).state
            y = _attractor(plane.flow(g, 1.2, 1), orbit + 1e-3, 3000)
            back2 = np.max(np.abs(plane.flow(g, 1.2, 2)(y, False)[0] - y))
            back1 = np.max(np.abs(plane.flow(g, 1.2, 1)(y, False)[0] - y))
            assert (back2 < 1e-8 < back1) == past and np.max(np.abs(y - orbit)) < 0.2, (g, back1, back2)


def test_cusp_of_a_hardening_duffing_fold_curve_where_the_hysteresis_begins():
    """x'' + 0.2 x' + x + x^3 = gamma cos(omega t): the two folds of the resonance curve are one curve in
    (omega, gamma) through a cusp; one-parameter sweeps along omega find two folds just above the cusp's
    gamma, where the curve crosses that line, and none just below (where the curve does not cross)."""
    plane = DuffingPlane(0.2, 1.0, 1.0, (0.8, 2.0, 0.0, 0.6), names=("omega", "gamma"))
    cs = C.ContinuationSettings(ds=0.005, ds_max=0.005, grazing=False)

    def folds(gamma):
        fam = plane.along_p(gamma)
        x = _attractor(fam.flow(0.8, 1), np.zeros(2), 300)
        br = C.continue_branch(fam, 0.8, x, 1, 0.8, 2.0, cs)
        return br, sorted(b.p for b in br.bifurcations if b.kind == "fold")

    br, _ = folds(0.3)
    curves = C.curves_from_branch(plane, br, "p", 0.3, dataclasses.replace(C.CURVES, ds=0.02, ds_max=0.05))
    assert [c.kind for c in curves] == ["fold"]  # the second fold lies on the curve of the first
    cusps = [b for b in curves[0].codim2 if b.kind == "cusp"]
    assert len(cusps) == 1 and cusps[0].located
    g_c = cusps[0].q  # measured (omega, gamma) = (1.187300, 0.164702)
    above = folds(g_c * 1.03)[1]
    cross = sorted(pt.z[-2] for pt in C.line_points(plane, curves[0], "q", g_c * 1.03))
    assert len(above) == 2 and np.max(np.abs(np.subtract(above, cross))) < 1e-6  # measured 5e-15
    assert folds(g_c * 0.97)[1] == [] and C.line_points(plane, curves[0], "q", g_c * 0.97) == []


# --- the KHV model ------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def linear_limit():
    """li2013 with the mean mesh stiffness, x1 = 0.5, b = 2: the P1 branch along e at w = 0.9 and the
    curves seeded from its grazing point and folds, in (w, e)."""
    d = design.load(ROOT / "config" / "designs" / "li2013.yaml")
    dyn = {**d.dynamics, "options": {**d.dynamics["options"], "stiffness_mode": "mean"}}
    d = dataclasses.replace(d, dynamics=dyn)
    fixed = {"x1": 0.5, "b": 2.0}
    fam = C.KHVFamily(d, "e", {**fixed, "w": 0.9}, 0.0, 3.0, nodes=5)
    x = simulate(fam.coefficients(0.5), SimulationSettings(transient_periods=2000, recorded_periods=1)).final_state
    br = C.continue_branch(fam, 0.5, x, 1, 0.0, 3.0, C.ContinuationSettings(ds=0.05, ds_max=0.05))
    plane = C.KHVPlane(d, ("w", "e"), fixed, (0.8, 1.6, 0.0, 3.0), nodes=5)
    curves = C.curves_from_branch(plane, br, "q", 0.9, dataclasses.replace(C.CURVES, ds=0.02, ds_max=0.02))
    return d, fixed, plane, br, curves


def _closed_form_grazing(d, fixed, w):
    """e_g(w) = (|x_s| - b) / |H(w)|: x_s the static mesh deflection, H the response of x_VH to a TE of
    unit amplitude, (-w^2 I + i w C + K) X = (0, w^2, 0) with the mesh terms in K and C."""
    c = point.point_coefficients(d, {**fixed, "w": w, "e": 1.0})
    m = c.matrices()
    mesh = np.outer(m["g"], [0.0, 1.0, 0.0])
    X = np.linalg.solve(-(w**2) * np.eye(3) + 1j * w * (m["C"] + c.c_m * mesh) + m["K"] + mesh, [0.0, w**2, 0.0])
    return (abs(model.static_deflection(c)[1]) - c.b) / abs(X[1])


def test_grazing_curve_of_the_linear_limit_is_the_closed_form(linear_limit):
    d, fixed, plane, _, curves = linear_limit
    graz = [c for c in curves if c.kind == "grazing"]
    assert len(graz) == 1 and graz[0].end_status == {"down": "box", "up": "box"}
    errs = []
    for w in np.linspace(0.8, 1.6, 20):
        (cross,) = C.line_points(plane, graz[0], "p", w)
        errs.append(abs(cross.z[-1] / _closed_form_grazing(d, fixed, w) - 1.0))
    assert max(errs) < 1e-6  # measured 5.0e-8 (median 2.0e-8)
    # every point of the curve, too
    assert all(abs(pt.z[-1] / _closed_form_grazing(d, fixed, pt.z[-2]) - 1.0) < 1e-6 for pt in graz[0].points)


def test_fold_curve_of_the_linear_limit_has_a_cusp_beyond_grazing(linear_limit):
    """Both folds of the e sweep at w = 0.9 lie on one fold curve through a cusp; an e sweep at w just below
    the cusp finds two folds where the curve crosses that line, one just above none."""
    d, fixed, plane, _, curves = linear_limit
    assert sorted(c.kind for c in curves) == ["fold", "grazing"]
    fold = next(c for c in curves if c.kind == "fold")
    (cusp,) = [b for b in fold.codim2 if b.kind == "cusp"]
    assert cusp.located and abs(cusp.multipliers[np.argmin(np.abs(cusp.multipliers - 1))] - 1) < 1e-9
    w_c, e_c = cusp.p, cusp.q  # measured (0.917465, 1.204323)
    assert e_c > _closed_form_grazing(d, fixed, w_c)  # contact is lost there

    def folds(w):
        fam = C.KHVFamily(d, "e", {**fixed, "w": w}, 1.0, 1.5, nodes=5)
        x = simulate(fam.coefficients(1.0), SimulationSettings(transient_periods=2000, recorded_periods=1))
        cs = C.ContinuationSettings(ds=0.01, ds_max=0.01, grazing=False)
        b = C.continue_branch(fam, 1.0, x.final_state, 1, 1.0, 1.5, cs)
        return sorted(f.p for f in b.bifurcations if f.kind == "fold")

    below = folds(w_c - 3e-3)
    cross = sorted(pt.z[-1] for pt in C.line_points(plane, fold, "p", w_c - 3e-3))
    assert len(below) == 2 and np.max(np.abs(np.subtract(below, cross))) < 1e-6  # measured 2.8e-11
    assert folds(w_c + 3e-3) == [] and C.line_points(plane, fold, "p", w_c + 3e-3) == []


@pytest.fixture(scope="module")
def calibrated_ns():
    d = design.load(ROOT / "config" / "designs" / "li2013_calibrated.yaml")
    br = _x1_branch(d, 5.0, 0.53, 0.555)
    plane = C.KHVPlane(d, ("x1", "e"), {"b": 2.0}, (0.50, 0.60, 4.0, 6.0), nodes=5)
    curves = C.curves_from_branch(plane, br, "p", 5.0, dataclasses.replace(C.CURVES, ds=0.02, ds_max=0.05))
    return d, br, plane, curves


def _x1_branch(d, e, lo, hi):
    fam = C.KHVFamily(d, "x1", {"b": 2.0, "e": e}, lo, hi, nodes=5)
    x = simulate(fam.coefficients(lo), SimulationSettings(transient_periods=2000, recorded_periods=1)).final_state
    return C.continue_branch(fam, lo, x, 1, lo, hi, C.ContinuationSettings(ds=0.1, ds_max=0.1))


def test_neimark_sacker_curve_crosses_the_sweeps_where_they_bifurcate(calibrated_ns):
    d, br, plane, curves = calibrated_ns
    (ns,) = [b for b in br.bifurcations if b.kind == "neimark_sacker"]
    assert ns.p == pytest.approx(0.54203, abs=1e-5)
    assert [c.kind for c in curves] == ["neimark_sacker"]
    curve = curves[0]
    assert np.max(np.abs(curve.residual)) < 1e-10
    (at5,) = C.line_points(plane, curve, "q", 5.0)
    assert abs(at5.z[-2] - ns.p) < 1e-5  # measured 6.4e-9
    for e in (4.5, 5.5):
        (cross,) = C.line_points(plane, curve, "q", e)
        x1 = float(cross.z[-2])
        other = _x1_branch(d, e, x1 - 0.01, x1 + 0.01)
        (hit,) = [b for b in other.bifurcations if b.kind == "neimark_sacker"]
        assert abs(hit.p - x1) < 1e-5  # measured 5.1e-10 (e = 4.5), 2.0e-9 (e = 5.5)
        assert abs(abs(cross.crit[0]) - 1.0) < 1e-10


def test_flip_neimark_sacker_point_is_where_the_sweep_doubles_its_period(calibrated_ns):
    """The NS curve meets a period-doubling curve: a sweep along x1 at that e has its period doubling there."""
    d, _, _, curves = calibrated_ns
    (fns,) = [b for b in curves[0].codim2 if b.kind == "flip_neimark_sacker"]
    assert fns.located  # measured (0.5865787, 4.3362427)
    br = _x1_branch(d, fns.q, fns.p - 0.01, fns.p + 0.01)
    (pd,) = [b for b in br.bifurcations if b.kind == "period_doubling"]
    assert abs(pd.p - fns.p) < 1e-5  # measured 5.2e-8
    assert np.min(np.abs(fns.multipliers + 1.0)) < 1e-6


def test_corrector_jacobians_from_one_batch_are_the_single_flows_bit_for_bit(calibrated_ns):
    """The corrector's finite-difference columns of a curve come from one batched kernel call; each must be, bit
    for bit, what one flow per column gives (the plane's own flow)."""
    _, _, plane, curves = calibrated_ns
    curve = curves[0]
    prob = CurveProblem(plane, curve.kind, curve.n, 6, curve.scales, C.CURVES)
    for pt in curve.points[:: max(1, len(curve) // 3)]:
        z = pt.z
        ev = prob.evaluate(z, None, pt)
        J = prob.jacobian(z, ev, pt)
        for k in range(z.size):
            zk = z.copy()
            zk[k] += C.CURVES.dp_rel * prob.scale[k]
            phi, M = plane.flow(float(zk[-2]), float(zk[-1]), 1)(zk[:-2], True)
            G, _ = condition(curve.kind, M, pt.crit)
            assert J[-1, k] == (G - ev.H[-1]) / (C.CURVES.dp_rel * prob.scale[k])
            if k >= 6:
                np.testing.assert_array_equal(
                    J[:-1, k], (phi - zk[:-2] - ev.H[:-1]) / (C.CURVES.dp_rel * prob.scale[k])
                )


def test_curve_dataset_is_cf_complete(calibrated_ns, linear_limit, tmp_path):
    _, _, _, curves = calibrated_ns
    ds = C.curve_dataset(curves, ("x1", "e"))
    assert io.missing_cf_attributes(ds) == []
    assert ds.sizes["point"] == len(curves[0]) and ds.sizes["codim2"] == len(curves[0].codim2)
    assert ds["e"].attrs["units"] == "1" and "transmission-error" in ds["e"].attrs["long_name"]
    assert decode(ds["codim2_type"].attrs)[int(ds["codim2_type"][0])] == "flip_neimark_sacker"
    io.write_netcdf(ds, tmp_path / "curves.nc", provenance.attributes(title="test"))
    lin = C.curve_dataset(linear_limit[4], ("w", "e"))
    meaning = decode(lin["curve_kind"].attrs)
    assert io.missing_cf_attributes(lin) == [] and {meaning[c] for c in lin["curve_kind"].values} == {"fold", "grazing"}
    assert {int(c) for c in lin["curve_kind"].values} == {CODES["fold"], CODES["grazing"]}


# --- regime boundaries of a map (geardyn.runs.continuation.curve_maps, curve_check, output) -------------


def _small_map(d, x, y, fixed, n=20):
    """A map of n x n points at the map preset's settings (128 steps, 400 + 50 periods), labelled in one chunk."""
    entry = {
        "designs": [d.name],
        "x": {**x, "num": n},
        "y": {**y, "num": n},
        "fixed": fixed,
        "integration": {"steps_per_period": 128, "transient_periods": 400, "recorded_periods": 50},
        "classifier": {"tangent_periods": 200, "error_floor": 1.9e-5},
    }
    spec = maps.MapSpec.from_config("small", entry, d.name, d.segment)
    return spec, maps.run_chunk(d, spec, 0), point.integration_settings(d, **entry["integration"])


def _map_curves(d, spec, cube, settings, lines, **changes):
    region = boundaries.Region.of_map(spec)
    bs = dataclasses.replace(boundaries.BoundarySpec(), lines_x=tuple(lines[0]), lines_y=tuple(lines[1]), **changes)
    bd, plane = curve_maps.boundary_curves(d, region, bs, settings, cube)
    return bd, curve_check.pixel_check(plane, bd.curves, cube, CHECK), plane


@pytest.fixture(scope="module")
def map_x1_b_small():
    """li2013_calibrated over (x1, b) at e = 5, 20 x 20 (about 1.5 s): the Neimark-Sacker curve of the P1 orbit
    bounds the quasi-periodic region (the shipped map_x1_b at 200 x 200, docs/orbits.md)."""
    d = design.load(ROOT / "config" / "designs" / "li2013_calibrated.yaml")
    spec, cube, settings = _small_map(
        d, {"parameter": "x1", "start": 0.416, "stop": 0.835}, {"parameter": "b", "start": 0.0, "stop": 2.2}, {"e": 5.0}
    )
    return cube, *_map_curves(d, spec, cube, settings, ([0.5], [2.0]))  # cube, bd, check, plane


def test_pixel_check_of_the_neimark_sacker_boundary(map_x1_b_small):
    """Both pixels beside every crossing of the curve with a row or column: P1 on the orbit's stable side,
    quasi-periodic beyond, or transient where the record still grows toward the torus at the labeller's cap
    (18 of 18 checked crossings); left out, each with its reason: the return crossings
    whose rows carry the torus across the curve's subcritical part (hysteresis), a stable side on the orbit
    whose multiplier is within the slow margin of 1, an other side undetermined at the circle, a crossing
    within 1.5 pixels of the curve itself."""
    cube, bd, check, _ = map_x1_b_small
    assert [(bc.kind, bc.curve.n) for bc in bd.curves] == [("neimark_sacker", 1)]
    # every record of the rows (after a periodic pixel) lies on the curve
    assert {r.fate for r in bd.records if r.n >= 1} == {"on_curve"}
    assert len(check.checked) >= 15 and check.fraction >= 0.95  # measured 1.0 (18 of 18)
    assert check.attrs()["pixel_check_samples"] == len(check.checked)
    margin = curve_check.slow_margin(cube)
    assert margin == max(1.9e-5, 1 / 4000)
    for s in check.samples:
        if s.ok:  # the predicted change: P1 on the stable side, a torus beyond (or a record still growing toward it)
            assert s.labels[0] == 1 and s.modulus < 1.0, s
            assert s.labels[1] in (vocabulary.LABELS["quasi_periodic"], vocabulary.LABELS["transient"]), s
        elif s.reason == "slow" and s.labels[0] == 1:  # beyond: a record at the circle, undetermined
            assert s.labels[1] == vocabulary.LABELS["undetermined"] and s.modulus < 1.0, s
        elif s.reason == "slow":  # the stable side's multiplier within the margin of 1
            assert 1.0 - margin <= s.modulus < 1.0, s
        elif s.reason == "hysteresis":  # the row came through the torus and kept it
            assert not s.forward and s.labels[0] != 1 and s.modulus < 1.0, s
        else:
            assert s.reason in ("crowded", "codim2"), s
    assert len(check.samples) - len(check.checked) <= 5  # measured 5


def test_pixel_check_fails_a_misplaced_curve_and_a_mislabelled_map(map_x1_b_small):
    """The check can fail: the curve moved by 3 pixels to larger x1 and lower b (its crossings straddle no change of the
    orbit's stability: ``not_straddled``), and the map with its P1 pixels relabelled quasi-periodic (the stable
    side on the orbit, certified, labelled otherwise: ``stable_side``)."""
    cube, bd, _, plane = map_x1_b_small
    ((curve, _, _),) = bd.curves
    dx, dy = (3 * float(cube[v][1] - cube[v][0]) for v in ("x", "y"))
    moved = [dataclasses.replace(pt, z=np.r_[pt.z[:-2], pt.z[-2] + dx, pt.z[-1] - dy]) for pt in curve.points]
    shifted = [C.curves.BoundaryCurve(C.Curve(curve.kind, curve.n, moved, curve.scales, {}))]
    wrong = curve_check.pixel_check(plane, shifted, cube, CHECK)
    assert wrong.fraction <= 0.3 and wrong.tally(("not_straddled",))  # measured 0.0: 19 of 19 not straddled
    relabelled = cube.copy()
    lab = relabelled["label"].values.copy()
    lab[lab == 1] = vocabulary.LABELS["quasi_periodic"]
    relabelled["label"] = (relabelled["label"].dims, lab, relabelled["label"].attrs)
    bad = curve_check.pixel_check(plane, bd.curves, relabelled, CHECK)
    assert bad.fraction <= 0.3 and bad.tally(("stable_side",))  # measured 0.0


@pytest.fixture(scope="module")
def linear_limit_map():
    """li2013 with the mean mesh stiffness over (w, e) at x1 = 0.5, b = 2, 20 x 20: the grazing curve (contact
    loss) of the linear limit, the fold curve and the curves beyond contact loss."""
    d = design.load(ROOT / "config" / "designs" / "li2013.yaml")
    d = dataclasses.replace(d, dynamics={**d.dynamics, "options": {**d.dynamics["options"], "stiffness_mode": "mean"}})
    spec, cube, settings = _small_map(
        d,
        {"parameter": "w", "start": 0.8, "stop": 1.6},
        {"parameter": "e", "start": 0.0, "stop": 3.0},
        {"x1": 0.5, "b": 2.0},
    )
    return d, cube, *_map_curves(d, spec, cube, settings, ([0.9], [1.5]), max_points=150)  # bd, check, plane


def test_pixel_check_of_the_grazing_curve_no_impact_to_single_sided(linear_limit_map):
    """Across the grazing curve the impact class changes from no impact to single-sided impact as the shot
    orbit predicts, at every row and column that crosses it; every checked crossing of every curve passes."""
    _, cube, bd, check, _ = linear_limit_map
    kinds = {bc.kind for bc in bd.curves}
    assert {"grazing", "fold", "neimark_sacker"} <= kinds
    grazing = [s for s in check.checked if s.kind == "grazing"]
    assert len(grazing) >= 12  # measured 15 (11 more within 3 pixels of a codimension-2 point)
    impact = cube["impact_class"].values
    for s in grazing:
        (j0, i0), (j1, i1) = s.pixels
        assert {int(impact[j0, i0]), int(impact[j1, i1])} == {0, 1}, s  # no impact | single-sided
    assert check.fraction >= 0.95 and len(check.checked) >= 25  # measured 1.0 (28 of 28)
    assert {s.reason for s in check.samples if not s.checked} == {"codim2"}


def test_grazing_meets_a_fold_a_period_doubling_and_a_neimark_sacker_on_the_back_flank(linear_limit_map):
    """The back-flank grazing curve of the linear limit's P1 orbit carries a grazing-fold, two grazing-flip and a
    grazing-Neimark-Sacker point, each located: there the back-flank margin of the orbit vanishes and the
    monodromy matrix, recomputed from the stored state, has a multiplier +1, -1 or a complex pair on the unit
    circle."""
    _, _, bd, _, plane = linear_limit_map
    found = {}
    for bc in bd.curves:
        for b in bc.curve.codim2:
            if bc.kind == "back_grazing":
                found.setdefault(b.kind, []).append(b)
    assert {k: len(v) for k, v in found.items()} == {"grazing_fold": 1, "grazing_flip": 2, "grazing_neimark_sacker": 1}
    for kind, points in found.items():
        for b in points:
            assert b.located
            h = back_margin(plane.coefficients(b.p, b.q), b.state, b.n, plane.settings)
            assert abs(h) < 1e-7, (kind, h)  # measured 4.7e-9 (fold), 3.9e-12, 7.5e-14 (flip), 1.1e-13 (NS)
            y, M = plane.flow(b.p, b.q, b.n)(b.state, True)
            assert np.max(np.abs(y - b.state)) < 1e-7  # on the orbit
            mu = np.linalg.eigvals(M)
            if kind == "grazing_fold":
                assert np.min(np.abs(mu - 1.0)) < 1e-8, mu  # measured 2.5e-13
            elif kind == "grazing_flip":
                assert np.min(np.abs(mu + 1.0)) < 1e-8, mu  # measured 5.6e-13, 2.4e-15
            else:
                pair = mu[np.abs(mu.imag) > 1e-6]
                assert pair.size >= 2 and np.min(np.abs(np.abs(pair) - 1.0)) < 1e-8, mu  # measured 1.9e-14


def test_boundary_settings_agree_with_the_config_schema():
    node = io_schema("config.schema.json")["$defs"]["curve_settings"]["properties"]
    defaults = dataclasses.asdict(boundaries.BoundarySpec())
    assert set(node) == set(defaults) - {"probes"}
    for key, sub in node.items():
        assert sub["default"] == (list(defaults[key]) if isinstance(defaults[key], tuple) else defaults[key]), key


def test_curves_file_is_cf_complete_and_keeps_the_check(map_x1_b_small, tmp_path):
    _, bd, check, _ = map_x1_b_small
    ds = curve_maps.boundary_dataset(bd, check)
    assert io.missing_cf_attributes(ds) == []
    assert ds.attrs["pixel_check_samples"] == len(check.checked) and ds.sizes["check"] == len(check.samples)
    assert "## Pixel check: small" in plots_curves.check_table("small", ds)
    assert ds["check_reason"].attrs["failures"].split() == list(pixel_samples.FAILURES)
    assert decode(ds["curve_kind"].attrs)[CODES["back_grazing"]] == "back_grazing"
    assert ds.sizes["record"] == len(bd.records) and ds.attrs["records_on_curve"] >= 1
    io.write_netcdf(ds, tmp_path / "curves.nc", provenance.attributes(title="test"))
    empty = curve_maps.boundary_dataset(type(bd)(bd.region))  # no curve at all: still a valid file
    assert io.missing_cf_attributes(empty) == []
    io.write_netcdf(empty, tmp_path / "empty.nc", provenance.attributes(title="test"))


def test_a_period_two_curve_on_the_doubled_period_one_orbit_starts_none(calibrated_ns):
    """The period-1 orbit at its Neimark-Sacker point is a period-2 orbit with its pair squared on the circle: a
    period-2 Neimark-Sacker curve seeded there is the period-1 curve traversed twice, so it starts none (a period-2
    curve that reaches such an orbit ends there, ``merged_into_shorter_period``)."""
    _, _, plane, curves = calibrated_ns
    pt = curves[0].points[len(curves[0]) // 2]
    assert C.curves.shorter_period(plane, pt.p, pt.q, pt.x, 2) and not C.curves.shorter_period(
        plane, pt.p, pt.q, pt.x, 1
    )
    assert C.continue_curve(plane, "neimark_sacker", 2, pt.x, (pt.p, pt.q), pt.crit[0] ** 2) is None
    again = C.continue_curve(plane, "neimark_sacker", 1, pt.x, (pt.p, pt.q), pt.crit[0])
    assert again is not None and again.end_status == curves[0].end_status


def test_every_orbit_of_a_curves_study_is_one_of_the_callers_integrator():
    """The seeds, the branches and the curves of a plane without a map integrate with the caller's integrator and
    step alignment (here plain RK4 on steps not aligned with the mesh-stiffness switches): every branch point is a
    fixed point of the caller's n-period map, within the shooting tolerance (1e-9), and is not one of the design's
    own integrator's (event-located RK4 on aligned steps), which moves it by 1e-4 or more."""
    d = design.load(ROOT / "config" / "designs" / "li2013.yaml")
    region = boundaries.Region(("x1", "e"), (0.50, 0.52, 4.9, 5.0), (("b", 2.0),))
    spec = dataclasses.replace(boundaries.BoundarySpec(), probes=1, max_period=2, back_grazing=False, nodes=5)
    steps = {"steps_per_period": 128, "transient_periods": 300, "recorded_periods": 30}
    settings = point.integration_settings(d, integrator="rk4", aligned=False, **steps)
    bd, _ = curve_maps.boundary_curves(d, region, spec, settings)
    assert [br.n for _, br in bd.branches] == [1, 1]  # a P1 orbit seeded and continued on both lines
    own = point.integration_settings(d, **steps)
    assert (own.integrator, own.aligned) == ("rk4_event", True)
    for line, br in bd.branches:
        mine, theirs = (curve_maps.line_family(d, region, line, s, spec.nodes) for s in (settings, own))
        for p, x in zip(br.p[::10], br.states[::10], strict=True):
            scale = max(1.0, float(np.max(np.abs(x))))
            moved = [float(np.max(np.abs(f.flow(float(p), br.n)(x, False)[0] - x))) / scale for f in (mine, theirs)]
            # measured: at most 3.3e-15 (the caller's map), at least 2.6e-3 (the design's), at 12 points
            assert moved[0] <= 1e-9 and moved[1] >= 1e-4, (line, p, moved)
