"""Linear forced response of the plus set to the static TE (geardyn.plus.forced), against numbers from
outside the solver: the single-DOF receptance, a direct complex solve, the static solution, the
high-frequency limit k e, and the natural frequencies of the modal model."""

from dataclasses import replace

import numpy as np
import pytest

import _model_oracle as oracle
from geardyn.plus import forced, modal
from geardyn.plus.design import default_design
from geardyn.plus.ishikawa import pd_mesh_load

D = default_design()
N_PHASE = 64
S = np.arange(N_PHASE) / N_PHASE


def _sine_te(amplitude=2e-6, h=1, mean=3e-6):
    return (mean + amplitude * np.cos(2 * np.pi * h * S))[None, :]


def _design(**forced_changes):
    return replace(D, forced=replace(D.forced, **forced_changes))


def test_single_dof_receptance():
    # m x'' + c x' + k x = F e^{iwt}: X = F / (k - m w^2 + 2 i zeta sqrt(k m) w)
    m, k, zeta, f0 = 2.0, 8.0e6, 0.03, 5.0
    w = np.array([1e-3, 0.5, 0.99, 1.0, 1.01, 3.0]) * np.sqrt(k / m)
    x = forced.modal_frf([k / m], [[1 / np.sqrt(m)]], zeta, np.array([f0]), w)[..., 0]
    exact = f0 / (k - m * w**2 + 2j * zeta * np.sqrt(k * m) * w)
    np.testing.assert_allclose(x, exact, rtol=1e-12)
    assert abs(x[3]) == pytest.approx(f0 / (2 * zeta * k), rel=1e-12)  # resonance: Q = 1 / (2 zeta)
    # quasi-static limit: the spring force k X equals the applied k TE
    te = 4e-6
    xs = forced.modal_frf([k / m], [[1 / np.sqrt(m)]], zeta, np.array([k * te]), 1e-6)[..., 0]
    assert k * xs.real == pytest.approx(k * te, rel=1e-9) and abs(xs.imag) < 1e-9 * te


def test_modal_superposition_equals_the_direct_complex_solve():
    md = modal.modes(D, "I")
    mat = modal.matrices(D, "I")
    om2, phi = md.omega2[md.n_rigid :], md.shapes[:, md.n_rigid :]
    C = oracle.modal_damping_matrix(mat.M, om2, phi, 0.05)
    rng = np.random.default_rng(0)
    v = [el.v[[modal.COORDS.index(c) for c in mat.coords]] for el in modal.elements(D) if el.kind == "pd"]
    f = sum(rng.normal() * vj for vj in v) * 1e2  # mesh forces are orthogonal to the rigid mode
    for w in (300.0, 2 * np.pi * 339.76, 5000.0, 2 * np.pi * 1314.0):
        direct = np.linalg.solve(mat.K - w**2 * mat.M + 1j * w * C, f)
        np.testing.assert_allclose(
            forced.modal_frf(om2, phi, 0.05, f, w), direct, rtol=1e-8, atol=1e-10 * np.abs(direct).max()
        )


def test_constant_te_gives_no_dynamic_force():
    res = forced.forced_response(D, np.full((1, N_PHASE), 7e-6), speeds=np.linspace(10, 4000, 50))
    assert np.abs(res.amplitude).max() == 0.0
    np.testing.assert_array_equal(res.dynamic_factor, 1.0)


def test_quasi_static_limit_is_the_static_solution():
    # w -> 0: K X = F (least squares removes the rigid-body motion, which F does not excite)
    d = _design(harmonics=1)
    a = 2e-6
    res = forced.forced_response(d, _sine_te(a), speeds=[1e-4])
    mat = modal.matrices(d, "I")
    keep = [modal.COORDS.index(c) for c in mat.coords]
    meshes = [el for el in modal.elements(d) if el.kind in modal.MESH_TYPES]
    g = forced.mesh_phases(d)
    e = np.array([a * np.exp(2j * np.pi * g[el.j]) if el.kind == "pd" else 0.0 for el in meshes])
    f = -sum(el.k * ej * el.v[keep] for el, ej in zip(meshes, e, strict=True))
    x = np.linalg.lstsq(mat.K, f, rcond=None)[0]
    static = np.array([el.k * (el.v[keep] @ x + ej) for el, ej in zip(meshes, e, strict=True)])
    np.testing.assert_allclose(res.amplitude[0, 0, 0], static, rtol=1e-6, atol=1e-9 * np.abs(static).max())


