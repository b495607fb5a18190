"""Mesh stiffness (paper 1 Eqs. 7-10) against closed forms, ISO 6336-1, docs/paper1.md and independent sums."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import integrate, optimize

from _examples import EXAMPLE_SCALE
from geardyn.gears import stiffness as s

EPS_GRID = [1.05, 1.17, 1.24, 1.30, 1.6, 1.95]


def test_iso_constants_and_printed_c1():
    assert s.ISO_C[0] == 0.04723 and s.PRINTED_C[0] == 0.04732
    q_iso = s.flexibility_q(30, 33, 0.626, 0.8, variant="paper", constants=s.ISO_C)
    q_pr = s.flexibility_q(30, 33, 0.626, 0.8, variant="paper", constants=s.PRINTED_C)
    # the transposition 0.04723 -> 0.04732 adds 9e-5 to q' = 0.064: k_C changes by -0.14 %
    # (docs/paper1.md, "ISO 6336-1 constants and the C1 transposition")
    assert 1 / q_pr * q_iso - 1 == pytest.approx(-0.0014, abs=0.0002)


def test_external_pair_matches_iso_formula_written_out():
    # ISO 6336-1 method B, external pair z = 19/20, x = 0.1/0.2, written out term by term
    z1, z2, x1, x2 = 19, 20, 0.1, 0.2
    c = (0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188, 0.00529, 0.00182)
    q = (
        c[0]
        + c[1] / z1
        + c[2] / z2
        + c[3] * x1
        + c[4] * x1 / z1
        + c[5] * x2
        + c[6] * x2 / z2
        + c[7] * x1**2
        + c[8] * x2**2
    )
    for variant in ("iso", "paper"):  # variants differ only for internal pairs
        assert s.flexibility_q(z1, z2, x1, x2, internal=False, variant=variant) == pytest.approx(q, rel=1e-14)


def test_paper_variant_kc_falls_4p9_percent_from_m_to_n():
    # with the paper's "+ for internal gearing" and z_n2 = 33, k_C falls 4.9 % from M to N;
    # the ISO internal treatment (z_n2 -> infinity) is almost flat.
    def drop(variant):
        qm = s.flexibility_q(30, 33, 0.416, 0.60095, variant=variant)
        qn = s.flexibility_q(30, 33, 0.835, 0.99443, variant=variant)
        return qm / qn - 1

    assert drop("paper") == pytest.approx(-0.049, abs=0.001)
    assert abs(drop("iso")) < 0.01


def test_pitch_stiffness_units():
    # Eq. (7): k_C = 0.8e3 B / q N/mm -> 0.8e6 B / q N/m
    assert s.pitch_point_stiffness(0.05, 20.0) == pytest.approx(0.8e6 * 20 / 0.05)


@pytest.mark.parametrize("eps", EPS_GRID)
@pytest.mark.parametrize("form", ["corrected", "printed"])
def test_mean_equals_numerical_integral(eps, form):
    k = s.ParabolicStiffness(eps, 2.0e8, form)
    num, _ = integrate.quad(k, 0.0, 1.0, points=[eps - 1.0], epsabs=0, epsrel=1e-13)
    assert k.mean() == pytest.approx(num, rel=1e-11)


@pytest.mark.parametrize("eps", EPS_GRID)
def test_corrected_mean_is_eight_ninths_eps_kc(eps):
    k_c = 3.0e8
    k = s.ParabolicStiffness(eps, s.tip_stiffness(k_c))
    assert k.mean() == pytest.approx(8 / 9 * eps * k_c, rel=1e-13)


@pytest.mark.parametrize("eps", EPS_GRID)
def test_corrected_form_is_sum_of_single_tooth_parabolas(eps):
    # independent: add up the pairs in contact, k_s(t) + k_s(t + 1) (+ k_s(t - 1) at the entry instant)
    kp = 1.7e8
    t = np.linspace(0.0, 1.0, 1001, endpoint=False)
    direct = s.single_tooth_stiffness(t, eps, kp) + np.where(
        t + 1.0 < eps, s.single_tooth_stiffness(t + 1.0, eps, kp), 0.0
    )
    assert s.ParabolicStiffness(eps, kp)(t) == pytest.approx(direct, rel=1e-12)


@pytest.mark.parametrize("eps", EPS_GRID)
def test_periodic_with_jumps_of_k_prime_at_entry_and_exit(eps):
    kp = 1.0e8
    k = s.ParabolicStiffness(eps, kp)
    t = np.linspace(0, 1, 97)
    assert k(t + 3.0) == pytest.approx(k(t), rel=1e-12)
    d = 1e-9
    assert k(0.0) - k(1.0 - d) == pytest.approx(kp, rel=1e-6)  # a pair enters at t = 0
    assert k(eps - 1.0 - d) - k(eps - 1.0) == pytest.approx(kp, rel=1e-6)  # a pair leaves at eps - 1
    # away from the jumps k is continuous
    for t0 in (0.5 * (eps - 1.0), 0.5 * eps):
        assert abs(k(t0 + d) - k(t0 - d)) < 1e-6 * kp
    assert k.fraction == pytest.approx(eps - 1.0)  # the jumps: a pair enters at 0, leaves at eps - floor(eps)


def test_printed_form_goes_negative_below_eps_1p193():
    # the printed Eq. (9) reaches k' (2 + 6/eps - 10/eps^2) at t = 1: negative for eps < (sqrt 29 - 3)/2
    # = 1.1926 (docs/paper1.md, "The printed form is negative for eps < 1.193")
    root = optimize.brentq(lambda e: s.ParabolicStiffness(e, 1.0, "printed").minimum(), 1.05, 1.5, xtol=1e-6)
    assert root == pytest.approx(1.193, abs=0.001)
    assert s.ParabolicStiffness(1.17, 1.0, "printed").minimum() < 0
    assert s.ParabolicStiffness(1.30, 1.0, "printed").minimum() > 0


@settings(max_examples=60 * EXAMPLE_SCALE, deadline=None)
@given(eps=st.floats(1.0, 1.999), kp=st.floats(1e6, 1e10), t=st.floats(-5, 5))
def test_corrected_stiffness_bounded_by_single_and_double_pair(eps, kp, t):
    k = float(s.ParabolicStiffness(eps, kp)(t))
    # one pair in contact at least (>= k'), at most two at their peak (<= 3 k')
    assert kp * (1 - 1e-12) <= k <= 3.0 * kp * (1 + 1e-12)


def test_bad_inputs_raise_clear_errors():
    with pytest.raises(ValueError, match="below 1"):
        s.ParabolicStiffness(0.9, 1.0)
    with pytest.raises(ValueError, match=r"printed Eq\. \(9\) is stated for 1 <= eps < 2"):
        s.ParabolicStiffness(2.3, 1.0, "printed")
    with pytest.raises(ValueError, match="unknown stiffness variant"):
        s.flexibility_q(30, 33, 0.5, 0.7, variant="nope")


@pytest.mark.parametrize("eps", [1.0, 1.3, 2.0, 2.3, 3.75])
def test_any_contact_ratio_sums_the_pairs_in_contact(eps):
    """k(s) = sum over every pair in contact of the single-pair parabola k'(1 + 2u(1 - u)), u = t / eps,
    t = s + j; n + 1 pairs on [0, f), n on [f, 1) with n = floor(eps); mean (4/3) eps k' for any eps."""
    kp = 2.0e8
    ks = s.ParabolicStiffness(eps, kp)
    phase = np.linspace(0.0, 0.999, 37)
    brute = [sum(kp * (1 + 2 * (t / eps) * (1 - t / eps)) for t in ph + np.arange(5) if t < eps) for ph in phase]
    np.testing.assert_allclose(ks(phase), brute, rtol=1e-13)
    assert ks.mean() == pytest.approx(4.0 / 3.0 * eps * kp, rel=1e-13)  # each pair's full contact, once a period
    assert ks.pairs == int(eps) and ks.fraction == pytest.approx(eps - int(eps))
