"""Modal model of the plus planetary set (paper 2, Eqs. 1-8)."""

from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import _model_oracle as oracle
from geardyn.plus import modal
from geardyn.plus.design import default_design

D = default_design()
WORKING = ("I", "II", "III")


def test_rigid_modes_free_and_working_conditions():
    # no member held: whole-set rotation and the Willis (gear-train) motion; one member held: one mechanism DOF
    assert modal.modes(D, "free").n_rigid == 2
    for c in WORKING:
        assert modal.modes(D, c).n_rigid == 1


def test_whole_set_rotation_stores_no_energy():
    q = np.zeros(len(modal.COORDS))
    q[[modal.COORDS.index(c) for c in ("theta_s", "theta_r", "theta_c")]] = 1.0  # planets: 0 relative rotation
    K = modal.matrices(D, "free").K
    assert np.abs(K @ q).max() == pytest.approx(0.0, abs=1e-6 * np.abs(K).max())


def test_plus_set_kinematic_ratio():
    # carrier fixed: ring/sun = +r_bs/r_br; Table 1 rounds the radii to 0.1 mm, z_s/z_r exact within 0.05 %
    ratio = oracle.kinematic_ratio_carrier_fixed(D)
    assert ratio == pytest.approx(D.sun.base_radius / D.ring.base_radius, rel=1e-9)
    assert ratio == pytest.approx(32 / 77, rel=5e-4)


def test_printed_sign_makes_a_minus_set():
    ratio = oracle.kinematic_ratio_carrier_fixed(replace(D, plus_set_sign=False))
    assert ratio == pytest.approx(-32 / 77, rel=5e-4)


@pytest.mark.parametrize("cond", ["free", *WORKING])
def test_matrices_symmetric_and_definite(cond):
    m = modal.matrices(D, cond)
    n = 11 if cond == "free" else 10
    assert m.M.shape == m.K.shape == m.C.shape == (n, n)
    for A in (m.M, m.K, m.C):
        np.testing.assert_allclose(A, A.T, rtol=0, atol=1e-12 * np.abs(A).max())
    assert np.linalg.eigvalsh(m.M).min() > 0
    k_eig = np.linalg.eigvalsh(m.K)
    assert k_eig.min() > -1e-9 * k_eig.max()  # positive semi-definite
    assert np.linalg.eigvalsh(m.C).min() > -1e-9 * np.abs(m.C).max()


def test_rotational_stiffness_matches_hand_derivation():
    """Independent check: the fixed Eq. (6) written by hand (rotations only) and the translational block."""
    rs, rp, rd, rr = D.sun.base_radius, D.planet_p.base_radius, D.planet_d.base_radius, D.ring.base_radius
    k = D.stiffness.sun_planet
    idx = {c: i for i, c in enumerate(modal.COORDS)}
    K = np.zeros((11, 11))
    for j in (1, 2, 3):
        for v in (
            {"theta_s": rs, "theta_c": -rs, f"theta_p{j}": rp},  # r_s (th_s - th_c) + r_p th_p
            {f"theta_p{j}": rp, f"theta_d{j}": rd},  # r_p th_p + r_d th_d (plus set)
            {"theta_r": rr, "theta_c": -rr, f"theta_d{j}": -rd},
        ):  # r_r (th_r - th_c) - r_d th_d
            vec = np.zeros(11)
            for c, val in v.items():
                vec[idx[c]] = val
            K += k * np.outer(vec, vec)
    ours = modal.matrices(D, "free").K
    rot = [idx[c] for c in modal.COORDS if c.startswith("theta")]
    np.testing.assert_allclose(ours[np.ix_(rot, rot)], K[np.ix_(rot, rot)], rtol=1e-12, atol=1e-9)
    xy = [idx["x_s"], idx["y_s"]]
    # sum_j n_j n_j^T = 3/2 I for three equally spaced planets, plus the bearing
    np.testing.assert_allclose(
        ours[np.ix_(xy, xy)], (1.5 * k + D.stiffness.sun_bearing) * np.eye(2), rtol=1e-12, atol=1e-6
    )


def _doubled(md):
    return [md.freq_hz[g[0]] for g in modal.distinct_groups(md.omega2) if len(g) == 2]


def test_mode_counts_and_three_doubled_planet_frequencies_shared():
    ref = _doubled(modal.modes(D, "free"))
    assert len(ref) == 3
    for c in WORKING:
        md = modal.modes(D, c)
        groups = modal.distinct_groups(md.omega2)
        assert sum(len(g) for g in groups) == 9  # 10 coordinates - 1 rigid
        assert sorted(len(g) for g in groups) == [1, 1, 1, 2, 2, 2]
        np.testing.assert_allclose(_doubled(md), ref, rtol=1e-9)
        types = modal.classify(md)
        assert types.count("planet") == 6 and types.count("overall") == 3 and types.count("rigid") == 1


def test_first_mode_near_340_hz():
    # first mode 339.8 Hz against the paper's 1295 Hz (docs/paper2.md, Sec. 2, "The frequency gap")
    assert modal.modes(D, "I").freq_hz[1] == pytest.approx(340.0, rel=0.01)


def test_printed_sun_terms_break_the_doubled_modes():
    md = modal.modes(replace(D, planet_angles_in_sun_terms=False), "I")
    assert len(_doubled(md)) < 3


@pytest.mark.parametrize("cond", WORKING)
def test_damped_tends_to_undamped(cond):
    prev = None
    for scale in (1e-1, 1e-2, 1e-3, 1e-4):
        md = modal.modes(replace(D, damping=D.damping.scaled(scale)), cond)
        err = np.nanmax(np.abs(md.damped_hz - md.freq_hz) / md.freq_hz)
        if prev is not None:
            assert err < prev / 50  # second order in the damping: f_d = f sqrt(1 - zeta^2)
        prev = err
    assert prev < 1e-8


@pytest.mark.parametrize("cond", WORKING)
def test_energy_shares_sum_to_one(cond):
    md = modal.modes(D, cond)
    se, ke = modal.energy_shares(D, md)
    el = slice(md.n_rigid, None)
    np.testing.assert_allclose(sum(v[el] for v in se.values()), 1.0, rtol=1e-10)
    np.testing.assert_allclose(sum(v for v in ke.values()), 1.0, rtol=1e-10)
    # strain energy of an M-normalised mode is w^2/2 (Rayleigh), checked through the element sum
    phi = md.shapes[:, el]
    mat = modal.matrices(D, cond)
    np.testing.assert_allclose(np.einsum("im,ij,jm->m", phi, mat.K, phi), md.omega2[el], rtol=1e-9)


@settings(max_examples=15, deadline=None)
@given(st.floats(min_value=0.05, max_value=50.0))
def test_uniform_stiffness_scaling_scales_frequencies_by_sqrt(s):
    f0 = modal.modes(D, "I").freq_hz
    f1 = modal.modes(D.with_stiffness_scale(s), "I").freq_hz
    np.testing.assert_allclose(f1[1:], np.sqrt(s) * f0[1:], rtol=1e-8)


@settings(max_examples=10, deadline=None)
@given(st.floats(min_value=0.0, max_value=360.0))
def test_rotating_the_whole_set_changes_no_frequency(shift):
    d2 = replace(D, planet_angles=tuple(a + np.radians(shift) for a in D.planet_angles))
    np.testing.assert_allclose(modal.modes(d2, "II").freq_hz, modal.modes(D, "II").freq_hz, rtol=1e-8, atol=1e-6)