def test_in_phase_quasi_static_te_is_taken_up_by_the_free_members():
    # the three branches in phase: sun and ring turn to absorb the TE, no mesh force at w -> 0
    res = forced.forced_response(_design(harmonics=1, phasing="in_phase"), _sine_te(), speeds=[1e-4])
    assert np.abs(res.amplitude).max() < 1e-6 * D.stiffness.planet_planet * 2e-6


def test_high_speed_limit_puts_the_whole_te_into_the_mesh_spring():
    # w -> infinity: X -> 0, the p-d force is k e (RMS k a / sqrt 2), the others carry nothing
    a = 2e-6
    res = forced.forced_response(_design(harmonics=3), _sine_te(a), speeds=[1e8])
    k = D.stiffness.planet_planet
    pd = np.array([name.startswith("pd") for name in res.meshes])
    np.testing.assert_allclose(res.rms[0, 0, pd], k * a / np.sqrt(2), rtol=1e-6)
    assert res.rms[0, 0, ~pd].max() < 1e-6 * k * a
    # the largest force is sampled at PHASE_SAMPLES points per period: off-grid phases lose at most 1 - cos(pi / n)
    fluct = k * a / pd_mesh_load(D)
    tol = fluct * (1 - np.cos(np.pi / forced.PHASE_SAMPLES)) + 1e-9
    np.testing.assert_allclose(res.dynamic_factor[0, 0, pd], 1 + fluct, atol=tol)


def _peaks(y):
    return np.where((y[1:-1] > y[:-2]) & (y[1:-1] > y[2:]))[0] + 1


@pytest.mark.parametrize("phasing, kind", [("sequential", "planet"), ("in_phase", "overall")])
def test_resonance_peaks_sit_at_the_natural_frequencies(phasing, kind):
    # one harmonic, light damping: the response peaks where h f_mesh meets a natural frequency. Sequential
    # planet phasing (h = 1, z_s = 32, three planets) excites only the doubled planet modes, in-phase
    # excitation only the axisymmetric (overall) ones.
    d = _design(harmonics=1, phasing=phasing, damping_ratio=0.005, speed_points=3000)
    res = forced.forced_response(d, _sine_te())
    md = modal.modes(d, "I")
    types = np.array(modal.classify(md))[md.n_rigid :]
    expected = np.unique(np.round(res.natural_hz[types == kind], 6)) / res.mesh_hz_per_rpm
    step = res.speed_rpm[1] - res.speed_rpm[0]
    total = res.rms[0].sum(axis=1)
    found = res.speed_rpm[_peaks(total)]
    assert len(found) == len(expected) == 3
    np.testing.assert_allclose(found, expected, atol=step)
    # the modes table of the documentation: 339.8, 877.6, 1314.0 Hz (planet) and 430.4, 1079.3, 1499.7 Hz (overall)
    hz = {"planet": [339.8, 877.6, 1314.0], "overall": [430.4, 1079.3, 1499.7]}[kind]
    np.testing.assert_allclose(found * res.mesh_hz_per_rpm, hz, atol=step * res.mesh_hz_per_rpm + 0.05)


def test_te_harmonics_of_a_known_series():
    te = 1.0 + 3.0 * np.cos(2 * np.pi * S + 0.4) + 0.5 * np.sin(2 * np.pi * 3 * S)
    c = forced.te_harmonics(te, 4)
    np.testing.assert_allclose(c, [3.0 * np.exp(0.4j), 0.0, -0.5j, 0.0], atol=1e-12)


def test_sequential_phases_of_three_planets():
    # z_s psi_j / 2 pi for psi = 0, 120, 240 deg and z_s = 32: 0, 32/3, 64/3 -> 0, 2/3, 1/3
    np.testing.assert_allclose(forced.mesh_phases(D), [0.0, 2 / 3, 1 / 3], atol=1e-12)
    assert forced.mesh_frequency_per_rpm(D, "I") == pytest.approx(32 / 60, rel=1e-12)
